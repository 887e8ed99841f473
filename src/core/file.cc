#include "liftoff/core/file.h"

#include <cerrno>
#include <cstdio>
#include <fstream>
#include <system_error>

#include "liftoff/core/output.h"

namespace liftoff {

namespace fs = std::filesystem;

Status CheckRegularFile(const fs::path& path) {
  const std::string name = path.string();
  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (error == std::errc::too_many_symbolic_link_levels) {
    return InvalidArgumentError(name + ": symbolic link loop (the link leads back to itself)");
  }
  if (status.type() == fs::file_type::not_found) return NotFoundError(name + ": no such file");
  if (error) return IoError(name + ": cannot read: " + error.message());
  if (status.type() == fs::file_type::directory) {
    return InvalidArgumentError(name + ": is a folder, expected a file");
  }
  if (status.type() != fs::file_type::regular) {
    return InvalidArgumentError(name +
                                ": is not a regular file (a device, pipe or socket); expected a "
                                "file");
  }
  return Status::Ok();
}

Result<std::string> ReadWholeFile(const fs::path& path, std::uintmax_t max_bytes) {
  LIFTOFF_RETURN_IF_ERROR(CheckRegularFile(path));
  std::error_code error;
  const std::uintmax_t size = fs::file_size(path, error);
  if (error) return IoError(path.string() + ": cannot read: " + error.message());
  if (size > max_bytes) {
    return InvalidArgumentError(path.string() + ": " + std::to_string(size) +
                                " bytes; expected at most " + std::to_string(max_bytes));
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError(path.string() + ": cannot open for reading");
  // the size read, never more than asked for (the file may grow while it is read)
  std::string contents(static_cast<size_t>(size), '\0');
  in.read(contents.data(), static_cast<std::streamsize>(size));
  if (in.bad()) return IoError(path.string() + ": read failed");
  contents.resize(static_cast<size_t>(in.gcount()));
  return contents;
}

Status CreateParentFolder(const fs::path& path) {
  const fs::path parent = path.parent_path();
  if (parent.empty()) return Status::Ok();
  std::error_code error;
  fs::create_directories(parent, error);
  if (error) return IoError(parent.string() + ": cannot create folder: " + error.message());
  return Status::Ok();
}

Status RenameIntoPlace(const fs::path& temporary, const fs::path& path) {
  if (std::rename(temporary.c_str(), path.c_str()) == 0) return Status::Ok();
  const int error_number = errno;  // before the removal can overwrite it
  std::error_code ignored;
  fs::remove(temporary, ignored);
  return IoError(path.string() + ": cannot rename into place: " +
                 std::generic_category().message(error_number));
}

Status WriteFileAtomically(const fs::path& path, std::string_view contents) {
  // written beside the target under a name of its own, then renamed: readers never see
  // half a file, and two writers never share a temporary file
  LIFTOFF_ASSIGN_OR_RETURN(TemporaryFile temporary, TemporaryFile::Create(path));
  LIFTOFF_RETURN_IF_ERROR(temporary.Write(contents));
  return temporary.Commit();
}

std::string DisplayPath(const fs::path& path) {
  std::error_code error;
  const fs::path here = fs::current_path(error);
  if (error || path.empty()) return path.string();
  const fs::path relative = fs::absolute(path, error).lexically_normal().lexically_relative(here);
  if (error || relative.empty() || *relative.begin() == "..") return path.string();
  return relative.string();
}

}  // namespace liftoff
