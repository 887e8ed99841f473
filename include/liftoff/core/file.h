// Whole-file reading and crash-safe writing, with errors that name the file.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "liftoff/core/status.h"

namespace liftoff {

/// The most bytes ReadWholeFile reads unless told otherwise (1 GiB).
inline constexpr std::uintmax_t kMaxWholeFileBytes = std::uintmax_t{1} << 30;

/// OK when `path` is a regular file (after following symbolic links) that can be read;
/// kNotFound when it does not exist, kInvalidArgument for a folder, a device, a pipe, a
/// socket or a symbolic link loop, each said so with the path.
Status CheckRegularFile(const std::filesystem::path& path);

/// The whole file as bytes. The errors of CheckRegularFile; kInvalidArgument for a file
/// larger than `max_bytes`; kIo when it cannot be read.
Result<std::string> ReadWholeFile(const std::filesystem::path& path,
                                  std::uintmax_t max_bytes = kMaxWholeFileBytes);

/// Writes `contents` to `path` through a TemporaryFile (liftoff/core/output.h) renamed into
/// place, so a reader never sees half a file; creates missing parent folders. kIo naming
/// the file and the system's reason on failure.
Status WriteFileAtomically(const std::filesystem::path& path, std::string_view contents);

/// Renames `temporary` onto `path`; removes `temporary` on failure. kIo naming `path` and
/// the system's reason.
Status RenameIntoPlace(const std::filesystem::path& temporary, const std::filesystem::path& path);

/// Creates the folder `path` will be written in, when missing. kIo on failure.
Status CreateParentFolder(const std::filesystem::path& path);

/// `path` as a person would like to read it: relative to the working folder when inside
/// it ("calib/laika-2018.json"), else as given.
std::string DisplayPath(const std::filesystem::path& path);

}  // namespace liftoff
