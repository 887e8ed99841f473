// Hostile inputs to every command, through the real binary: outputs aimed at the
// command's own inputs, non-finite and overflowing numbers, devices, symbolic link loops,
// deep JSON, huge files and bad flags. Each case asserts the exit code, that the message
// names the culprit, and that no file in the scratch folder changed (inputs and earlier
// outputs alike) and none was left behind.
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <thread>

#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "liftoff/capture/laika2018.h"
#include "liftoff/cli/commands.h"
#include "support/test_support.h"

namespace liftoff::cli {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::CommandRun;
using liftoff::testing::Quoted;
using liftoff::testing::ReadFile;
using liftoff::testing::ScratchDir;
using liftoff::testing::SourceDir;
using liftoff::testing::WriteFile;
using ::testing::HasSubstr;
using ::testing::Not;

constexpr const char* kLiftoffLogHeader =
    "# liftoff-log 1\n"
    "device_time_ns,host_time_ns,seq,led,bend_counts,rotate_counts,bend_spool_rad,"
    "rotate_shaft_rad,vertebra_rad,event,detail\n";

// A liftoff-format log: LED on at 1 s, the vertebra at t_s / 10 rad every 100 ms to 5 s.
std::string LiftoffLog(bool with_led_event = true) {
  std::string text = kLiftoffLogHeader;
  if (with_led_event) text += "1000000000,,,,,,,,,led_on,\n";
  for (int t_ms = 0; t_ms <= 5000; t_ms += 100) {
    text += std::to_string(int64_t{t_ms} * 1'000'000) + ",,,,,,,," +
            std::to_string(t_ms / 10000.0) + ",,\n";
  }
  return text;
}

// A manifest of one trial whose log is `log_path` (liftoff's format, auto-detected).
void WriteManifest(const ScratchDir& scratch, const std::string& id, const std::string& log_path,
                   const std::string& name = "manifest.json") {
  const nlohmann::json manifest = {
      {"format", "liftoff-manifest"},
      {"version", 1},
      {"trials",
       {{{"id", id},
         {"foot", "A"},
         {"log", {{"path", log_path}}},
         {"times", {{"led_on_s", 1.0}, {"liftoff_s", 2.0}}}}}}};
  WriteFile(scratch / name, manifest.dump(2));
}

// One trial with a good log: manifest.json and A1.csv.
void OneTrial(const ScratchDir& scratch) {
  WriteFile(scratch / "A1.csv", LiftoffLog());
  WriteManifest(scratch, "A1", "A1.csv");
}

// A 2018 Laika folder of one trial: data/<times CSV> and its log.
void Folder2018(const ScratchDir& scratch) {
  WriteFile(scratch / "data" / capture::kLaika2018TimesCsv,
            "Times,,,,\n,,,,\nFoot,Test no,Begin,Lift,Total\nA,1,0.5,1.5,1\n");
  WriteFile(scratch / "data" / "Test1 Front Right Blue.txt", "0,0.1,\r1000,0.2,\r2000,0.3,\r");
}

std::string DeepJson(size_t depth) { return std::string(depth, '[') + std::string(depth, ']'); }

// Every regular file under the scratch folder and its bytes, but the captured streams.
std::map<std::string, std::string> Snapshot(const ScratchDir& scratch) {
  std::map<std::string, std::string> files;
  std::error_code error;
  for (auto it = fs::recursive_directory_iterator(scratch.path(), error);
       it != fs::recursive_directory_iterator(); it.increment(error)) {
    const fs::path& path = it->path();
    const std::string name = path.lexically_relative(scratch.path()).string();
    if (name == "stdout.txt" || name == "stderr.txt") continue;
    const fs::file_type type = fs::symlink_status(path, error).type();
    files[name] = type == fs::file_type::symlink   ? "-> " + fs::read_symlink(path).string()
                  : type == fs::file_type::regular ? ReadFile(path)
                                                   : "(not a file)";
  }
  return files;
}

struct HostileCase {
  std::string name;
  std::function<void(const ScratchDir&)> setup;
  /// Arguments; "@" stands for the scratch folder.
  std::string arguments;
  int exit_code;
  /// Every one must be in standard error.
  std::vector<std::string> culprits;
  /// None may be in standard output or error (work that must not have happened).
  std::vector<std::string> absent = {};
};

std::string Expand(std::string arguments, const ScratchDir& scratch) {
  for (size_t at = arguments.find('@'); at != std::string::npos; at = arguments.find('@', at)) {
    arguments.replace(at, 1, scratch.path().string());
    at += scratch.path().string().size();
  }
  return arguments;
}

const std::vector<HostileCase>& Cases() {
  static const std::vector<HostileCase> cases = {
      // -- outputs onto the command's own inputs
      {"table -o its manifest", OneTrial, "table @/manifest.json -o @/manifest.json", 3,
       {"--output", "MANIFEST", "refusing to write over an input"}},
      {"table -o a trial's log", OneTrial, "table @/manifest.json -o @/A1.csv", 3,
       {"--output", "trial A1's log"}},
      {"table -o the log by another spelling", OneTrial,
       "table @/manifest.json -o @/./sub/../A1.csv", 3, {"trial A1's log"}},
      {"table --plot its manifest", OneTrial, "table @/manifest.json --plot @/manifest.json", 3,
       {"--plot", "expected FILE.svg or FILE.png", "manifest.json"}},
      {"table --plot beside it onto its manifest",
       [](const ScratchDir& s) {
         OneTrial(s);
         fs::copy_file(s / "manifest.json", s / "plot.svg");
       },
       "table @/plot.svg --plot @/plot.png", 3, {"--plot", "MANIFEST"}},
      {"table -o its calibration",
       [](const ScratchDir& s) {
         OneTrial(s);
         fs::copy_file(SourceDir() / "calib" / "laika-2018.json", s / "calib.json");
       },
       "table @/manifest.json -c @/calib.json -o @/calib.json", 3, {"--output", "calibration"}},
      {"log --convert onto its log", [](const ScratchDir& s) { WriteFile(s / "raw.txt", "0,0.1,\r"); },
       "log @/raw.txt --convert @/raw.txt", 3, {"--convert", "LOG", "raw.txt"}},
      {"log --convert onto a hard link of its log",
       [](const ScratchDir& s) {
         WriteFile(s / "raw.txt", "0,0.1,\r");
         fs::create_hard_link(s / "raw.txt", s / "link.txt");
       },
       "log @/raw.txt --convert @/link.txt", 3, {"--convert", "LOG"}},
      {"log --convert onto a symbolic link to its log",
       [](const ScratchDir& s) {
         WriteFile(s / "raw.txt", "0,0.1,\r");
         fs::create_symlink(s / "raw.txt", s / "link.txt");
       },
       "log @/raw.txt --convert @/link.txt", 3, {"--convert", "LOG"}},
      {"video --verify onto its clip",
       [](const ScratchDir& s) { WriteFile(s / "clip.mp4", std::string(4096, 'v')); },
       "video @/clip.mp4 --verify @/clip.mp4 --progress off", 3, {"--verify", "CLIP"}},
      {"video --annotate onto its clip",
       [](const ScratchDir& s) { WriteFile(s / "clip.mp4", std::string(4096, 'v')); },
       "video @/clip.mp4 --annotate @/clip.mp4 --progress off", 3, {"--annotate", "CLIP"}},
      {"sync --verify onto its log",
       [](const ScratchDir& s) {
         WriteFile(s / "A1.csv", LiftoffLog());
         WriteFile(s / "clip.mp4", std::string(4096, 'v'));
       },
       "sync @/A1.csv --video @/clip.mp4 --foot-roi 0,0,10,10 --verify @/A1.csv --progress off",
       3, {"--verify", "LOG"}},
      {"sim run --curves onto its model",
       [](const ScratchDir& s) {
         fs::copy_file(SourceDir() / "samples" / "models" / "laika.json", s / "model.json");
       },
       "sim run --model @/model.json --curves @/model.json --progress off", 3,
       {"--curves", "--model"}},
      {"sim sweep -o onto its model",
       [](const ScratchDir& s) {
         fs::copy_file(SourceDir() / "samples" / "models" / "laika.json", s / "model.json");
       },
       "sim sweep --model @/model.json -o @/model.json --progress off", 3, {"--output", "--model"}},
      {"sim export-mjcf -o onto its model",
       [](const ScratchDir& s) {
         fs::copy_file(SourceDir() / "samples" / "models" / "laika.json", s / "model.json");
       },
       "sim export-mjcf --model @/model.json -o @/model.json", 3, {"--output", "--model"}},
      {"import-2018 -o onto its times with --force", Folder2018,
       std::string("import-2018 @/data -o \"@/data/") + capture::kLaika2018TimesCsv + "\" --force",
       3, {"--output", "FOLDER's times"}},
      {"import-2018 -o onto a log with --force", Folder2018,
       "import-2018 @/data -o \"@/data/Test1 Front Right Blue.txt\" --force", 3,
       {"--output", "trial A1's log"}},

      // -- numbers that are not finite or do not fit
      {"log with inf in an angle column",
       [](const ScratchDir& s) {
         WriteFile(s / "inf.csv", std::string(kLiftoffLogHeader) + "0,,,,,,,,0.1,,\n" +
                                      "100000000,,,,,,,,inf,,\n");
       },
       "log @/inf.csv", 5, {"inf.csv:4", "vertebra_rad", "finite"}},
      {"sync with nan in an angle column",
       [](const ScratchDir& s) {
         WriteFile(s / "nan.csv", std::string(kLiftoffLogHeader) + "0,,,,,,,,0.1,,\n" +
                                      "100000000,,,,,,,,nan,,\n");
       },
       "sync @/nan.csv --led-on 0 --liftoff 0.05", 5, {"nan.csv:4", "finite"}},
      {"sync with sample times near the int64 limits",
       [](const ScratchDir& s) {
         WriteFile(s / "huge.csv", std::string(kLiftoffLogHeader) +
                                       "-9223372036854775000,,,,,,,,0.1,,\n" +
                                       "9223372036854775000,,,,,,,,0.2,,\n");
       },
       "sync @/huge.csv --led-on 0 --liftoff 1", 5, {"huge.csv:3", "device_time_ns", "4e18"}},
      {"calibration with a gear ratio of 1e-320",
       [](const ScratchDir& s) {
         std::string text = ReadFile(SourceDir() / "calib" / "laika-2018.json");
         text.replace(text.find("\"gearbox_ratio\": 1000"), 21, "\"gearbox_ratio\": 1e-320");
         WriteFile(s / "calib.json", text);
       },
       "calib @/calib.json", 3, {"calib.json", "/motor/gearbox_ratio", "[0.01, 100000]"}},

      // -- unbounded, nested, looping inputs
      {"table of JSON nested 100000 deep",
       [](const ScratchDir& s) { WriteFile(s / "deep.json", DeepJson(100000)); },
       "table @/deep.json", 5, {"deep.json:1:65", "nested deeper than 64"}},
      {"calib of JSON nested 100000 deep",
       [](const ScratchDir& s) { WriteFile(s / "deep.json", DeepJson(100000)); },
       "calib @/deep.json", 5, {"deep.json", "nested deeper"}},
      {"sim run with a model nested 100000 deep",
       [](const ScratchDir& s) { WriteFile(s / "deep.json", DeepJson(100000)); },
       "sim run --model @/deep.json --progress off", 5, {"deep.json", "nested deeper"}},
      {"table whose trial log is /dev/zero",
       [](const ScratchDir& s) { WriteManifest(s, "A1", "/dev/zero"); }, "table @/manifest.json",
       3, {"/dev/zero", "not a regular file"}},
      {"log of /dev/zero", nullptr, "log /dev/zero", 3, {"/dev/zero", "not a regular file"}},
      {"calib of /dev/zero", nullptr, "calib /dev/zero", 3, {"/dev/zero", "not a regular file"}},
      {"table of a symbolic link loop",
       [](const ScratchDir& s) { fs::create_symlink(s / "loop.json", s / "loop.json"); },
       "table @/loop.json", 3, {"loop.json", "symbolic link loop"}},
      {"log of a symbolic link loop",
       [](const ScratchDir& s) { fs::create_symlink(s / "loop.csv", s / "loop.csv"); },
       "log @/loop.csv", 3, {"loop.csv", "symbolic link loop"}},
      {"calib of a file beyond the JSON size limit",
       [](const ScratchDir& s) {
         WriteFile(s / "huge.json", "{");
         fs::resize_file(s / "huge.json", std::uintmax_t{65} << 20);  // sparse
       },
       "calib @/huge.json", 3, {"huge.json", "68157440 bytes", "at most 67108864"}},
      {"log with a line longer than the limit",
       [](const ScratchDir& s) {
         WriteFile(s / "long.csv", std::string(kLiftoffLogHeader) + "0,,,,,,,,0.1,,\n" +
                                       std::string(100000, '7') + "\n");
       },
       "log @/long.csv", 5, {"long.csv:4", "at most 4096 bytes"}},
      {"empty calibration", [](const ScratchDir& s) { WriteFile(s / "empty.json", ""); },
       "calib @/empty.json", 5, {"empty.json"}},
      {"empty manifest", [](const ScratchDir& s) { WriteFile(s / "empty.json", ""); },
       "table @/empty.json", 5, {"empty.json:1:1"}},
      {"binary model",
       [](const ScratchDir& s) { WriteFile(s / "bin.json", std::string("\x00\x01\x02", 3)); },
       "sim run --model @/bin.json --progress off", 5, {"bin.json:1:1", "invalid JSON"}},
      {"simulation results nested 100000 deep",
       [](const ScratchDir& s) {
         OneTrial(s);
         WriteFile(s / "deep.json", DeepJson(100000));
       },
       "table @/manifest.json --sim @/deep.json", 5, {"deep.json:1:65", "nested deeper"}},
      {"2018 log with inf",
       [](const ScratchDir& s) { WriteFile(s / "l18.txt", "0,0.1,\r100,inf,\r200,0.3,\r"); },
       "log @/l18.txt", 5, {"l18.txt:2", "inf"}},
      {"binary log",
       [](const ScratchDir& s) { WriteFile(s / "bin.csv", std::string("\x00\x01\xff\xfe", 4)); },
       "log @/bin.csv", 5, {"bin.csv"}},

      // -- the smaller ones
      {"a PNG named .mp4",
       [](const ScratchDir& s) {
         fs::copy_file(SourceDir() / "docs" / "images" / "synth-frame-default.png", s / "clip.mp4");
       },
       "video @/clip.mp4 --progress off", 5, {"clip.mp4", "not a video", "PNG"}},
      {"log with a negative --max-bad-lines",
       [](const ScratchDir& s) { WriteFile(s / "A1.csv", LiftoffLog()); },
       "log @/A1.csv --max-bad-lines -1", 3, {"--max-bad-lines", "-1"}},
      {"sync with a negative --max-bad-lines",
       [](const ScratchDir& s) { WriteFile(s / "A1.csv", LiftoffLog()); },
       "sync @/A1.csv --led-on 1 --liftoff 2 --max-bad-lines -1", 3, {"--max-bad-lines"}},
      {"table with a negative --max-bad-lines", OneTrial,
       "table @/manifest.json --max-bad-lines -1", 3, {"--max-bad-lines"}},
      {"synth --seed with a 2D set", nullptr, "synth --set ci --seed 3 -o @/set", 2,
       {"--seed", "ci3d, hard3d or campaign"}},
      {"synth --keyframe-interval with a 2D set", nullptr,
       "synth --set ci --keyframe-interval 250 -o @/set", 2,
       {"--keyframe-interval", "ci3d or hard3d"}},
      {"synth --keyframe-interval out of range", nullptr,
       "synth --set hard3d --keyframe-interval 20000 -o @/set -q", 3,
       {"--keyframe-interval", "20000", "10000"}},
      {"synth --led-on-spread with a 2D set", nullptr,
       "synth --set ci --led-on-spread 1 -o @/set", 2, {"--led-on-spread", "ci3d or hard3d"}},
      {"synth --led-on-spread out of range", nullptr,
       "synth --set hard3d --led-on-spread 11 -o @/set -q", 3,
       {"--led-on-spread", "11", "0 .. 10"}},
      {"synth --flicker with a 2D set", nullptr, "synth --set ci --flicker 0.3 -o @/set", 2,
       {"--flicker", "ci3d or hard3d"}},
      {"synth --flicker out of range", nullptr, "synth --set hard3d --flicker 0.7 -o @/set -q", 3,
       {"--flicker", "0.7", "0 .. 0.5"}},
      {"synth --flicker-readout-ms longer than a frame", nullptr,
       "synth --set hard3d --flicker-readout-ms 50 -o @/set -q", 3,
       {"hard3d-01", "flicker_readout_s", "0.05"}},
      {"synth --led-radius-mm with a 2D set", nullptr, "synth --set ci --led-radius-mm 2 -o @/set",
       2, {"--led-radius-mm", "ci3d or hard3d"}},
      {"synth --led-radius-mm nan with a 2D set", nullptr,
       "synth --set ci --led-radius-mm nan -o @/set", 2, {"--led-radius-mm", "ci3d or hard3d"}},
      {"synth --led-radius-mm under 1 mm", nullptr,
       "synth --set hard3d --led-radius-mm 0.5 -o @/set -q", 3,
       {"--led-radius-mm", "led_radius_m", "0.001 .. 0.02"}},
      {"synth --exposure-ms of zero", nullptr, "synth --set ci3d --exposure-ms 0 -o @/set -q", 3,
       {"--exposure-ms", "exposure_s"}},
      {"synth --exposure-ms longer than a 60 fps clip's frame", nullptr,
       "synth --set ci3d --exposure-ms 20 -o @/set -q", 3, {"ci3d-05", "exposure_s", "0.02"}},
      {"sim sweep --hardware of a missing manifest", nullptr,
       "sim sweep --hardware @/missing.json --progress off", 4, {"--hardware", "missing.json"},
       {"s wall"}},  // failed before the sweep, not after it
      {"a trial id with a line break",
       [](const ScratchDir& s) {
         WriteFile(s / "A1.csv", LiftoffLog());
         WriteManifest(s, "A1\n| x | y |", "A1.csv");
       },
       "table @/manifest.json", 3, {"/trials/0/id", "one line"}},
  };
  return cases;
}

class HostileInput : public ::testing::TestWithParam<size_t> {};

TEST_P(HostileInput, FailsNamingTheCulpritAndChangesNoFile) {
  const HostileCase& c = Cases()[GetParam()];
  SCOPED_TRACE(c.name);
  ScratchDir scratch;
  if (c.setup) c.setup(scratch);
  const std::map<std::string, std::string> before = Snapshot(scratch);

  const CommandRun run = liftoff::testing::RunCommand(LIFTOFF_BINARY, Expand(c.arguments, scratch),
                                                      scratch);
  EXPECT_EQ(run.code, c.exit_code) << run.err;
  for (const std::string& culprit : c.culprits) EXPECT_THAT(run.err, HasSubstr(culprit));
  for (const std::string& text : c.absent) EXPECT_THAT(run.out + run.err, Not(HasSubstr(text)));
  EXPECT_THAT(run.err, Not(HasSubstr("internal error")));
  EXPECT_THAT(run.out, Not(HasSubstr("nan")));  // errors may quote a bad "nan"; results never
  // inputs and earlier outputs unchanged, nothing new (no temporary file left behind)
  const std::map<std::string, std::string> after = Snapshot(scratch);
  EXPECT_EQ(after.size(), before.size());
  for (const auto& [name, bytes] : before) {
    const auto it = after.find(name);
    ASSERT_NE(it, after.end()) << name << " disappeared";
    EXPECT_TRUE(it->second == bytes) << name << " changed";
  }
}

INSTANTIATE_TEST_SUITE_P(EveryCase, HostileInput, ::testing::Range<size_t>(0, Cases().size()),
                         [](const ::testing::TestParamInfo<size_t>& param) {
                           std::string name = Cases()[param.param].name;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

// -- outcomes that are not errors but must never pass for results

// `liftoff sim <arguments>` with damping the engine cannot resolve, on a short timeline,
// writing `output_flag` `output` (curves or results)
CommandRun DivergingSim(const std::string& arguments, const std::string& output_flag,
                        const fs::path& output, const ScratchDir& scratch) {
  return liftoff::testing::RunCommand(
      LIFTOFF_BINARY,
      "sim " + arguments + " --damping 1e4 " + output_flag + " " + Quoted(output) +
          " --bend-start-s 1 --reference-s 1.9 --ramp-start-s 2 --ramp-s 10 --progress off",
      scratch);
}

TEST(HostileSim, ADivergedRunIsItsOwnOutcomeWithItsOwnExitCode) {
  ScratchDir scratch;
  const CommandRun run =
      DivergingSim("run --foot A --tension high", "--curves", scratch / "c.csv", scratch);
  EXPECT_EQ(run.code, kExitDiverged) << run.err;
  EXPECT_THAT(run.out, HasSubstr("diverged at t = "));
  EXPECT_THAT(run.err, HasSubstr("diverged at t = "));
  EXPECT_THAT(run.err, HasSubstr("m/s (at most 1000 m/s is physical)"));
  EXPECT_THAT(run.out, Not(HasSubstr("did not lift")));
  EXPECT_THAT(run.out + run.err + ReadFile(scratch / "c.csv"), Not(HasSubstr("nan")));
  // every flag in range: a coarse step with stiff cables
  const CommandRun stiff = liftoff::testing::RunCommand(
      LIFTOFF_BINARY,
      "sim run --foot A --dt 0.01 --stiffness 20000,20000,20000 --json --progress off", scratch);
  EXPECT_EQ(stiff.code, kExitDiverged) << stiff.err;
  const nlohmann::json outcome = nlohmann::json::parse(stiff.out);
  EXPECT_EQ(outcome["status"], "diverged");
  EXPECT_EQ(outcome["stood"], false);
  EXPECT_TRUE(outcome["liftoff_rad"].is_null());
  EXPECT_GT(outcome["diverged_at_s"].get<double>(), 0.0);
}

TEST(HostileSim, ADivergedRunIsMarkedInTheSweepAndLeftOutOfTheRange) {
  ScratchDir scratch;
  const CommandRun run =
      DivergingSim("sweep --feet A --tensions high", "-o", scratch / "sweep.json", scratch);
  EXPECT_EQ(run.code, kExitDiverged) << run.err;
  EXPECT_THAT(run.out, HasSubstr("| diverged |"));
  EXPECT_THAT(run.out, HasSubstr("| – | – |"));  // no range from a diverged run
  EXPECT_THAT(run.out + run.err, Not(HasSubstr("nan")));
  const nlohmann::json results = nlohmann::json::parse(ReadFile(scratch / "sweep.json"));
  ASSERT_EQ(results["runs"].size(), 1u);
  EXPECT_EQ(results["runs"][0]["diverged"], true);
  EXPECT_EQ(results["runs"][0]["stood"], false);
}

// the names in `dir` that start with `prefix`
std::vector<std::string> NamesStartingWith(const fs::path& dir, const std::string& prefix) {
  std::vector<std::string> names;
  std::error_code error;
  for (const auto& entry : fs::directory_iterator(dir, error)) {
    const std::string name = entry.path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
  }
  return names;
}

// Ctrl-C while `log --convert` writes: the signal arrives while the temporary file exists
// (watched for), the process dies of it, and neither the temporary file nor a half output
// is left.
TEST(HostileLog, CtrlCWhileConvertingLeavesNoTemporaryFile) {
  ScratchDir scratch;
  std::string log = kLiftoffLogHeader;
  for (int64_t i = 0; i < 2'000'000; ++i) {
    log += std::to_string(i * 1'000'000) + ",1700000000000000000,7,1,12345,67890,0.25,0.5,0.125,,\n";
  }
  WriteFile(scratch / "big.csv", log);
  const fs::path output = scratch / "converted.csv";
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    const int null_fd = open("/dev/null", O_WRONLY);
    dup2(null_fd, STDOUT_FILENO);
    dup2(null_fd, STDERR_FILENO);
    const std::string log_path = (scratch / "big.csv").string(), out_path = output.string();
    execl(LIFTOFF_BINARY, LIFTOFF_BINARY, "log", log_path.c_str(), "--convert", out_path.c_str(),
          static_cast<char*>(nullptr));
    _exit(127);
  }
  // interrupt as soon as the temporary file shows up
  bool interrupted = false;
  int status = 0;
  for (int polls = 0; polls < 600'000; ++polls) {
    if (!NamesStartingWith(scratch.path(), "converted.csv.tmp").empty()) {
      kill(child, SIGINT);
      interrupted = true;
      break;
    }
    if (waitpid(child, &status, WNOHANG) == child) break;
    std::this_thread::sleep_for(std::chrono::microseconds(100));
  }
  if (interrupted) {
    ASSERT_EQ(waitpid(child, &status, 0), child);
  }
  if (!interrupted || (WIFEXITED(status) && WEXITSTATUS(status) == 0)) {
    GTEST_SKIP() << "the conversion finished before the signal arrived; nothing to check";
  }
  ASSERT_TRUE(WIFSIGNALED(status)) << "exit " << WEXITSTATUS(status);
  EXPECT_EQ(WTERMSIG(status), SIGINT);
  EXPECT_THAT(NamesStartingWith(scratch.path(), "converted.csv"), ::testing::IsEmpty());
}

TEST(HostileSync, WarnsWhenALiftoffLogHasNoLedEvent) {
  ScratchDir scratch;
  WriteFile(scratch / "A1.csv", LiftoffLog(/*with_led_event=*/false));
  const CommandRun sync = liftoff::testing::RunCommand(
      LIFTOFF_BINARY, "sync " + Quoted(scratch / "A1.csv") + " --led-on 1 --liftoff 2", scratch);
  EXPECT_EQ(sync.code, kExitOk) << sync.err;
  EXPECT_THAT(sync.out + sync.err, HasSubstr("no LED event"));
  WriteManifest(scratch, "A1", "A1.csv");
  const CommandRun table = liftoff::testing::RunCommand(
      LIFTOFF_BINARY, "table " + Quoted(scratch / "manifest.json"), scratch);
  EXPECT_EQ(table.code, kExitOk) << table.err;
  EXPECT_THAT(table.err, HasSubstr("A1: the log has no LED event"));
  // with the event: no warning
  WriteFile(scratch / "A1.csv", LiftoffLog(/*with_led_event=*/true));
  const CommandRun marked = liftoff::testing::RunCommand(
      LIFTOFF_BINARY, "sync " + Quoted(scratch / "A1.csv") + " --led-on 1 --liftoff 2", scratch);
  EXPECT_EQ(marked.code, kExitOk) << marked.err;
  EXPECT_THAT(marked.out + marked.err, Not(HasSubstr("no LED event")));
}

}  // namespace
}  // namespace liftoff::cli
