// Shared fixtures for liftoff's tests: where the source tree and the reference data are,
// scratch folders, and small file helpers.
#pragma once

#include <filesystem>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include <gtest/gtest.h>

#include "liftoff/core/calibration.h"

namespace liftoff::testing {

/// The liftoff source tree (for calib/, samples/).
std::filesystem::path SourceDir();

/// ../shared/reference next to the source tree (or $LIFTOFF_REFERENCE_DIR), when present.
std::optional<std::filesystem::path> ReferenceDir();

/// Expects `path` to hold a whole PNG: its signature, an IHDR first and an IEND last.
void ExpectValidPng(const std::filesystem::path& path);
/// Expects `path` to hold an SVG document: an <svg> element closed at the end.
void ExpectValidSvg(const std::filesystem::path& path);

/// The targets of every `opening`...`closing` in `text` (e.g. "](" and ')' for Markdown
/// links, "src=\"" and '"' for HTML).
std::vector<std::string> LinkTargets(const std::string& text, std::string_view opening,
                                     char closing);
/// Expects `page` to hold at least `at_least` such links and every one to be inline data,
/// an anchor, or a file beside the page (never a remote address).
void ExpectLinksResolve(const std::filesystem::path& page, std::string_view opening,
                        char closing, size_t at_least);

/// The program `name` in a folder of PATH, or nullopt.
std::optional<std::filesystem::path> FindOnPath(const std::string& name);

/// A fresh empty folder for one test, removed when the object is destroyed.
class ScratchDir {
 public:
  ScratchDir();
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  /// path() / name.
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// The 2018 drive chain built in code, independent of calib/: 12 counts per rotor
/// revolution, 1000:1 gearbox, 4:1 spur gear (so a vertebra angle is a quarter of the
/// output shaft's). Name "test".
Calibration DriveChainCalibration();

/// What a command line did: its exit code and what it printed.
struct CommandRun {
  int code = -1;  ///< exit status; -1 when it did not exit normally
  std::string out;
  std::string err;
};
/// Runs `binary` with `arguments` (already quoted as a shell needs) through the shell,
/// capturing standard output and error in files under `scratch`.
CommandRun RunCommand(const std::filesystem::path& binary, const std::string& arguments,
                      const ScratchDir& scratch);
/// Runs a command's Run function in this process: `run(command, out, err)` with its
/// exit code and what it wrote (liftoff::cli's RunTable, RunReport, ...).
template <typename Command, typename RunFunction>
CommandRun RunInProcess(RunFunction run, const Command& command) {
  std::ostringstream out, err;
  CommandRun result;
  result.code = run(command, out, err);
  result.out = out.str();
  result.err = err.str();
  return result;
}
/// `path` in double quotes, for a shell command line.
std::string Quoted(const std::filesystem::path& path);

/// Writes `contents` to `path` byte for byte (creating parent folders).
void WriteFile(const std::filesystem::path& path, const std::string& contents);
/// Reads a whole file; empty when missing.
std::string ReadFile(const std::filesystem::path& path);

}  // namespace liftoff::testing

/// Skips the current test with a message when the reference data is absent (a user's
/// fresh clone has no ../shared).
#define LIFTOFF_REQUIRE_REFERENCE(dir_var)                                              \
  const auto dir_var##_opt = ::liftoff::testing::ReferenceDir();                        \
  if (!dir_var##_opt) {                                                                 \
    GTEST_SKIP() << "../shared/reference is absent (a fresh clone has none); skipping"; \
  }                                                                                     \
  const std::filesystem::path dir_var = *dir_var##_opt
