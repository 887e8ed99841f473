#include "liftoff/cli/video_commands.h"

#include <unistd.h>

#include <cassert>
#include <charconv>
#include <cmath>
#include <iostream>
#include <memory>
#include <optional>
#include <ostream>
#include <set>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_common.h"
#include "liftoff/cli/flags.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "liftoff/video/clip_analysis.h"
#include "liftoff/video/verification.h"

namespace liftoff::cli {
namespace {

// A region flag's "x,y,w,h" ("563,45,26,26"), px; kInvalidArgument naming the flag when
// it is not four integers with x, y >= 0 and w, h > 0.
Result<cv::Rect> RectFlag(std::string_view text, std::string_view flag) {
  const auto fail = [&] {
    return InvalidArgumentError(std::string(flag) + ": expected x,y,w,h in pixels (x, y >= 0; " +
                                "w, h > 0), got \"" + std::string(text) + "\"");
  };
  int values[4] = {0, 0, 0, 0};
  const char* at = text.data();
  const char* end = text.data() + text.size();
  for (int i = 0; i < 4; ++i) {
    const auto [next, error] = std::from_chars(at, end, values[i]);
    if (error != std::errc()) return fail();
    at = next;
    if (i < 3) {
      if (at == end || *at != ',') return fail();
      ++at;
    }
  }
  if (at != end || values[0] < 0 || values[1] < 0 || values[2] <= 0 || values[3] <= 0) {
    return fail();
  }
  return cv::Rect(values[0], values[1], values[2], values[3]);
}

// the analysis for people
void PrintAnalysis(const video::ClipAnalysis& analysis, std::ostream& out) {
  out << analysis.video_path.string() << " (" << analysis.width_px << "x" << analysis.height_px
      << "): " << analysis.timing.Brief() << '\n'
      << "LED: " << analysis.led.Brief() << '\n';
  if (!analysis.foot) {
    out << "foot: not analysed (no --foot-roi)\n";
  } else {
    const video::FootTrack& foot = *analysis.foot;
    out << "foot: " << foot.Brief() << '\n'
        << "rest window: " << FormatSeconds(analysis.rest_from_ns) << "-"
        << FormatSeconds(analysis.rest_to_ns) << " s (" << Plural(analysis.rest_frames, "frame")
        << "), noise " << FormatFixed(foot.rest_noise_px, 3) << " px, threshold "
        << FormatFixed(foot.threshold_px, 3) << " px";
    if (foot.px_per_mm > 0) {
      out << " at " << FormatFixed(foot.px_per_mm, 3) << " px/mm"
          << (foot.px_per_mm_estimated ? " (estimated from the foot's width)" : "");
    }
    out << '\n';
  }
  if (Result<EventTimes> events = analysis.Events(); events.ok()) {
    out << "events: LED on " << FormatSeconds(events->led_on_ns, 4) << " s +- "
        << FormatMilliseconds(events->led_on_uncertainty_ns) << ", liftoff ("
        << video::LiftoffInstantName(analysis.liftoff_instant) << ") "
        << FormatSeconds(events->liftoff_ns, 4) << " s +- "
        << FormatMilliseconds(events->liftoff_uncertainty_ns) << "; interval LED on -> liftoff "
        << FormatSeconds(events->liftoff_ns - events->led_on_ns, 4) << " s +- "
        << FormatMilliseconds(events->led_on_uncertainty_ns + events->liftoff_uncertainty_ns)
        << '\n';
  }
  for (const std::string& warning : analysis.warnings) out << "warning: " << warning << '\n';
}

}  // namespace

// ---------------------------------------------------------------------------------------
// a clip analysis' flags

namespace {

using ClipOptions = video::ClipAnalysisOptions;

// a region as its flag gives it ("x,y,w,h"); "" for none
std::string RegionText(const cv::Rect& region) {
  if (region.empty()) return "";
  return std::to_string(region.x) + "," + std::to_string(region.y) + "," +
         std::to_string(region.width) + "," + std::to_string(region.height);
}

// a region flag bound to the region `access` gives
template <typename Access>
FieldFlag<ClipOptions> RegionFlag(std::string flag, std::string field, Access access,
                                  std::string help) {
  return TextFlagOf<ClipOptions>(
      flag, std::move(field),
      [access](const ClipOptions& options) { return RegionText(access(options)); },
      [flag, access](ClipOptions& options, const std::string& text) -> Status {
        LIFTOFF_ASSIGN_OR_RETURN(access(options), RectFlag(text, flag));
        return Status::Ok();
      },
      "x,y,w,h", std::move(help));
}

std::vector<std::pair<std::string, Foot>> FootWords() {
  std::vector<std::pair<std::string, Foot>> words;
  for (Foot foot : kAllFeet) words.emplace_back(std::string(FootName(foot)), foot);
  return words;
}

// the whole of `text` as a finite number; nullopt otherwise
std::optional<double> FiniteNumber(std::string_view text) {
  double value = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size() || !std::isfinite(value)) {
    return std::nullopt;
  }
  return value;
}

// --rest-window FROM,TO, s from the LED switch-on: both ends of the rest window (their
// ranges and order are Validate()'s)
FieldFlag<ClipOptions> RestWindowFlag() {
  const std::string flag_name = "--rest-window";
  FieldFlag<ClipOptions> flag = TextFlagOf<ClipOptions>(
      flag_name, "rest_from_led_s",
      [](const ClipOptions& options) {
        return JoinNumbers({options.rest_from_led_s, options.rest_to_led_s}, ",");
      },
      [flag_name](ClipOptions& options, const std::string& text) -> Status {
        const size_t comma = text.find(',');
        const std::optional<double> from_s =
            comma == std::string::npos ? std::nullopt : FiniteNumber(text.substr(0, comma));
        const std::optional<double> to_s =
            comma == std::string::npos ? std::nullopt : FiniteNumber(text.substr(comma + 1));
        if (!from_s || !to_s) {
          return InvalidArgumentError(
              flag_name +
              ": expected FROM,TO in seconds relative to the LED switch-on, FROM < TO, each in "
              "[-60, 60] (e.g. -0.5,0), got \"" +
              text + "\"");
        }
        options.rest_from_led_s = *from_s;
        options.rest_to_led_s = *to_s;
        return Status::Ok();
      },
      "FROM,TO", "Foot rest window FROM,TO in s from the LED switch-on (write --rest-window=-1,0)");
  flag.scaled = true;  // two fields: the message keeps the field's name after the flag's
  flag.more_fields = {"rest_to_led_s"};
  return flag;
}

// --liftoff's words: the instants' own names
std::vector<std::pair<std::string, video::LiftoffInstant>> LiftoffWords() {
  std::vector<std::pair<std::string, video::LiftoffInstant>> words;
  for (const auto instant : {video::LiftoffInstant::kThreshold, video::LiftoffInstant::kOnset}) {
    words.emplace_back(std::string(video::LiftoffInstantName(instant)), instant);
  }
  return words;
}

}  // namespace

const std::vector<FieldFlag<video::ClipAnalysisOptions>>& ClipFlags() {
  using O = ClipOptions;
  static const std::vector<FieldFlag<O>> flags = {
      RegionFlag("--led-roi", LIFTOFF_FIELD(led.roi_px),
                 "LED region x,y,w,h in pixels (default: located automatically)"),
      RegionFlag("--foot-roi", LIFTOFF_FIELD(foot.foot_roi_px),
                 "Foot region x,y,w,h in pixels: the foot at rest and room above it (without "
                 "it: the LED only)"),
      ChoiceFlag<O>("--foot", LIFTOFF_FIELD(foot.tape_colour), FootWords(),
                    "Check that the tracked foot shows this foot's tape colour"),
      NumberFlag<O>("--px-per-mm", LIFTOFF_FIELD(foot.px_per_mm), kSameUnit,
                    "Image scale at the foot, px per mm (0: from the foot's width)"),
      NumberFlag<O>("--threshold-mm", LIFTOFF_FIELD(foot.threshold_mm), kSameUnit,
                    "Liftoff threshold above rest, mm"),
      NumberFlag<O>("--threshold-px", LIFTOFF_FIELD(foot.threshold_px), kSameUnit,
                    "Liftoff threshold above rest, px, in (0, 1000] (instead of "
                    "--threshold-mm)"),
      NumberFlag<O>("--exposure-ms", LIFTOFF_FIELD(led.exposure_s), kMillisecondsForSeconds,
                    "Camera exposure per frame, ms, at most the frame interval (0: unknown; "
                    "the LED then allows any exposure up to the frame interval, the foot takes "
                    "half the frame interval)"),
  };
  return flags;
}

const std::vector<FieldFlag<video::ClipAnalysisOptions>>& ClipInstantFlags() {
  using O = ClipOptions;
  static const std::vector<FieldFlag<O>> flags = {
      RestWindowFlag(),
      ChoiceFlag<O>("--liftoff", LIFTOFF_FIELD(liftoff), LiftoffWords(), "Liftoff instant"),
  };
  return flags;
}

Result<video::ClipAnalysisOptions> CheckedClipOptions(video::ClipAnalysisOptions options) {
  options.foot.exposure_s = options.led.exposure_s;  // --exposure-ms: the camera's, for both
  Status valid = NameFlagIn(options.Validate(), ClipFlags());
  valid = NameFlagIn(valid, ClipInstantFlags());
  if (!valid.ok()) return valid;
  return options;
}

// ---------------------------------------------------------------------------------------
// progress

Result<VideoProgress> VideoProgress::Create(std::string_view mode, std::ostream& err) {
  LIFTOFF_ASSIGN_OR_RETURN(ProgressLine line,
                           ProgressLine::Create(mode, "--progress", "video", err));
  return VideoProgress(std::move(line));
}

VideoProgress::VideoProgress(ProgressLine line)
    : line_(std::move(line)), started_ns_(MonotonicNowNs()) {}

void VideoProgress::Show(std::string_view label, int64_t frames_done, int64_t t_ns) {
  if (line_.off()) return;
  // each clip's rate from its own start
  const int64_t now_ns = MonotonicNowNs();
  if (label != label_) {
    label_ = label;
    started_ns_ = now_ns;
  }
  if (!line_.Due()) return;
  const double wall_s = SecondsFromNs(now_ns - started_ns_);
  line_.Show(std::string(label) + ": frame " + std::to_string(frames_done) + ", " +
             FormatSeconds(t_ns, 1) + " s of video, " +
             FormatFixed(static_cast<double>(frames_done) / std::max(wall_s, 1e-3), 0) +
             " frames/s");
}

void VideoProgress::Done() { line_.Clear(); }

Result<video::ClipAnalysis> AnalyzeClipShowingProgress(const std::filesystem::path& path,
                                                       const video::ClipAnalysisOptions& options,
                                                       VideoProgress& progress) {
  const std::string label = path.filename().string();
  auto analysis = video::AnalyzeClip(path, options, [&](int64_t frames_done, int64_t t_ns) {
    progress.Show(label, frames_done, t_ns);
  });
  progress.Done();
  return analysis;
}

// ---------------------------------------------------------------------------------------
// liftoff video

int RunVideo(const VideoCommand& command, std::ostream& out, std::ostream& err) {
  auto options = CheckedClipOptions(command.clip);
  if (!options.ok()) return ReportError(options.status(), err);
  auto progress = VideoProgress::Create(command.progress, err);
  if (!progress.ok()) return ReportError(progress.status(), err);
  if (const int refused = RefuseToOverwriteInputs(
          {{"--verify", command.verify_path}, {"--annotate", command.annotate_path}},
          {{"CLIP", command.video_path}}, err);
      refused != kExitOk) {
    return refused;
  }
  auto analysis = AnalyzeClipShowingProgress(command.video_path, *options, *progress);
  if (!analysis.ok()) return ReportError(analysis.status(), err);

  // proof, when asked for (a second decode)
  Status verified;
  video::VerificationReport verification;
  if (!command.verify_path.empty() || !command.annotate_path.empty()) {
    video::VerificationOptions verify_options;
    verify_options.image_path = command.verify_path;
    verify_options.video_path = command.annotate_path;
    auto written = video::WriteVerification(*analysis, verify_options);
    if (written.ok()) {
      verification = std::move(written).value();
    } else {
      verified = written.status();
    }
  }

  if (command.json) {
    nlohmann::json document = analysis->ToJson();
    document["verification"] = {{"image", verification.image_path.empty()
                                              ? nlohmann::json()
                                              : nlohmann::json(verification.image_path.string())},
                                {"video", verification.video_path.empty()
                                              ? nlohmann::json()
                                              : nlohmann::json(verification.video_path.string())}};
    out << document.dump(2) << '\n';
  } else {
    PrintAnalysis(*analysis, out);
  }
  if (!verified.ok()) return ReportError(verified, err);
  if (!verification.image_path.empty() || !verification.video_path.empty()) {
    err << "wrote " << verification.Brief() << '\n';
  }
  return kExitOk;
}

// ---------------------------------------------------------------------------------------
// liftoff table's verification images

namespace {

// a trial id as a file name: anything but letters, digits, '.', '_' and '-' becomes '_'
std::string SafeFileStem(const std::string& id) {
  std::string stem = id.empty() ? std::string("trial") : id;
  for (char& c : stem) {
    const bool keep = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                      c == '.' || c == '_' || c == '-';
    if (!keep) c = '_';
  }
  if (stem.front() == '.') stem.front() = '_';
  return stem;
}

std::string Lowercase(std::string text) {
  for (char& c : text) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return text;
}

}  // namespace

std::vector<std::string> TrialFileStems(const std::vector<std::string>& trial_ids) {
  std::vector<std::string> stems;
  std::set<std::string> taken;  // lowercase: unique on file systems that ignore case
  for (const std::string& id : trial_ids) {
    const std::string safe = SafeFileStem(id);
    std::string stem = safe;
    for (int suffix = 2; !taken.insert(Lowercase(stem)).second; ++suffix) {
      stem = safe + "-" + std::to_string(suffix);
    }
    stems.push_back(std::move(stem));
  }
  return stems;
}

TrialVerifications WriteTrialVerifications(const sync::ManifestAnalysis& analysis,
                                           const std::vector<std::string>& stems,
                                           const std::filesystem::path& dir, std::ostream& err) {
  TrialVerifications result;
  result.image_paths.resize(analysis.outcomes.size());
  result.errors.resize(analysis.outcomes.size());
  for (size_t i = 0; i < analysis.outcomes.size() && i < stems.size(); ++i) {
    const sync::TrialOutcome& outcome = analysis.outcomes[i];
    if (!outcome.video) continue;
    video::VerificationOptions options;
    options.image_path = dir / (stems[i] + ".png");
    auto written = video::WriteVerification(*outcome.video, options);
    if (!written.ok()) {
      const Status failure = written.status().WithContext(outcome.trial.id);
      err << "error: " << failure.ToString() << '\n';
      result.errors[i] = failure;
      if (result.first_failure.ok()) result.first_failure = failure;
      continue;
    }
    result.image_paths[i] = options.image_path;
    result.written.push_back(written->Brief());
  }
  return result;
}

// ---------------------------------------------------------------------------------------
// the flags

std::vector<Flag*> AddClipFlags(Command& app, video::ClipAnalysisOptions& clip) {
  std::vector<Flag*> added;
  Flag *threshold_mm = nullptr, *threshold_px = nullptr;
  for (const FieldFlag<video::ClipAnalysisOptions>& flag : ClipFlags()) {
    added.push_back(flag.add(app, clip));
    if (flag.flag == "--threshold-mm") threshold_mm = added.back();
    if (flag.flag == "--threshold-px") threshold_px = added.back();
  }
  assert(threshold_mm != nullptr && threshold_px != nullptr && "ClipFlags names both");
  threshold_px->Excludes(threshold_mm);
  return added;
}

Subcommand AddVideoCommand(Command& parent) {
  auto command = std::make_shared<VideoCommand>();
  Command* app = parent.AddSubcommand(
      "video", "Find the LED switch-on and the foot's liftoff in one clip, with proof");
  app->AddOption("clip", command->video_path, "Video file")->Required();
  AddClipFlags(*app, command->clip);
  AddFlags(*app, ClipInstantFlags(), command->clip);
  app->AddOption("--verify", command->verify_path, "Write a verification image (PNG)");
  app->AddOption("--annotate", command->annotate_path,
                  "Write the clip with the detections drawn (Motion JPEG AVI)");
  app->AddSwitch("--json", command->json, "JSON output");
  app->AddOption("--progress", command->progress, "Progress on stderr: auto, live, lines or off")
      ->ShowDefault();
  return RunsWith(app, command, RunVideo);
}

}  // namespace liftoff::cli
