#include "liftoff/core/file.h"

#include <fstream>
#include <sstream>
#include <system_error>

namespace liftoff {

namespace fs = std::filesystem;

Result<std::string> ReadWholeFile(const fs::path& path) {
  std::error_code error;
  if (!fs::exists(path, error)) return NotFoundError(path.string() + ": no such file");
  if (fs::is_directory(path, error)) {
    return InvalidArgumentError(path.string() + ": is a folder, expected a file");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) return IoError(path.string() + ": cannot open for reading");
  std::ostringstream contents;
  contents << in.rdbuf();
  if (in.bad()) return IoError(path.string() + ": read failed");
  return std::move(contents).str();
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
  std::error_code error;
  fs::rename(temporary, path, error);
  if (!error) return Status::Ok();
  fs::remove(temporary, error);
  return IoError(path.string() + ": cannot rename into place: " + error.message());
}

Status WriteFileAtomically(const fs::path& path, std::string_view contents) {
  LIFTOFF_RETURN_IF_ERROR(CreateParentFolder(path));
  // write beside the target, then rename: readers never see half a file
  fs::path temporary = path;
  temporary += ".tmp";
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) return IoError(path.string() + ": cannot open for writing");
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) {
      std::error_code ignored;
      fs::remove(temporary, ignored);
      return IoError(path.string() + ": write failed");
    }
  }
  return RenameIntoPlace(temporary, path);
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
