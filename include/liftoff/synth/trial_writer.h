// One synthetic trial on disk: the rendered video, the matching controller log, the
// ground truth (JSON) and the trial's manifest entry, from a TrialSpec.
//
// Files, in `output_dir`, named after the spec's id:
//   <id>.mp4 | .avi | .mkv   the video (codec from camera.codec)
//   <id>.csv                 the controller log (liftoff-log v1, docs/formats.md)
//   <id>.truth.json          the ground truth (GroundTruth::ToJson, docs/synth.md)
//
// Everything is a pure function of (spec, calibration): the same inputs give the same log
// and truth byte for byte, and the same video bytes for FFV1 and MJPEG. Frames are
// rendered and encoded one at a time, so memory stays flat in the clip's length.
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "liftoff/core/calibration.h"
#include "liftoff/core/manifest.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/status.h"
#include "liftoff/synth/spec.h"

namespace liftoff::synth {

/// What WriteTrial produced.
struct WrittenTrial {
  /// The three files, absolute or as `output_dir` was given.
  std::filesystem::path video_path, log_path, truth_path;
  /// The exact answer (also in truth_path).
  GroundTruth truth;
  /// The trial as a manifest entry: foot, rotation, pulled group, log, video and regions
  /// of interest; no event times (finding them is video analysis' job).
  TrialRecord manifest_entry;
  /// Wall time spent drawing frames and encoding them, s.
  double render_seconds = 0.0;
  double encode_seconds = 0.0;
};

/// The camera's nominal frame times, video clock, ns: slot k at k / fps for every slot
/// before duration_s; each slot after the first is dropped with camera.drop_probability
/// and moved by a uniform offset in +-camera.timestamp_jitter_s, all drawn from the
/// spec's seed. The first frame is at 0; times are strictly increasing.
std::vector<int64_t> FrameScheduleNs(const TrialSpec& spec);

/// Which frame's exposure first sees the LED, and for what fraction of that exposure
/// (1 when the switch-on falls between exposures). Fills truth.led_on_video_ns,
/// led_first_frame and led_first_frame_fraction from the frame times (the exposure of
/// frame i is [frame_times_ns[i], frame_times_ns[i] + exposure)). led_on_video_ns is empty
/// when the LED never switches on within [0, duration_s); the frame fields are empty too
/// when no exposure sees it.
void FillLedTruth(const TrialSpec& spec, const std::vector<int64_t>& frame_times_ns,
                  GroundTruth& truth);

/// Spool angle the synthetic log's bend reaches, rad: the angle at which the cable on the
/// largest groove is at 80 % of its length (the paper's P = 80 %), 0.2 * length / radius
/// of that groove; positive for HR, negative for HL (as the emulator signs it).
double BendSpoolTargetRad(const Calibration& calibration, CableGroup pulled_group);

/// Writes the trial's controller log to `path`, streaming: samples every 1 / log.rate_hz
/// on the device clock (the grid anchored at the LED switch-on), each moved by up to
/// +-log.jitter_s, kept only inside bursts when log.burst_period_s > 0, from lead_s before
/// the LED switch-on to tail_s after the clip's end. Each sample carries the LED state and
/// the raw counts of both motors quantised through `calibration` (the rotating vertebra
/// from Timeline::VertebraRadAt, the bend spool from Timeline::BendSpoolRadAt towards
/// BendSpoolTargetRad), and the angles those counts give. With log.led_event an led_on
/// event sits at log.led_on_device_ns; without it the log is 2018-style: its device clock
/// starts at the LED switch-on (led_on_device_ns must be 0), it has no samples before it
/// and every sample's LED flag is on, so sync takes the origin as the LED instant.
Status WriteTrialLog(const Timeline& timeline, const Calibration& calibration,
                     const std::filesystem::path& path);

/// Renders, encodes and records one trial into `output_dir` (created when missing;
/// existing files of the same names are replaced). kInvalidArgument for a spec that does
/// not validate (or led_event off with a non-zero led_on_device_ns); kIo when a file
/// cannot be written; the renderer's and encoder's errors otherwise.
Result<WrittenTrial> WriteTrial(const TrialSpec& spec, const Calibration& calibration,
                                const std::filesystem::path& output_dir);

}  // namespace liftoff::synth
