#include "support/test_support.h"

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include <sys/wait.h>

namespace liftoff::testing {

std::filesystem::path SourceDir() {
  if (const char* env = std::getenv("LIFTOFF_SOURCE_DIR")) return env;
  return LIFTOFF_SOURCE_DIR;
}

void ExpectValidPng(const std::filesystem::path& path) {
  const std::string bytes = ReadFile(path);
  ASSERT_GT(bytes.size(), 1000u) << path;
  EXPECT_EQ(bytes.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << path;
  EXPECT_EQ(bytes.substr(12, 4), "IHDR") << path;
  EXPECT_EQ(bytes.substr(bytes.size() - 8, 4), "IEND") << path;
}

void ExpectValidSvg(const std::filesystem::path& path) {
  const std::string text = ReadFile(path);
  EXPECT_NE(text.find("<svg"), std::string::npos) << path;
  const size_t close = text.rfind("</svg>");
  ASSERT_NE(close, std::string::npos) << path;
  EXPECT_EQ(text.find_first_not_of(" \r\n", close + 6), std::string::npos) << path;
}

std::vector<std::string> LinkTargets(const std::string& text, std::string_view opening,
                                     char closing) {
  // (a search, not std::regex: it recurses per character, and inlined images would
  // overflow its stack)
  std::vector<std::string> targets;
  for (size_t at = text.find(opening); at != std::string::npos; at = text.find(opening, at)) {
    at += opening.size();
    const size_t end = text.find(closing, at);
    if (end == std::string::npos) break;
    targets.push_back(text.substr(at, end - at));
  }
  return targets;
}

void ExpectLinksResolve(const std::filesystem::path& page, std::string_view opening,
                        char closing, size_t at_least) {
  const std::vector<std::string> targets = LinkTargets(ReadFile(page), opening, closing);
  EXPECT_GE(targets.size(), at_least) << page;
  for (const std::string& target : targets) {
    if (target.rfind("data:", 0) == 0 || target.rfind("#", 0) == 0) continue;
    EXPECT_FALSE(target.rfind("http", 0) == 0) << page << " links outside: " << target;
    EXPECT_TRUE(std::filesystem::exists(page.parent_path() / target))
        << page << " links to " << target;
  }
}

std::optional<std::filesystem::path> FindOnPath(const std::string& name) {
  std::istringstream path(std::getenv("PATH") ? std::getenv("PATH") : "");
  for (std::string folder; std::getline(path, folder, ':');) {
    if (!folder.empty() && std::filesystem::exists(std::filesystem::path(folder) / name)) {
      return std::filesystem::path(folder) / name;
    }
  }
  return std::nullopt;
}

std::optional<std::filesystem::path> ReferenceDir() {
  std::filesystem::path dir;
  if (const char* env = std::getenv("LIFTOFF_REFERENCE_DIR")) {
    dir = env;
  } else {
    dir = SourceDir().parent_path() / "shared" / "reference";
  }
  if (!std::filesystem::is_directory(dir / "laika-2018-hardware")) return std::nullopt;
  return dir;
}

ScratchDir::ScratchDir() {
  const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
  std::string name = info ? std::string(info->test_suite_name()) + "." + info->name() : "test";
  std::random_device random;
  path_ =
      std::filesystem::temp_directory_path() / ("liftoff-" + name + "-" + std::to_string(random()));
  std::filesystem::create_directories(path_);
}

ScratchDir::~ScratchDir() {
  std::error_code ignored;
  std::filesystem::remove_all(path_, ignored);
}

Calibration DriveChainCalibration() {
  Calibration calibration;
  calibration.name = "test";
  calibration.encoder_counts_per_motor_rev = 12;
  calibration.gearbox_ratio = 1000;
  calibration.spur_gear_ratio = 4;
  return calibration;
}

CommandRun RunCommand(const std::filesystem::path& binary, const std::string& arguments,
                      const ScratchDir& scratch) {
  const std::filesystem::path out_file = scratch / "stdout.txt";
  const std::filesystem::path err_file = scratch / "stderr.txt";
  const std::string command = Quoted(binary) + " " + arguments + " >" + Quoted(out_file) + " 2>" +
                              Quoted(err_file) + " </dev/null";
  const int status = std::system(command.c_str());
  CommandRun run;
  run.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  run.out = ReadFile(out_file);
  run.err = ReadFile(err_file);
  return run;
}

std::string Quoted(const std::filesystem::path& path) { return "\"" + path.string() + "\""; }

void WriteFile(const std::filesystem::path& path, const std::string& contents) {
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << contents;
}

std::string ReadFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream contents;
  contents << in.rdbuf();
  return contents.str();
}

}  // namespace liftoff::testing
