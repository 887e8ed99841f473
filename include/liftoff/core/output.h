// The output policy every writing command follows: an output never replaces one of the
// command's own inputs, and a temporary file never outlives its writer (signals included).
#pragma once

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "liftoff/core/status.h"

namespace liftoff {

/// A file a command reads or writes, with the flag or argument that named it, for
/// messages ("--output", "MANIFEST", "trial T1's log").
struct NamedPath {
  std::string role;
  std::filesystem::path path;
};

/// True when `a` and `b` name one file: the same inode when both exist (hard links,
/// symbolic links, "./x" beside "x"), else the same weakly canonical path.
bool SameFile(const std::filesystem::path& a, const std::filesystem::path& b);

/// kInvalidArgument when an output names the same file as an input, naming both:
/// "--output m.json: is the command's input MANIFEST (m.json); refusing to write over an
/// input". Empty paths and "-" (standard output) are not files and are skipped.
Status CheckOutputsAreNotInputs(const std::vector<NamedPath>& outputs,
                                const std::vector<NamedPath>& inputs);

/// kInvalidArgument when `path` exists (a symbolic link, even dangling, counts) and
/// `replace` is false: "a.csv: exists (WHAT); pass --force to replace it". `what` says what
/// the file may be ("the log of an earlier recording?"); empty: nothing is said.
Status RefuseToReplace(const std::filesystem::path& path, std::string_view what, bool replace);

/// A temporary file beside `target`, "<target>.tmp.<pid>.<random>", created exclusively
/// (O_EXCL) so two writers of one output never share it. It is removed when the object is
/// destroyed uncommitted, and on SIGINT, SIGTERM or SIGHUP (then the signal's default
/// action runs) unless the program installed its own handler for that signal first.
class TemporaryFile {
 public:
  /// Creates the file (and `target`'s missing parent folders). kIo naming `target`.
  static Result<TemporaryFile> Create(const std::filesystem::path& target);

  TemporaryFile(TemporaryFile&& other) noexcept;
  TemporaryFile& operator=(TemporaryFile&&) = delete;
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  ~TemporaryFile();

  const std::filesystem::path& path() const { return path_; }
  /// Appends bytes. kIo naming the target, with the system's reason.
  Status Write(std::string_view bytes);
  /// Closes the file and renames it onto the target. On failure the temporary file is
  /// removed and the error carries the system's reason. Call at most once.
  Status Commit();

 private:
  TemporaryFile(std::filesystem::path target, std::filesystem::path path, int fd, int slot);
  void Discard();

  std::filesystem::path target_;
  std::filesystem::path path_;
  int fd_ = -1;
  int slot_ = -1;  // index in the signal handler's registry; -1 when not registered
};

/// Temporary files registered for removal on a signal, right now (for tests).
int LiveTemporaryFileCount();

}  // namespace liftoff
