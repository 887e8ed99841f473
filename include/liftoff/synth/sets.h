// Named sets of synthetic trials. "ci" is the video pipeline's test set: a fixed list of
// short clips that together exercise every nuisance and option of a TrialSpec at least
// once, plus the invalid inputs of the pipeline's error tests. Sets are generated at test
// time (`liftoff synth --set ci -o DIR`); no video is committed.
//
// A written set's folder holds each trial's video, log and truth (trial_writer.h), the
// invalid inputs, `manifest.json` (the valid trials as a trial manifest) and `set.json`
// (the index: every file, every truth, what each clip exercises; docs/synth.md).
#pragma once

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <string_view>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/status.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/trial_writer.h"

namespace liftoff::synth {

/// The CI set's valid trials, in a fixed order with fixed seeds (docs/synth.md lists them).
/// Every clip is short: mostly a 0.2 rad/s ramp starting 0.2 s after the LED at 0.61 s, the
/// foot 1 mm up 1.46-3.84 s into the clip, which ends 0.4 s later; mostly 640x480. Ids are
/// "ci-NN-what". The csv-curve trial names "ci-height-curve.csv" relative to the set's
/// folder; WriteSet writes that file there and resolves the path.
std::vector<TrialSpec> CiSet();

/// One input the video pipeline must reject, and how to make it.
struct InvalidInput {
  enum class Kind {
    kRendered,   ///< `spec` rendered as a trial (video, log and truth)
    kTruncated,  ///< `spec` rendered, then only the first keep_fraction of the video's bytes kept
    kNotAVideo,  ///< a file with a video's extension that holds no video
  };
  /// File stem: "invalid-led-never-on".
  std::string id;
  Kind kind = Kind::kRendered;
  /// The error the video pipeline must report for it.
  StatusCode expected_error = StatusCode::kNotFound;
  /// One line for people: "the LED never switches on".
  std::string what;
  /// The clip (kRendered, kTruncated); its id equals `id`.
  TrialSpec spec;
  /// kTruncated: fraction of the video's bytes kept (0 .. 1).
  double keep_fraction = 1.0;
};

/// The CI set's invalid inputs: LED never on (kNotFound), foot never lifts (kNotFound),
/// truncated file (kParse), not a video (kParse).
std::vector<InvalidInput> CiInvalidInputs();

/// What a trial exercises beyond the CI baseline, as short tags ("1280x720", "h264",
/// "vfr-drops", "flicker-60hz", ...), for set.json and the docs.
std::vector<std::string> DescribeVariations(const TrialSpec& spec);

/// The trials of a named set: "ci" (CiSet), "paper" (four full-length 720p trials, one
/// per foot, the paper's ramp and default nuisances). kNotFound naming the known sets.
Result<std::vector<TrialSpec>> SetByName(std::string_view name);

/// Progress of WriteSet, reported before each file is made.
struct SetProgress {
  /// 0-based position and the number of items (valid trials + invalid inputs).
  int index = 0;
  int count = 0;
  std::string id;
};

struct SetSummary {
  std::string name;
  std::filesystem::path output_dir;
  /// manifest.json (valid trials) and set.json (index).
  std::filesystem::path manifest_path, index_path;
  /// The valid trials written, in set order.
  std::vector<WrittenTrial> trials;
  /// The invalid inputs' files (the video, or the non-video), in CiInvalidInputs order.
  std::vector<std::filesystem::path> invalid_paths;
  /// Frames rendered (valid and invalid clips), and the time spent on them, s.
  int64_t frames = 0;
  double render_seconds = 0.0;
  double encode_seconds = 0.0;
  double wall_seconds = 0.0;

  /// "ci: 24 trials + 4 invalid inputs, 5210 frames in 21.4 s (render 2.1 ms/frame,
  /// encode 1.3 ms/frame)".
  std::string Brief() const;
};

/// Writes every trial of set `name` (and, for "ci", its invalid inputs) into
/// `output_dir`, then manifest.json and set.json. Items are written on up to two threads
/// (one per core); the files do not depend on the thread count. `progress` (may be empty)
/// is called as each item starts, from the thread that takes it, never two at a time.
/// Errors of SetByName and WriteTrial, with the item's id in front; after a failure no
/// further item is started.
Result<SetSummary> WriteSet(std::string_view name, const Calibration& calibration,
                            const std::filesystem::path& output_dir,
                            const std::function<void(const SetProgress&)>& progress = {});

}  // namespace liftoff::synth
