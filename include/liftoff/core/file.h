// Whole-file reading and crash-safe writing, with errors that name the file.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "liftoff/core/status.h"

namespace liftoff {

/// The whole file as bytes. kNotFound when it does not exist, kInvalidArgument for a
/// folder, kIo when it cannot be read.
Result<std::string> ReadWholeFile(const std::filesystem::path& path);

/// Writes `contents` to `path` through `path.tmp` renamed into place, so a reader never
/// sees half a file; creates missing parent folders. kIo naming the file on failure.
Status WriteFileAtomically(const std::filesystem::path& path, std::string_view contents);

/// Renames `temporary` onto `path`; removes `temporary` on failure. kIo naming `path`.
Status RenameIntoPlace(const std::filesystem::path& temporary, const std::filesystem::path& path);

/// Creates the folder `path` will be written in, when missing. kIo on failure.
Status CreateParentFolder(const std::filesystem::path& path);

/// `path` as a person would like to read it: relative to the working folder when inside
/// it ("calib/laika-2018.json"), else as given.
std::string DisplayPath(const std::filesystem::path& path);

}  // namespace liftoff
