#include "liftoff/video/led_detector.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <numeric>
#include <optional>
#include <utility>

#include "cell_sums.h"
#include "led_timing.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "video_util.h"

namespace liftoff::video {
namespace {

using internal::ExposureRange;
using Grid = internal::CellGrid;
using internal::InstantInterval;
using internal::LitFraction;
using internal::MeasureCells;
using internal::RectText;

// Frames before a step that must be flat.
constexpr int kBeforeFrames = 4;
// A window is flat when its spread is at most this fraction of the step: stricter when
// locating (every region of the frame competes) than in a given ROI (the LED is there;
// camera shake moves the ROI's surroundings through it).
constexpr double kFlatFracLocated = 0.25;
constexpr double kFlatFracRoi = 0.35;
// Smallest step of a region's mean looked at, grey levels.
constexpr double kMinStepLevels = 0.05;
// A region's two-frame jump must also exceed this many times its usual frame-to-frame
// change (an average over about kNoiseFrames frames before the step).
constexpr double kNoiseFactor = 4.0;
constexpr double kNoiseFrames = 16.0;
// A step must stand out from what the whole frame did at that instant (codec key frames,
// exposure changes and camera shake step many regions at once, an LED few): its jump at
// least kOutlierFactor times the 90th percentile of every region's sharp jump, the part of
// its two-frame jump that the changes just before and after it do not explain (a moving
// object changes a region every frame, so its sharp jump is small).
constexpr double kOutlierFactor = 3.0;
constexpr double kOutlierQuantile = 0.9;
constexpr size_t kQuantileSamples = 1000;
// The located LED: among the steps whose brightest-channel contrast is at least this
// fraction of the best one, the largest.
constexpr double kEligibleContrastFrac = 0.5;
// Located steps must look like a light: in the 4 x 4 cells around the block, those that
// step the other way do so by at most kOppositeFrac of the block's step in all, and the
// cells stepping by kExtentFrac of the largest cell step or more span about as many
// columns as rows (within one).
constexpr double kOppositeFrac = 0.5;
constexpr double kExtentFrac = 0.3;
// A step is confirmed when the region then holds its new level (or goes back to the old
// one: a short pulse) for this many more frames, at most one frame in between (a foot
// passing through a region at speed can look like a step for a few frames, then moves on).
constexpr int kConfirmFrames = 8;
// Flicker: each cell's level is followed by an average over about this many frames; the
// frame's gain is the median of the cells' ratios to it (cells darker than
// kGainMinLevels grey levels are left out).
constexpr double kReferenceFrames = 64.0;
constexpr double kGainMinLevels = 10.0;
// Automatic locating samples every other row (internal::kCellRowStep); the gain uses every
// other cell column and row. With an ROI, the frame-wide statistics use every
// kReferenceStride-th cell.
constexpr int kGainStride = 2;
constexpr int kReferenceStride = 4;
// A measured fraction of the exposure is known to within max(sigmas * its noise, margin)
// (3 sigmas of a frame's noise: the frame's own and that of the two levels it is measured
// between, medians of a few frames); the margin covers what noise estimates from a few
// frames miss (codec effects at the step), so a frame lit 92 % or more may have been lit
// all along.
constexpr double kFractionSigmas = 3.0;
constexpr double kFractionMargin = 0.08;
// A frame next to the step counts as partly lit above this fraction (or the noise band):
// H.264's B-frames borrow a little of the next frame's light, so the frame before a
// switch-on can look lit by a few percent.
constexpr double kLitFraction = 0.15;
// With an ROI, the detection signal sums the largest brightness changes of this many
// pixels: a 256th of the ROI (a person draws it around the LED with a margin that grows
// with the LED), at least 9 (a light of 1 px radius and its glow).
constexpr size_t kTopPixelsMin = 9;
constexpr size_t kTopPixelsShare = 256;
// The pixels of a step: those whose step is above this many times a pixel's noise and
// this fraction of the largest pixel step; pixels stepping the other way by more than
// kRoiOppositeFrac of their total make it no light (an edge moved).
constexpr double kPixelNoiseSigmas = 5.0;
constexpr double kPixelStepFrac = 0.1;
constexpr double kRoiOppositeFrac = 0.5;
// But a small light (its strong steps, kRoiStrongFrac of the largest or more, summing at
// least kSmallLightShare of their total within the (2 kSmallLightRadiusPx + 1) px square
// centred on the largest) is one when the strong steps the other way stay under that share: a codec
// renewing a tiny LED's block moves many pixels a little either way, and a few of them strongly
// (H.264 stepped a pixel 4 px beside hard3d-06's 0.6 px LED, --seed 5000, by a third of the LED's
// own step).
constexpr double kRoiStrongFrac = 0.3;
constexpr int64_t kSmallLightRadiusPx = 3;
constexpr double kSmallLightShare = 0.8;
// With an ROI, its outer kBorderPx px are left out of the detection (camera shake carries
// an edge or a highlight from just outside the ROI into it, where it looks like a light
// that switched on), narrower in an ROI under 2 * kBorderPx + kMinInnerPx px.
constexpr int kBorderPx = 3;
constexpr int kMinInnerPx = 10;
// With an ROI, each row's flicker gain leaves out pixels brighter than this many times
// the frame's gain (a light that switched on, not the lamp's flicker, up to +-50 %).
constexpr double kRowRatioMax = 1.6;
// The row beside the ROI is sampled every kStripStepPx px, and used when that gives at
// least kStripMinSamples samples a row.
constexpr int kStripStepPx = 16;
constexpr size_t kStripMinSamples = 8;
// With an ROI, a row of the frame's cells changes gain between two frames by the median of
// its cells' ratios, from at least this many cells (else the frame's gain).
constexpr size_t kRowRatioMinCells = 3;
// A row gain under this (a black frame) is not divided by.
constexpr double kMinRowGain = 0.05;
// Rows share their flicker gain in bands of this many.
constexpr int kGainBandRows = 4;
// With an ROI the region's signal is read two ways, each a "region" of its own: the
// changes with the scene's flicker taken out (an LED on its own supply, as on the robot),
// and the pixels divided by their row's gain (a renderer's or a camera's flicker that
// scales the LED's light with the picture: strong flicker swings the first reading's lit
// frames beyond a step's flatness). The first wins wherever it finds a switch-on of about
// the best contrast (ChooseRoiSignal).
constexpr int kRoiOwnLight = 0;
constexpr int kRoiScaledLight = 1;
constexpr int kRoiSignals = 2;
// A lit pixel whose brightest channel reaches this level clips (a codec's rounding keeps a
// clipped pixel within 2 levels of 255) (a partly lit frame then
// looks brighter than its fraction); such pixels are left out of the dating series unless
// the others carry less than kUnclippedShare of the step.
constexpr double kClipLevels = 253.0;
constexpr double kUnclippedShare = 0.25;
// The pixels of a light hold their levels much better than a whole region: the frames
// before and after a step must stay within this fraction of it.
constexpr double kFlatFracPixels = 0.2;
// The LED's pixels: the frame just before a step may be lit up to this fraction and be left
// out of the frames before (a codec building a small spot up over frames made re-drawn
// hard3d-06's half-lit frame, --seed 6000, 57 % of the step in its pixels, and the frame
// before it was not yet a step).
constexpr double kPartlyLitBeforeFrac = 0.75;
// A dim step (under dim_warning_levels) through a lossy codec: a frame's lit fraction is
// known to within this either way.
constexpr double kDimCodecFrac = 0.5;
// The frames after a step may go on in its direction by at most this fraction of it (a
// codec refines a small bright spot over a few frames), during its confirmation too.
constexpr double kCreepFrac = 0.5;
// With an ROI, a step whose contrast does not stand out from the frame's (a codec renewed
// much of the picture at that frame) still counts when its largest pixel step is at least
// this many times the 90th percentile of the ROI's pixel steps (at least kStandoutFloor, a
// grey level in each channel): a frame-wide change moves the ROI's other pixels as much,
// a light only its own.
constexpr double kLocalStandout = 4.0;
constexpr double kStandoutFloor = 3.0;
// The LED's contrast with an ROI: the brightest-channel step of its pixel of this rank
// (0: the largest; 2 ignores two noisy pixels and keeps a light of 3 px).
constexpr size_t kContrastRank = 2;
// A region that stepped to a level steps again in the same direction only by more than
// this many times that step.
constexpr double kStrongerFactor = 3.0;
// Intervals kept for the usual frame interval (the bound of an unknown exposure).
constexpr size_t kIntervalWindow = 31;
// With an ROI, a build-up: the LED's pixels leave their old level and reach the new one over
// at most this many frames (a codec holding a small spot at a partial level, or wobbling).
constexpr int kBuildUpFrames = 12;
// Recorded steps per region at most (a region that keeps stepping is no sync LED).
constexpr size_t kMaxEventsPerRegion = 4096;

// Per pixel of a width_px x height_px ROI: 1 unless within the border band (kBorderPx).
std::vector<uint8_t> InnerMask(int width_px, int height_px) {
  const int band = std::clamp((std::min(width_px, height_px) - kMinInnerPx) / 2, 0, kBorderPx);
  std::vector<uint8_t> inner(static_cast<size_t>(width_px) * static_cast<size_t>(height_px), 0);
  for (int y = band; y < height_px - band; ++y) {
    for (int x = band; x < width_px - band; ++x) {
      inner[static_cast<size_t>(y) * static_cast<size_t>(width_px) + static_cast<size_t>(x)] = 1;
    }
  }
  return inner;
}

// Every how many of `count` values a quantile looks at (about kQuantileSamples of them).
size_t SampleStride(size_t count) { return std::max<size_t>(1, count / kQuantileSamples); }

// The shape of a window of a series around a step at its frame `before_count` (or a
// build-up over the `gap` frames from there; 1 for a step): the levels before and after (medians),
// the step between them (positive in the step's direction), the spread of the frames before (the
// last one left out when it is already up to threshold_frac of the way: a codec's B-frame borrows
// light from the next frame), how far the frames after fall back against the step, and how far they
// go on in its direction (a codec refines a small bright spot over a few frames).
struct WindowShape {
  double before_level = 0.0, after_level = 0.0, step = 0.0;
  double before_spread = 0.0, after_against = 0.0, after_creep = 0.0;
};

WindowShape ShapeOf(const double* values, int before_count, int gap, int after_count, bool rise,
                    double threshold_frac, std::vector<double>& scratch) {
  const double sign = rise ? 1.0 : -1.0;
  const auto before = static_cast<size_t>(before_count);
  const auto after_first = before + static_cast<size_t>(gap);
  const auto after = static_cast<size_t>(after_count);
  WindowShape shape;
  scratch.assign(values, values + after_first + after);
  shape.before_level = MedianOf(scratch.data(), before_count);
  shape.after_level = MedianOf(scratch.data() + after_first, after_count);
  shape.step = sign * (shape.after_level - shape.before_level);
  size_t flat_before = before;
  if (before >= 3) {
    scratch.assign(values, values + before - 1);
    const double earlier = MedianOf(scratch.data(), before_count - 1);
    const double ahead = sign * (values[before - 1] - earlier);
    if (ahead > 0 && ahead < threshold_frac * shape.step) flat_before = before - 1;
  }
  const auto [low, high] = std::minmax_element(values, values + flat_before);
  shape.before_spread = *high - *low;
  double furthest = -std::numeric_limits<double>::infinity();
  double least = std::numeric_limits<double>::infinity();
  for (size_t i = after_first; i < after_first + after; ++i) {
    const double along = sign * values[i];
    furthest = std::max(furthest, along);
    shape.after_against = std::max(shape.after_against, furthest - along);
    least = std::min(least, along);
    shape.after_creep = std::max(shape.after_creep, along - least);
  }
  return shape;
}

// How far a window's levels are from flat, against the limits a light's pixels must keep
// (kFlatFracPixels of the step either side, kCreepFrac after it): under 1 passes.
double Roughness(const WindowShape& shape) {
  if (!(shape.step > 0)) return std::numeric_limits<double>::infinity();
  return std::max(std::max(shape.before_spread, shape.after_against) / kFlatFracPixels,
                  shape.after_creep / kCreepFrac) /
         shape.step;
}

enum class Level : uint8_t { kUnknown, kLow, kHigh };

// One step a region made, with what is needed to date it: the frames around it.
struct StepEvent {
  int region = 0;
  bool rise = true;
  // the detection signal's levels, which confirmation watches
  double signal_step = 0.0;
  double signal_off = 0.0, signal_on = 0.0;
  // the dating series (`value`, per frame of the window): linear in the LED's lit
  // fraction; its levels off and on and its noise; clipped: the LED's pixels clip when
  // lit, so a partly lit frame may look brighter than its fraction
  double off = 0.0, on = 0.0;
  double noise = 0.0;
  bool clipped = false;
  // how far the frames after the step went on in its direction, as a fraction of the step
  // (the lit level may be higher still: a partly lit frame may have been less lit)
  double creep = 0.0;
  double contrast_levels = 0.0;  // brightest channel step
  double standout = 0.0;  // with an ROI: largest pixel step over the ROI's usual (kLocalStandout)
  double off_levels = 0.0, on_levels = 0.0;  // the region's mean, grey levels
  int64_t period_ns = 0;         // usual frame interval at the time
  // with an ROI: the frames between the levels of a build-up (from index[kBeforeFrames] on;
  // 1 for a step), whose first one's lit fraction a codec may have held at any level
  int build_up_frames = 1;
  std::vector<int64_t> index, t_ns;
  std::vector<double> value;
  std::array<float, 16> cell_steps{};  // auto: the 4 x 4 cells around the block
  // while it is being confirmed: frames still to watch, frames seen between the levels,
  // and the region's level before it
  int frames_to_confirm = 0;
  int between = 0;
  Level level_before = Level::kUnknown;
  float level_step_before = 0.0f;
};

// Whether `event` is a rise of the LED's own light (kRoiOwnLight) whose step came after
// t_ns (its last frame before the step is later).
bool OwnRiseAfter(const StepEvent& event, int64_t t_ns) {
  return event.region == kRoiOwnLight && event.rise && event.t_ns[kBeforeFrames - 1] > t_ns;
}

}  // namespace

Status LedDetector::Options::Validate() const {
  if (roi_px.width < 0 || roi_px.height < 0 || (roi_px.width == 0) != (roi_px.height == 0)) {
    return InvalidArgumentError(
        "roi_px: expected an empty region (0 x 0: locate the LED) or a "
        "positive width and height, got " +
        RectText(roi_px));
  }
  if (cell_px < 4 || cell_px > 64) {
    return InvalidArgumentError("cell_px: expected 4 .. 64, got " + std::to_string(cell_px));
  }
  if (!(threshold_frac > 0.0 && threshold_frac < 1.0)) {
    return InvalidArgumentError("threshold_frac: expected 0 < x < 1, got " +
                                FormatNumber(threshold_frac));
  }
  if (min_on_frames < 1 || min_on_frames > 100) {
    return InvalidArgumentError("min_on_frames: expected 1 .. 100, got " +
                                std::to_string(min_on_frames));
  }
  if (!(min_contrast_levels > 0.0 && min_contrast_levels <= 255.0)) {
    return InvalidArgumentError("min_contrast_levels: expected 0 < x <= 255, got " +
                                FormatNumber(min_contrast_levels));
  }
  if (!(dim_warning_levels >= min_contrast_levels && dim_warning_levels <= 255.0)) {
    return InvalidArgumentError("dim_warning_levels: expected min_contrast_levels .. 255, got " +
                                FormatNumber(dim_warning_levels));
  }
  if (!(exposure_s >= 0.0 && exposure_s <= 1.0)) {
    return InvalidArgumentError("exposure_s: expected 0 (unknown) .. 1 s, got " +
                                FormatNumber(exposure_s));
  }
  return Status::Ok();
}

std::string LedResult::Brief() const {
  if (pulses.empty()) return "LED not found";
  const LedPulse& first = pulses.front();
  std::string text = "LED on at " + FormatFixed(SecondsFromNs(first.on_ns), 4) + " s +- " +
                     FormatFixed(static_cast<double>(first.on_uncertainty_ns) * 1e-6, 1) +
                     " ms (frame " + std::to_string(first.first_lit_frame) + ", " +
                     FormatFixed(100.0 * first.first_lit_fraction, 0) + " % lit), ROI " +
                     RectText(roi_px) + (roi_located ? " (located)" : "") + ", " +
                     Plural(static_cast<int64_t>(pulses.size()), "pulse");
  if (!warnings.empty()) text += ", " + Plural(static_cast<int64_t>(warnings.size()), "warning");
  return text;
}

struct LedDetector::Impl {
  Options options;
  Status options_status;
  bool located = false;  // automatic locating (no ROI given)

  // geometry, fixed by the first frame: the cells (every cell when locating, a sparse
  // reference lattice with an ROI) and the regions (2 x 2 blocks of cells, or the ROI)
  int width_px = 0, height_px = 0;
  Grid grid;
  int block_columns = 0;
  int regions = 0;
  double pixels_per_region = 0.0;  // pixels summed per region (sampled rows)

  // the last `ring` frames: times, flicker gains, the cells' flicker-corrected sums and
  // brightest channels, the regions' sums (and the ROI's brightest channel). A step is
  // judged on a `window` of them (kBeforeFrames, the step, after_frames); with an ROI the
  // ring is longer, for a build-up (kBuildUpFrames)
  int after_frames = 3;
  int window = 0;
  int ring = 0;
  int64_t frames = 0;
  std::vector<int64_t> ring_index, ring_t_ns;
  std::vector<double> ring_gain;
  std::vector<float> cell_sums;     // ring x cells
  std::vector<uint8_t> cell_peaks;  // ring x cells
  std::vector<double> region_sums;  // ring x regions

  // with an ROI: its last `ring` pictures (B, G, R), each pixel's reference brightness
  // (B + G + R, following the frames that leave the step window, so a step is measured
  // against frames before it; a build-up's later frames against a reference that has taken
  // in its first ones at 1/64 a frame), how many of the largest changes the signal sums,
  // scratch
  std::vector<uint8_t> roi_pictures;  // ring x ROI pixels x 3
  std::vector<float> pixel_reference;
  int64_t reference_frames = 0;
  size_t top_pixels = 0;
  std::vector<uint8_t> inner;  // per ROI pixel: 1 inside the border band (see kBorderPx)
  std::vector<float> changes, scaled_changes;
  std::vector<float> row_gains;  // ring x ROI rows
  std::vector<float> row_ratios;
  std::vector<float> band_gains;
  std::vector<size_t> strip_columns;  // frame columns beside the ROI sampled for row gains
  std::vector<float> strip_reference;  // ROI rows x strip columns
  std::vector<float> strip_ring;       // ring x ROI rows x strip columns
  std::vector<float> corrected;  // ROI pixels x ring
  std::vector<double> pixel_steps, channel_steps, lit_peaks, pixel_wobble;
  std::vector<double> dating_series, scaled_series;
  // with an ROI: every frame's time and the ROI's mean brightness (the trace in LedResult)
  double roi_mean_levels = 0.0;
  std::vector<int64_t> trace_t_ns;
  std::vector<double> trace_brightness_levels;

  // per cell and region: the flicker reference, the usual frame-to-frame change, the level
  std::vector<float> cell_reference;
  std::vector<float> region_noise;
  std::vector<Level> level;
  std::vector<float> level_step;  // the step that set the level

  // the frame being measured (raw cell sums and peaks), scratch for medians and quantiles
  std::vector<float> raw_sums;
  std::vector<float> ratios;
  std::vector<double> jumps;
  std::vector<double> window_values, window_copy;
  std::vector<uint8_t> window_peaks;
  std::vector<float> window_sums;

  std::array<int64_t, kIntervalWindow> intervals_ns{};
  size_t interval_count = 0;
  int64_t last_t_ns = 0;

  std::vector<StepEvent> events;   // confirmed
  std::vector<StepEvent> pending;  // being confirmed
  std::vector<uint32_t> events_per_region;
  // the best switch-on that was too faint, for the "never switches on" message
  double rejected_contrast = -1.0;
  int rejected_region = -1;

  size_t Slot(int64_t frame) const { return static_cast<size_t>(frame % ring); }
  // index of a region's sum at a frame in region_sums
  size_t RegionSlot(int region, int64_t frame) const {
    return Slot(frame) * static_cast<size_t>(regions) + static_cast<size_t>(region);
  }
  double FlatFrac() const { return located ? kFlatFracLocated : kFlatFracRoi; }
  size_t Cells() const { return static_cast<size_t>(grid.cells()); }

  cv::Rect RegionRect(int region) const;

  Status Setup(const Frame& frame);

  // the frame's brightness against the cells' references: flicker of the lighting scales
  // the whole scene (not the LED's own light), so it is taken out additively
  double Gain();

  void Measure(const Frame& frame, size_t slot);

  uint8_t* RoiPicture(size_t slot);

  // the frame leaving the step window joins each ROI pixel's reference brightness (and the
  // strips' beside it)
  void FollowReference(const uint8_t* picture, const float* strip);

  float* StripSamples(size_t slot) { return &strip_ring[slot * strip_reference.size()]; }

  // the frame's rows beside the ROI (B + G + R every kStripStepPx px)
  void SampleStrips(const cv::Mat& bgr, float* strip) const;

  float* RowGains(size_t slot);

  // each row's gain: mains flicker seen by a rolling shutter bands the rows. The median
  // ratio of the frame's row beside the ROI (every kStripStepPx px) to its reference, so
  // the LED, however large in its ROI, never counts; the frame's gain where the row beside
  // the ROI is too short or too dark. An ROI as wide as the frame uses its own row instead,
  // leaving out pixels brighter than kRowRatioMax times the frame's gain (a lit light).
  void MeasureRowGains(const uint8_t* picture, const float* strip, double gain, float* gains);

  // the ROI's rows in bands of kGainBandRows (banding changes slowly from row to row), each
  // measured on all its rows and taken for its middle row; rows between are interpolated
  int GainBands() const { return (options.roi_px.height + kGainBandRows - 1) / kGainBandRows; }
  int BandRow(int band) const;

  // with an ROI, the detection signals (kRoiSignals of them) into `sums`: the sum of the
  // top_pixels largest increases of B + G + R over each pixel's reference (the scene's part
  // scaled by its row's gain), plus the top_pixels largest decreases (negative); the same
  // with each change divided by its row's gain. A light switching on raises them,
  // switching off lowers them, and however small the light, its pixels are among those
  void MeasureRoi(const cv::Mat& bgr, size_t slot, double gain, double* sums);
  // the sum of the top_pixels largest and the top_pixels smallest of `values` (reordered)
  double ExtremeChanges(std::vector<float>& values) const;

  // Whether the pixels that stepped strongly (kRoiStrongFrac of the largest step or more)
  // are a small light, most of them near the largest, that the strong steps the other way
  // do not match: a codec that renews a tiny LED's block moves many pixels a little either
  // way (too many for the sum of every clear step), where an edge that moved steps its two
  // sides strongly along its length. Reads pixel_steps.
  bool SmallLightInRenewedBlock(double largest, size_t width) const;

  // with an ROI: which pixels stepped at k, from the pictures around it. The dating series
  // sums the pixels that brightened (rise) or darkened (fall) clearly, leaving out those
  // that clip when lit unless they carry most of the step (then the event is marked
  // clipped). False when the step does not look like a light: pixels stepping the other
  // way by a good part of it (an edge moved by camera shake or a passing part).
  // A build-up: the `gap` frames from k on (1 for a step) lie between the levels.
  bool MeasureRoiStep(int64_t k, int gap, bool rise, StepEvent& event);
  // Each ROI pixel's step at frame k (pixel_steps, channel_steps, lit_peaks, pixel_wobble;
  // its gain-corrected series in `corrected`); the sums of the pixels' off and on levels.
  void MeasurePixelSteps(int64_t k, int gap, bool rise, double& off_sum, double& on_sum);
  // The dating series (dating_series) over the frames [k - kBeforeFrames, + count): the sum of
  // the pixels that stepped beyond `clear` (those that clip when lit only when `clipped`),
  // each with the scene's flicker taken out; and the same pixels divided by their row's
  // flicker gain (scaled_series): a light the flicker scales with the scene.
  // False (scaled_series left at 0) where a row's gain is under kMinRowGain (a black frame).
  bool SumDatingSeries(int64_t k, size_t count, double clear, bool clipped);
  // the quantile q of |pixel_steps| over the ROI's inner pixels
  double InnerQuantile(double q);

  int64_t PeriodNs() const;

  // what a step's jump must exceed to stand out from the frame at k (with an ROI: the
  // reference cells' sharp jumps, scaled to the ROI's size)
  double OutlierJump(int64_t k);

  // the median ratio of a row of cells' brightest channels, next over previous (cells
  // darker than kGainMinLevels or clipped left out), or `fallback` from under
  // kRowRatioMinCells cells
  double RowRatio(const uint8_t* previous, const uint8_t* next, double fallback);

  // what a step's contrast must reach to stand out from the frame at k: the brightest
  // channel of most cells stays put, except where many step together
  double OutlierContrast(int64_t k);

  // the step test for frame k = newest - after_frames, every region
  void Evaluate();

  // With an ROI: a switch-on that a codec built up over 2 .. kBuildUpFrames frames (a small
  // spot held at a partial level, or wobbling, before it settles), which no window of one
  // step frame sees as clean: the kBeforeFrames frames before at the old level, the newest
  // after_frames at the new one, every frame between lit (above kLitFraction of the step,
  // above the new level by at most kCreepFrac of the step). The longest such build-up ending now
  // is tested as a step is (it stands out, looks like a light, enough contrast, then holds)
  // and replaces the steps still being confirmed that began after its second frame.
  void TestBuildUp();
  // the shape of `region`'s sums over the window of a step at k (a build-up of `gap` frames
  // from k; 1 for a step; the window in window_values) when it steps by min_step or more and
  // is flat before and after; nullopt otherwise
  std::optional<WindowShape> FlatShape(int region, int64_t k, int gap, bool rise,
                                       double threshold_frac, double min_step);
  // the signal's shape for a build-up of `gap` frames from `first`, when it is one
  std::optional<WindowShape> BuildUpShape(int64_t first, int gap, double min_step);
  // whether a rise of `step` may start at `first`: the ROI is not at a high level, or only
  // by a fainter step (as in Evaluate: kStrongerFactor), or by a step still being confirmed
  // that began after `first` (not one whose partly lit frame before it is `first`: that step
  // dates the same frame, its fraction measured)
  bool RiseMayStartAt(int64_t first, double step) const;
  // drops the rises still being confirmed that began after `first` (as RiseMayStartAt), the
  // ROI's level back to what the earliest of them found
  void DropRisesAfter(int64_t first);

  // the step of one series of the ring (medians of the windows before and after k),
  // signed so that the step's direction is positive
  template <typename T>
  double WindowStep(const std::vector<T>& series, size_t stride, size_t offset, int64_t k,
                    bool rise, std::vector<T>& scratch) const;

  // located: the LED's own contrast, grey levels: the step of the brightest channel of the
  // block's best cell, or of its mean where that is larger (a brighter object beside the
  // LED hides its brightest pixel)
  double Contrast(int region, int64_t k, bool rise);

  // a step of `region` at frame k becomes a pending event when it is clean, stands out
  // from the frame's other regions and looks like a light
  void TestStep(int region, int64_t k, bool rise, double min_step, double jump,
                double& outlier_jump, double& outlier_contrast);
  // the region's window around k: a step of at least min_step, flat on both sides, whose
  // frames cross the threshold only at k; nullopt otherwise
  std::optional<WindowShape> CleanStep(int region, int64_t k, bool rise, double min_step);
  // the event pending confirmation (described); its region takes the new level meanwhile
  void AddPending(StepEvent event);
  // the event's signal, frames and (located) levels; false when it does not look like a light
  // (`gap` frames from k on between the levels: 1 for a step)
  bool DescribeEvent(int region, int64_t k, int gap, bool rise, const WindowShape& shape,
                     double contrast, StepEvent& event);

  // the step of each of the 4 x 4 cells around the block (medians of the same windows)
  void RecordCellSteps(StepEvent& event, int64_t k);

  // the steps being confirmed against the newest frame: confirmed ones join `events`,
  // rejected ones give their region back its level
  void Confirm(size_t slot);

  // a light switching is local and one-signed: the cells around the block do not step the
  // other way (an edge moving by, with camera shake or a passing foot, darkens one side as
  // it brightens the other), and its step is about as wide as it is tall (an edge or a
  // band shifted across the region steps a row or a column of cells)
  static bool LooksLikeALight(const StepEvent& event);

  Status Process(const Frame& frame);

  // the instant of one step, from its frames
  // A frame partly lit by a switch-on is followed by a fully lit one (an exposure of at most
  // the frame interval cannot be partly lit twice), so the frame before a partly lit one is
  // not taken for the partly lit frame, however much light a codec lent it.
  LedPulse DatePulse(const StepEvent& event) const;

  // located: a square of the block's size around the centroid of the cells' steps
  cv::Rect LocatedRect(const StepEvent& event) const;

  // the LED's region: among the switch-ons with a brightest-channel contrast near the best
  // one, the largest step
  static int ChooseRegion(const std::vector<const StepEvent*>& steps);
  // with an ROI, the signal whose switch-ons are the LED's: among the switch-ons with a
  // contrast near the best one (as ChooseRegion), kRoiOwnLight's where it has one, else
  // kRoiScaledLight's (the moving part that the first reading took for a switch-on under
  // +-50 % bands had less than half the contrast of the LED only the second found); -1: none
  static int ChooseRoiSignal(const std::vector<const StepEvent*>& steps);

  Result<LedResult> Finish() const;
  // Why no step of `steps` (in the order they happened) is a switch-on seen `where`.
  Status NoSwitchOn(const std::vector<const StepEvent*>& steps, const std::string& where) const;
};

cv::Rect LedDetector::Impl::RegionRect(int region) const {
  if (!located) return options.roi_px;
  const auto column = static_cast<size_t>(region % block_columns);
  const auto row = static_cast<size_t>(region / block_columns);
  const int x0 = grid.x0_px[column], y0 = grid.y0_px[row];
  return cv::Rect(x0, y0, grid.x0_px[column + 1] + grid.cell_px - x0,
                  grid.y0_px[row + 1] + grid.cell_px - y0);
}

Status LedDetector::Impl::Setup(const Frame& frame) {
  width_px = frame.bgr.cols;
  height_px = frame.bgr.rows;
  after_frames = options.min_on_frames;
  window = kBeforeFrames + 1 + after_frames;
  ring = located ? window : kBeforeFrames + kBuildUpFrames + after_frames;
  if (width_px < 2 * options.cell_px || height_px < 2 * options.cell_px) {
    return InvalidArgumentError("frame " + std::to_string(width_px) + "x" +
                                std::to_string(height_px) + " is smaller than 2 x 2 cells of " +
                                std::to_string(options.cell_px) + " px (cell_px)");
  }
  if (located) {
    grid = Grid::Make(width_px, height_px, options.cell_px, 1);
    block_columns = grid.columns - 1;
    regions = block_columns * (grid.rows - 1);
    pixels_per_region = 4.0 * grid.sampled_px_per_cell;
  } else {
    const cv::Rect& roi = options.roi_px;
    if (roi.x < 0 || roi.y < 0 || roi.x + roi.width > width_px || roi.y + roi.height > height_px) {
      return InvalidArgumentError("LED ROI " + RectText(roi) + " is outside the " +
                                  std::to_string(width_px) + "x" + std::to_string(height_px) +
                                  " frame");
    }
    grid = Grid::Make(width_px, height_px, options.cell_px, kReferenceStride);
    regions = kRoiSignals;
    const auto pixels = static_cast<size_t>(roi.area());
    top_pixels = std::min(pixels, std::max(kTopPixelsMin, pixels / kTopPixelsShare));
    inner = InnerMask(roi.width, roi.height);
    pixels_per_region = static_cast<double>(top_pixels);
    roi_pictures.assign(static_cast<size_t>(ring) * pixels * 3, 0);
    pixel_reference.assign(pixels, 0.0f);
    changes.assign(pixels, 0.0f);
    scaled_changes.assign(pixels, 0.0f);
    corrected.assign(pixels * static_cast<size_t>(ring), 0.0f);
    pixel_steps.assign(pixels, 0.0);
    channel_steps.assign(pixels, 0.0);
    lit_peaks.assign(pixels, 0.0);
    pixel_wobble.assign(pixels, 0.0);
    dating_series.assign(static_cast<size_t>(ring), 0.0);
    scaled_series.assign(static_cast<size_t>(ring), 0.0);
    row_gains.assign(static_cast<size_t>(ring) * static_cast<size_t>(roi.height), 1.0f);
    for (int x = 0; x < width_px; x += kStripStepPx) {
      if (x < roi.x - kStripStepPx || x >= roi.x + roi.width + kStripStepPx) {
        strip_columns.push_back(static_cast<size_t>(x));
      }
    }
    strip_reference.assign(strip_columns.size() * static_cast<size_t>(roi.height), 0.0f);
    band_gains.assign(static_cast<size_t>(GainBands()), 1.0f);
    strip_ring.assign(static_cast<size_t>(ring) * strip_reference.size(), 0.0f);
    row_ratios.reserve(std::max(strip_columns.size() * static_cast<size_t>(kGainBandRows),
                                static_cast<size_t>(roi.width)));
  }
  const auto slots = static_cast<size_t>(ring);
  ring_index.assign(slots, 0);
  ring_t_ns.assign(slots, 0);
  ring_gain.assign(slots, 1.0);
  cell_sums.assign(slots * Cells(), 0.0f);
  region_sums.assign(slots * static_cast<size_t>(regions), 0.0);
  cell_peaks.assign(slots * Cells(), 0);
  cell_reference.assign(Cells(), 0.0f);
  region_noise.assign(static_cast<size_t>(regions), 0.0f);
  level.assign(static_cast<size_t>(regions), Level::kUnknown);
  level_step.assign(static_cast<size_t>(regions), 0.0f);
  events_per_region.assign(static_cast<size_t>(regions), 0);
  raw_sums.assign(Cells(), 0.0f);
  window_values.resize(static_cast<size_t>(ring));
  window_copy.resize(static_cast<size_t>(ring));
  window_peaks.resize(static_cast<size_t>(ring));
  window_sums.resize(static_cast<size_t>(ring));
  return Status::Ok();
}

double LedDetector::Impl::Gain() {
  if (frames == 0) return 1.0;
  const double min_reference = kGainMinLevels * 3.0 * grid.sampled_px_per_cell;
  const int stride = located ? kGainStride : 1;
  ratios.clear();
  for (int row = 0; row < grid.rows; row += stride) {
    for (int column = 0; column < grid.columns; column += stride) {
      const auto cell = static_cast<size_t>(row * grid.columns + column);
      if (static_cast<double>(cell_reference[cell]) > min_reference) {
        ratios.push_back(raw_sums[cell] / cell_reference[cell]);
      }
    }
  }
  if (ratios.empty()) return 1.0;
  return static_cast<double>(MedianOf(ratios.data(), static_cast<int>(ratios.size())));
}

void LedDetector::Impl::Measure(const Frame& frame, size_t slot) {
  uint8_t* peaks = &cell_peaks[slot * Cells()];
  MeasureCells(frame.bgr, grid, raw_sums.data(), peaks);
  const double gain = Gain();
  ring_gain[slot] = gain;
  const auto excess = static_cast<float>(gain - 1.0);
  // the references average the first frames, then follow slowly (a lit LED joins its
  // region's reference only after a while, so the region is corrected as the scene)
  const double follow_rate = 1.0 / std::min(kReferenceFrames, static_cast<double>(frames + 1));
  const auto follow = static_cast<float>(follow_rate);
  float* cells = &cell_sums[slot * Cells()];
  for (size_t cell = 0; cell < Cells(); ++cell) {
    if (frames == 0) cell_reference[cell] = raw_sums[cell];
    cells[cell] = raw_sums[cell] - excess * cell_reference[cell];
    cell_reference[cell] += follow * (raw_sums[cell] - cell_reference[cell]);
  }
  double* sums = &region_sums[slot * static_cast<size_t>(regions)];
  if (!located) {
    MeasureRoi(frame.bgr, slot, gain, sums);
    return;
  }
  // blocks of 2 x 2 cells
  const auto columns = static_cast<size_t>(grid.columns);
  const auto blocks = static_cast<size_t>(block_columns);
  for (size_t row = 0; row + 1 < static_cast<size_t>(grid.rows); ++row) {
    const float* top = cells + row * columns;
    const float* bottom = top + columns;
    double* out = sums + row * blocks;
    for (size_t c = 0; c < blocks; ++c) {
      out[c] = static_cast<double>(top[c] + top[c + 1] + bottom[c] + bottom[c + 1]);
    }
  }
}

uint8_t* LedDetector::Impl::RoiPicture(size_t slot) {
  return &roi_pictures[slot * static_cast<size_t>(options.roi_px.area()) * 3];
}

void LedDetector::Impl::FollowReference(const uint8_t* picture, const float* strip) {
  ++reference_frames;
  const auto rate =
      static_cast<float>(1.0 / std::min(kReferenceFrames, static_cast<double>(reference_frames)));
  for (size_t i = 0; i < pixel_reference.size(); ++i, picture += 3) {
    const auto brightness = static_cast<float>(picture[0] + picture[1] + picture[2]);
    pixel_reference[i] += rate * (brightness - pixel_reference[i]);
  }
  for (size_t i = 0; i < strip_reference.size(); ++i) {
    strip_reference[i] += rate * (strip[i] - strip_reference[i]);
  }
}

void LedDetector::Impl::SampleStrips(const cv::Mat& bgr, float* strip) const {
  const size_t columns = strip_columns.size();
  for (int y = 0; y < options.roi_px.height; ++y) {
    const uint8_t* line = bgr.ptr<uint8_t>(options.roi_px.y + y);
    float* out = strip + static_cast<size_t>(y) * columns;
    for (size_t s = 0; s < columns; ++s) {
      const uint8_t* pixel = line + 3 * strip_columns[s];
      out[s] = static_cast<float>(pixel[0] + pixel[1] + pixel[2]);
    }
  }
}

float* LedDetector::Impl::RowGains(size_t slot) {
  return &row_gains[slot * static_cast<size_t>(options.roi_px.height)];
}

void LedDetector::Impl::MeasureRowGains(const uint8_t* picture, const float* strip, double gain,
                                        float* gains) {
  const auto min_reference = static_cast<float>(3.0 * kGainMinLevels);
  const size_t columns = strip_columns.size();
  const auto width = static_cast<size_t>(options.roi_px.width);
  const auto most = static_cast<float>(kRowRatioMax * gain);
  for (int band = 0; band < GainBands(); ++band) {
    const int y = BandRow(band);
    const int band_end = std::min(options.roi_px.height, (band + 1) * kGainBandRows);
    const auto band_rows = static_cast<size_t>(band_end - band * kGainBandRows);
    const size_t samples = columns * band_rows;
    row_ratios.clear();
    if (columns >= kStripMinSamples) {
      const size_t first = static_cast<size_t>(band * kGainBandRows) * columns;
      const float* reference = &strip_reference[first];
      const float* brightness = strip + first;
      for (size_t s = 0; s < samples; ++s) {
        if (reference[s] >= min_reference) row_ratios.push_back(brightness[s] / reference[s]);
      }
    } else {
      const size_t first = static_cast<size_t>(y) * width;
      for (size_t i = first; i < first + width; ++i) {
        const uint8_t* pixel = picture + 3 * i;
        if (pixel_reference[i] < min_reference) continue;
        const float ratio = static_cast<float>(pixel[0] + pixel[1] + pixel[2]) / pixel_reference[i];
        if (ratio < most) row_ratios.push_back(ratio);
      }
    }
    const size_t needed = columns >= kStripMinSamples ? samples : width;
    const float band_gain =
        2 * row_ratios.size() > needed
            ? MedianOf(row_ratios.data(), static_cast<std::ptrdiff_t>(row_ratios.size()))
            : static_cast<float>(gain);
    band_gains[static_cast<size_t>(band)] = band_gain;
  }
  // every row: linear between the measured rows around it
  for (int y = 0; y < options.roi_px.height; ++y) {
    const int band = std::clamp((y - kGainBandRows / 2) / kGainBandRows, 0, GainBands() - 1);
    const int next = std::min(band + 1, GainBands() - 1);
    const int from = BandRow(band), to = BandRow(next);
    const float weight =
        to > from
            ? std::clamp(static_cast<float>(y - from) / static_cast<float>(to - from), 0.0f, 1.0f)
            : 0.0f;
    gains[y] =
        band_gains[static_cast<size_t>(band)] +
        weight * (band_gains[static_cast<size_t>(next)] - band_gains[static_cast<size_t>(band)]);
  }
}

int LedDetector::Impl::BandRow(int band) const {
  return std::min(band * kGainBandRows + kGainBandRows / 2, options.roi_px.height - 1);
}

void LedDetector::Impl::MeasureRoi(const cv::Mat& bgr, size_t slot, double gain, double* sums) {
  const cv::Rect& roi = options.roi_px;
  uint8_t* picture = RoiPicture(slot);
  float* strip = StripSamples(slot);
  // the frame leaving the window joins the references (the first frame starts them)
  if (frames >= window) {
    const size_t leaving = Slot(frames - window);
    FollowReference(RoiPicture(leaving), StripSamples(leaving));
  }
  const auto row_bytes = static_cast<size_t>(roi.width) * 3;
  for (int y = 0; y < roi.height; ++y) {
    std::memcpy(picture + static_cast<size_t>(y) * row_bytes,
                bgr.ptr<uint8_t>(roi.y + y) + roi.x * 3, row_bytes);
  }
  SampleStrips(bgr, strip);
  if (frames == 0) {
    reference_frames = 0;
    std::fill(pixel_reference.begin(), pixel_reference.end(), 0.0f);
    std::fill(strip_reference.begin(), strip_reference.end(), 0.0f);
    FollowReference(picture, strip);
  }
  float* gains = RowGains(slot);
  MeasureRowGains(picture, strip, gain, gains);
  const auto width = static_cast<size_t>(roi.width);
  const uint8_t* pixel = picture;
  uint64_t total = 0;  // B + G + R over the ROI, for the trace
  const auto min_gain = static_cast<float>(kMinRowGain);
  for (size_t i = 0; i < changes.size(); ++i, pixel += 3) {
    const int brightness = pixel[0] + pixel[1] + pixel[2];
    total += static_cast<uint64_t>(brightness);
    const float row_gain = gains[i / width];
    changes[i] = inner[i] ? static_cast<float>(brightness) - row_gain * pixel_reference[i] : 0.0f;
    // (a black frame is not divided by)
    scaled_changes[i] = row_gain >= min_gain ? changes[i] / row_gain : changes[i];
  }
  roi_mean_levels = static_cast<double>(total) / (3.0 * static_cast<double>(changes.size()));
  sums[kRoiOwnLight] = ExtremeChanges(changes);
  sums[kRoiScaledLight] = ExtremeChanges(scaled_changes);
}

double LedDetector::Impl::ExtremeChanges(std::vector<float>& values) const {
  const auto top = static_cast<std::ptrdiff_t>(top_pixels);
  std::nth_element(values.begin(), values.begin() + top - 1, values.end(), std::greater<>());
  double signal = std::accumulate(values.begin(), values.begin() + top, 0.0);
  std::nth_element(values.begin(), values.begin() + top - 1, values.end());
  signal += std::accumulate(values.begin(), values.begin() + top, 0.0);
  return signal;
}

bool LedDetector::Impl::SmallLightInRenewedBlock(double largest, size_t width) const {
  const double strong = kRoiStrongFrac * largest;
  const auto peak = static_cast<size_t>(std::max_element(pixel_steps.begin(), pixel_steps.end()) -
                                        pixel_steps.begin());
  const auto near_peak = [&](size_t i) {
    const auto dx = static_cast<int64_t>(i % width) - static_cast<int64_t>(peak % width);
    const auto dy = static_cast<int64_t>(i / width) - static_cast<int64_t>(peak / width);
    return std::max(std::abs(dx), std::abs(dy)) <= kSmallLightRadiusPx;
  };
  double stepped_strong = 0.0, stepped_near = 0.0, opposite_strong = 0.0;
  for (size_t i = 0; i < pixel_steps.size(); ++i) {
    if (pixel_steps[i] > strong) {
      stepped_strong += pixel_steps[i];
      if (near_peak(i)) stepped_near += pixel_steps[i];
    } else if (pixel_steps[i] < -strong) {
      opposite_strong -= pixel_steps[i];
    }
  }
  return stepped_near >= kSmallLightShare * stepped_strong &&
         opposite_strong <= kRoiOppositeFrac * stepped_strong;
}

void LedDetector::Impl::MeasurePixelSteps(int64_t k, int gap, bool rise, double& off_sum,
                                          double& on_sum) {
  const size_t pixels = pixel_reference.size();
  const auto frames_in_ring = static_cast<size_t>(ring);
  const auto before = static_cast<size_t>(kBeforeFrames);
  const size_t after_first = before + static_cast<size_t>(gap);
  const size_t count = after_first + static_cast<size_t>(after_frames);
  const auto width = static_cast<size_t>(options.roi_px.width);
  std::vector<float> peaks(count);
  off_sum = on_sum = 0.0;
  for (size_t i = 0; i < pixels; ++i) {
    float* values = &corrected[i * frames_in_ring];
    for (size_t j = 0; j < count; ++j) {
      const size_t slot = Slot(k - kBeforeFrames + static_cast<int64_t>(j));
      const uint8_t* pixel = RoiPicture(slot) + 3 * i;
      values[j] = static_cast<float>(pixel[0] + pixel[1] + pixel[2]) -
                  (RowGains(slot)[i / width] - 1.0f) * pixel_reference[i];
      peaks[j] = static_cast<float>(std::max({pixel[0], pixel[1], pixel[2]}));
    }
    std::copy(values, values + count, window_sums.begin());
    const double level_before = MedianOf(window_sums.data(), kBeforeFrames);
    const double level_after =
        MedianOf(window_sums.data() + after_first, static_cast<std::ptrdiff_t>(after_frames));
    const double peak_before = MedianOf(peaks.data(), kBeforeFrames);
    const double peak_after =
        MedianOf(peaks.data() + after_first, static_cast<std::ptrdiff_t>(after_frames));
    pixel_steps[i] = rise ? level_after - level_before : level_before - level_after;
    channel_steps[i] = rise ? peak_after - peak_before : peak_before - peak_after;
    lit_peaks[i] = rise ? peak_after : peak_before;
    pixel_wobble[i] = std::abs(static_cast<double>(values[before - 1] - values[before - 2]));
    if (!inner[i]) pixel_steps[i] = channel_steps[i] = 0.0;
    off_sum += rise ? level_before : level_after;
    on_sum += rise ? level_after : level_before;
  }
}

bool LedDetector::Impl::SumDatingSeries(int64_t k, size_t count, double clear, bool clipped) {
  const auto frames_in_ring = static_cast<size_t>(ring);
  const auto width = static_cast<size_t>(options.roi_px.width);
  std::fill(dating_series.begin(), dating_series.end(), 0.0);
  std::fill(scaled_series.begin(), scaled_series.end(), 0.0);
  bool scaled = true;
  for (size_t i = 0; i < pixel_reference.size(); ++i) {
    if (!(pixel_steps[i] > clear) || (!clipped && lit_peaks[i] >= kClipLevels)) continue;
    const float* values = &corrected[i * frames_in_ring];
    for (size_t j = 0; j < count; ++j) {
      const size_t slot = Slot(k - kBeforeFrames + static_cast<int64_t>(j));
      const uint8_t* pixel = RoiPicture(slot) + 3 * i;
      const double gain = static_cast<double>(RowGains(slot)[i / width]);
      dating_series[j] += static_cast<double>(values[j]);
      if (gain < kMinRowGain)
        scaled = false;
      else
        scaled_series[j] += (pixel[0] + pixel[1] + pixel[2]) / gain;
    }
  }
  if (!scaled) std::fill(scaled_series.begin(), scaled_series.end(), 0.0);
  return scaled;
}

bool LedDetector::Impl::MeasureRoiStep(int64_t k, int gap, bool rise, StepEvent& event) {
  const size_t pixels = pixel_reference.size();
  const auto count = static_cast<size_t>(kBeforeFrames + gap + after_frames);
  const auto width = static_cast<size_t>(options.roi_px.width);
  double off_sum = 0.0, on_sum = 0.0;
  MeasurePixelSteps(k, gap, rise, off_sum, on_sum);
  // a pixel's noise (the median frame-to-frame change is sqrt(2) / kMadToSigma = 0.954
  // sigma for Gaussian noise)
  const double sigma = MedianOf(pixel_wobble.data(), static_cast<std::ptrdiff_t>(pixels)) *
                       kMadToSigma / std::sqrt(2.0);
  const double largest = *std::max_element(pixel_steps.begin(), pixel_steps.end());
  const double clear = std::max(kPixelNoiseSigmas * sigma, kPixelStepFrac * largest);
  double stepped = 0.0, opposite = 0.0, unclipped = 0.0;
  for (size_t i = 0; i < pixels; ++i) {
    if (pixel_steps[i] > clear) {
      stepped += pixel_steps[i];
      if (lit_peaks[i] < kClipLevels) unclipped += pixel_steps[i];
    } else if (pixel_steps[i] < -clear) {
      opposite -= pixel_steps[i];
    }
  }
  if (stepped <= 0.0) return false;
  if (opposite > kRoiOppositeFrac * stepped && !SmallLightInRenewedBlock(largest, width)) {
    return false;
  }
  event.clipped = unclipped < kUnclippedShare * stepped;
  event.standout = largest / std::max(kStandoutFloor, InnerQuantile(kOutlierQuantile));
  // the dating series and the LED's contrast over the chosen pixels
  std::vector<double> contrasts;
  for (size_t i = 0; i < pixels; ++i) {
    if (pixel_steps[i] > clear) contrasts.push_back(channel_steps[i]);
  }
  std::sort(contrasts.begin(), contrasts.end(), std::greater<>());
  event.contrast_levels = contrasts[std::min(contrasts.size() - 1, kContrastRank)];
  const bool scaled_usable = SumDatingSeries(k, count, clear, event.clipped);
  // the levels: the medians of the frames before and after (the pixels of a small light
  // may still be catching up after it: the creep widens the partly lit frame's band); the
  // series whose lit frames hold flatter: the LED's own light, or all of it scaled by the
  // flicker (a renderer's flicker scales the whole picture)
  const double threshold_frac = std::max(options.threshold_frac, kPartlyLitBeforeFrac);
  WindowShape shape = ShapeOf(dating_series.data(), kBeforeFrames, gap, after_frames, rise,
                              threshold_frac, window_copy);
  const WindowShape scaled = ShapeOf(scaled_series.data(), kBeforeFrames, gap, after_frames, rise,
                                     threshold_frac, window_copy);
  if (scaled_usable && Roughness(scaled) < Roughness(shape)) {
    shape = scaled;
    dating_series.swap(scaled_series);
  }
  if (!(shape.step > 0) || Roughness(shape) > 1.0) return false;
  const double widest = std::max(shape.before_spread, shape.after_against);
  event.off = rise ? shape.before_level : shape.after_level;
  event.on = rise ? shape.after_level : shape.before_level;
  if (!(event.on > event.off)) return false;
  event.noise = 0.5 * widest;
  event.creep = shape.after_creep / (event.on - event.off);
  event.value.assign(dating_series.begin(),
                     dating_series.begin() + static_cast<std::ptrdiff_t>(count));
  event.off_levels = off_sum / (3.0 * static_cast<double>(pixels));
  event.on_levels = on_sum / (3.0 * static_cast<double>(pixels));
  return true;
}

double LedDetector::Impl::InnerQuantile(double q) {
  jumps.clear();
  for (size_t i = 0; i < pixel_steps.size(); ++i) {
    if (inner[i]) jumps.push_back(std::abs(pixel_steps[i]));
  }
  return jumps.empty() ? 0.0 : OrderQuantileOf(jumps, q);
}

int64_t LedDetector::Impl::PeriodNs() const {
  if (interval_count == 0) return 0;
  std::array<int64_t, kIntervalWindow> copy = intervals_ns;
  return MedianOf(copy.data(), static_cast<int>(std::min(interval_count, kIntervalWindow)));
}

double LedDetector::Impl::OutlierJump(int64_t k) {
  jumps.clear();
  const int64_t last = std::min<int64_t>(k + 2, k + after_frames);
  const auto sharp = [](double before, double previous, double next, double after) {
    const double wobble = std::max(std::abs(previous - before), std::abs(after - next));
    return std::max(0.0, std::abs(next - previous) - 2.0 * wobble);
  };
  if (located) {
    const auto at = [&](int64_t frame) {
      return &region_sums[Slot(frame) * static_cast<size_t>(regions)];
    };
    const double *before = at(k - 2), *previous = at(k - 1), *next = at(k + 1), *after = at(last);
    const size_t count = static_cast<size_t>(regions), stride = SampleStride(count);
    for (size_t r = 0; r < count; r += stride) {
      jumps.push_back(sharp(before[r], previous[r], next[r], after[r]));
    }
  } else {
    const auto at = [&](int64_t frame) { return &cell_sums[Slot(frame) * Cells()]; };
    const float *before = at(k - 2), *previous = at(k - 1), *next = at(k + 1), *after = at(last);
    const double scale = pixels_per_region / grid.sampled_px_per_cell;
    for (size_t c = 0; c < Cells(); c += SampleStride(Cells())) {
      jumps.push_back(scale * sharp(before[c], previous[c], next[c], after[c]));
    }
  }
  return kOutlierFactor * OrderQuantileOf(jumps, kOutlierQuantile);
}

double LedDetector::Impl::OutlierContrast(int64_t k) {
  jumps.clear();
  const uint8_t* previous = &cell_peaks[Slot(k - 1) * Cells()];
  const uint8_t* next = &cell_peaks[Slot(k + 1) * Cells()];
  const double previous_gain = ring_gain[Slot(k - 1)], next_gain = ring_gain[Slot(k + 1)];
  if (located) {
    for (size_t c = 0; c < Cells(); c += SampleStride(Cells())) {
      jumps.push_back(std::abs(next[c] / next_gain - previous[c] / previous_gain));
    }
    return kOutlierFactor * OrderQuantileOf(jumps, kOutlierQuantile);
  }
  // with an ROI (a lattice of a few cells a row): each row of cells by its own change of
  // gain between the two frames, as a rolling shutter bands the flicker by rows
  const auto columns = static_cast<size_t>(grid.columns);
  for (size_t row = 0; row < static_cast<size_t>(grid.rows); ++row) {
    const double ratio =
        RowRatio(previous + row * columns, next + row * columns, next_gain / previous_gain);
    for (size_t c = row * columns; c < (row + 1) * columns; ++c) {
      jumps.push_back(std::abs(next[c] - ratio * previous[c]) / next_gain);
    }
  }
  return kOutlierFactor * OrderQuantileOf(jumps, kOutlierQuantile);
}

double LedDetector::Impl::RowRatio(const uint8_t* previous, const uint8_t* next, double fallback) {
  row_ratios.clear();
  for (int c = 0; c < grid.columns; ++c) {
    if (previous[c] >= kGainMinLevels && next[c] >= kGainMinLevels && previous[c] < kClipLevels &&
        next[c] < kClipLevels) {
      row_ratios.push_back(static_cast<float>(next[c]) / static_cast<float>(previous[c]));
    }
  }
  if (row_ratios.size() < kRowRatioMinCells) return fallback;
  return static_cast<double>(
      MedianOf(row_ratios.data(), static_cast<std::ptrdiff_t>(row_ratios.size())));
}

void LedDetector::Impl::Evaluate() {
  const int64_t k = frames - 1 - after_frames;
  const double min_step = kMinStepLevels * 3.0 * pixels_per_region;
  const double* next = &region_sums[Slot(k + 1) * static_cast<size_t>(regions)];
  const double* previous = &region_sums[Slot(k - 1) * static_cast<size_t>(regions)];
  const double* earlier = &region_sums[Slot(k - 2) * static_cast<size_t>(regions)];
  const auto follow = static_cast<float>(1.0 / kNoiseFrames);
  double outlier_jump = -1.0;  // computed when first needed
  double outlier_contrast = -1.0;
  for (int region = 0; region < regions; ++region) {
    const auto r = static_cast<size_t>(region);
    const double jump = next[r] - previous[r];
    const double needed = std::max(min_step, kNoiseFactor * static_cast<double>(region_noise[r]));
    region_noise[r] +=
        follow * (static_cast<float>(std::abs(previous[r] - earlier[r])) - region_noise[r]);
    // a region at a level steps only the other way, unless by far more than the step
    // that set the level (a faint step before the LED's must not hide it)
    const bool stronger = std::abs(jump) > kStrongerFactor * static_cast<double>(level_step[r]);
    const bool rise = jump > needed && (level[r] != Level::kHigh || stronger);
    const bool fall = jump < -needed && (level[r] != Level::kLow || stronger);
    if (rise || fall) {
      TestStep(region, k, rise, min_step, std::abs(jump), outlier_jump, outlier_contrast);
    }
  }
}

void LedDetector::Impl::TestBuildUp() {
  const int64_t newest = frames - 1;
  const double min_step = kMinStepLevels * 3.0 * pixels_per_region;
  const int64_t longest = std::min<int64_t>(kBuildUpFrames, frames - kBeforeFrames - after_frames);
  for (auto gap = static_cast<int>(longest); gap >= 2; --gap) {
    const int64_t first = newest - after_frames - gap + 1;
    const std::optional<WindowShape> shape = BuildUpShape(first, gap, min_step);
    if (!shape) continue;
    if (!RiseMayStartAt(first, shape->step) ||
        events_per_region[kRoiOwnLight] >= kMaxEventsPerRegion) {
      return;
    }
    // it stands out from the frame and looks like a light, as a step must, and its first
    // frame is the first lit in the LED's own pixels too
    const double jump = region_sums[RegionSlot(kRoiOwnLight, first + 1)] -
                        region_sums[RegionSlot(kRoiOwnLight, first - 1)];
    if (jump < OutlierJump(first)) return;
    StepEvent event;
    if (!MeasureRoiStep(first, gap, true, event)) return;
    const auto dating_fraction = [&](size_t i) {
      return (event.value[i] - event.off) / (event.on - event.off);
    };
    if (dating_fraction(kBeforeFrames - 1) >= kLitFraction) return;
    const double contrast = event.contrast_levels;
    if (contrast < OutlierContrast(first) && event.standout < kLocalStandout) return;
    if (contrast < options.min_contrast_levels) {
      if (contrast > std::max(rejected_contrast, 0.0)) {
        rejected_contrast = contrast;
        rejected_region = 0;
      }
      return;
    }
    DropRisesAfter(first);
    DescribeEvent(kRoiOwnLight, first, gap, true, *shape, contrast, event);
    AddPending(std::move(event));
    return;
  }
}

std::optional<WindowShape> LedDetector::Impl::FlatShape(int region, int64_t k, int gap, bool rise,
                                                        double threshold_frac, double min_step) {
  const auto count = static_cast<size_t>(kBeforeFrames + gap + after_frames);
  for (size_t i = 0; i < count; ++i) {
    window_values[i] = region_sums[RegionSlot(region, k - kBeforeFrames + static_cast<int64_t>(i))];
  }
  const WindowShape shape = ShapeOf(window_values.data(), kBeforeFrames, gap, after_frames, rise,
                                    threshold_frac, window_copy);
  const double step = shape.step;
  if (step < min_step) return std::nullopt;
  const double flat = FlatFrac();
  if (shape.before_spread > flat * step || shape.after_against > flat * step ||
      shape.after_creep > kCreepFrac * step) {
    return std::nullopt;
  }
  return shape;
}

std::optional<WindowShape> LedDetector::Impl::BuildUpShape(int64_t first, int gap,
                                                           double min_step) {
  const std::optional<WindowShape> flat_shape =
      FlatShape(kRoiOwnLight, first, gap, true, kLitFraction, min_step);
  if (!flat_shape) return std::nullopt;
  const WindowShape& shape = *flat_shape;
  const double step = shape.step;
  if (step <= kNoiseFactor * static_cast<double>(region_noise[kRoiOwnLight])) return std::nullopt;
  const auto fraction = [&](size_t i) { return (window_values[i] - shape.before_level) / step; };
  const auto before = static_cast<size_t>(kBeforeFrames);
  if (fraction(before - 1) >= kLitFraction) return std::nullopt;
  for (size_t i = before; i < before + static_cast<size_t>(gap); ++i) {
    if (fraction(i) < kLitFraction || fraction(i) > 1.0 + kCreepFrac) return std::nullopt;
  }
  return shape;
}

bool LedDetector::Impl::RiseMayStartAt(int64_t first, double step) const {
  if (level[kRoiOwnLight] != Level::kHigh ||
      step > kStrongerFactor * static_cast<double>(level_step[kRoiOwnLight])) {
    return true;
  }
  const int64_t first_t_ns = ring_t_ns[Slot(first)];
  return std::any_of(pending.begin(), pending.end(),
                     [&](const StepEvent& event) { return OwnRiseAfter(event, first_t_ns); });
}

void LedDetector::Impl::DropRisesAfter(int64_t first) {
  const int64_t first_t_ns = ring_t_ns[Slot(first)];
  const StepEvent* earliest = nullptr;
  const auto later_rise = [&](const StepEvent& event) { return OwnRiseAfter(event, first_t_ns); };
  for (const StepEvent& event : pending) {
    if (later_rise(event) &&
        (!earliest || event.t_ns[kBeforeFrames] < earliest->t_ns[kBeforeFrames])) {
      earliest = &event;
    }
  }
  if (!earliest) return;
  level[kRoiOwnLight] = earliest->level_before;
  level_step[kRoiOwnLight] = earliest->level_step_before;
  const auto dropped = std::remove_if(pending.begin(), pending.end(), later_rise);
  events_per_region[kRoiOwnLight] -= static_cast<uint32_t>(std::distance(dropped, pending.end()));
  pending.erase(dropped, pending.end());
}

template <typename T>
double LedDetector::Impl::WindowStep(const std::vector<T>& series, size_t stride, size_t offset,
                                     int64_t k, bool rise, std::vector<T>& scratch) const {
  for (int i = 0; i < window; ++i) {
    scratch[static_cast<size_t>(i)] = series[Slot(k - kBeforeFrames + i) * stride + offset];
  }
  const double before = MedianOf(scratch.data(), kBeforeFrames);
  const double after = MedianOf(scratch.data() + kBeforeFrames + 1, after_frames);
  return rise ? after - before : before - after;
}

double LedDetector::Impl::Contrast(int region, int64_t k, bool rise) {
  const int column = region % block_columns, row = region / block_columns;
  double contrast = 0.0;
  for (int dy = 0; dy < 2; ++dy) {
    for (int dx = 0; dx < 2; ++dx) {
      const auto cell = static_cast<size_t>((row + dy) * grid.columns + column + dx);
      const double peak_step = WindowStep(cell_peaks, Cells(), cell, k, rise, window_peaks);
      const double mean_step = WindowStep(cell_sums, Cells(), cell, k, rise, window_sums) /
                               (3.0 * grid.sampled_px_per_cell);
      contrast = std::max(contrast, std::max(peak_step, mean_step));
    }
  }
  return contrast;
}

std::optional<WindowShape> LedDetector::Impl::CleanStep(int region, int64_t k, bool rise,
                                                        double min_step) {
  const std::optional<WindowShape> flat_shape =
      FlatShape(region, k, 1, rise, options.threshold_frac, min_step);
  if (!flat_shape) return std::nullopt;
  const WindowShape& shape = *flat_shape;
  const double step = shape.step;
  const double flat = FlatFrac();
  const auto before = window_values.cbegin();
  const auto before_end = before + kBeforeFrames;
  const auto after = before_end + 1;
  const auto after_end = before + window;
  const auto [before_low, before_high] = std::minmax_element(before, before_end);
  const auto [after_low, after_high] = std::minmax_element(after, after_end);
  // a partly lit frame just after a k still at the old level is the next frame's
  // transition: wait for it (after a partly lit k it is a codec building up a small spot
  // over a few frames)
  const bool old_level_at_k = std::abs(*before_end - shape.before_level) <= flat * step;
  if (old_level_at_k && std::abs(*after - shape.after_level) > 0.5 * flat * step) {
    return std::nullopt;
  }
  const double off = rise ? shape.before_level : shape.after_level;
  const double threshold = off + options.threshold_frac * step;
  if (rise ? !(*before_high<threshold&& * after_low> threshold)
           : !(*before_low > threshold && *after_high < threshold)) {
    return std::nullopt;
  }
  return shape;
}

void LedDetector::Impl::TestStep(int region, int64_t k, bool rise, double min_step, double jump,
                                 double& outlier_jump, double& outlier_contrast) {
  // a clean step in this region's sums, larger than the frame's other jumps
  const std::optional<WindowShape> shape = CleanStep(region, k, rise, min_step);
  if (!shape) return;
  if (outlier_jump < 0) outlier_jump = OutlierJump(k);
  if (jump < outlier_jump) return;

  // the LED's contrast: enough, and larger than the frame's other regions'
  StepEvent event;
  if (!located && !MeasureRoiStep(k, 1, rise, event)) return;
  const double contrast = located ? Contrast(region, k, rise) : event.contrast_levels;
  if (outlier_contrast < 0) outlier_contrast = OutlierContrast(k);
  if (contrast < outlier_contrast && (located || event.standout < kLocalStandout)) return;
  if (contrast < options.min_contrast_levels) {
    if (rise && contrast > std::max(rejected_contrast, 0.0)) {
      rejected_contrast = contrast;
      rejected_region = region;
    }
    return;
  }
  if (events_per_region[static_cast<size_t>(region)] >= kMaxEventsPerRegion) return;

  if (!DescribeEvent(region, k, 1, rise, *shape, contrast, event)) return;
  AddPending(std::move(event));
}

void LedDetector::Impl::AddPending(StepEvent event) {
  const auto r = static_cast<size_t>(event.region);
  event.frames_to_confirm = kConfirmFrames;
  event.level_before = level[r];
  event.level_step_before = level_step[r];
  level[r] = event.rise ? Level::kHigh : Level::kLow;
  level_step[r] = static_cast<float>(event.signal_step);
  ++events_per_region[r];
  pending.push_back(std::move(event));
}

bool LedDetector::Impl::DescribeEvent(int region, int64_t k, int gap, bool rise,
                                      const WindowShape& shape, double contrast, StepEvent& event) {
  const double step = shape.step;
  const double off = rise ? shape.before_level : shape.after_level;
  event.region = region;
  event.rise = rise;
  event.signal_step = step;
  event.signal_off = off;
  event.signal_on = off + step;
  event.contrast_levels = contrast;
  event.period_ns = PeriodNs();
  event.build_up_frames = gap;
  for (int64_t frame = k - kBeforeFrames; frame < k + gap + after_frames; ++frame) {
    event.index.push_back(ring_index[Slot(frame)]);
    event.t_ns.push_back(ring_t_ns[Slot(frame)]);
  }
  if (!located) return true;
  // the block's own sums date the step
  event.off = off;
  event.on = off + step;
  event.noise = 0.5 * std::max({shape.before_spread, shape.after_against, shape.after_creep});
  event.off_levels = event.off / (3.0 * pixels_per_region);
  event.on_levels = event.on / (3.0 * pixels_per_region);
  for (int64_t frame = k - kBeforeFrames; frame <= k + after_frames; ++frame) {
    event.value.push_back(region_sums[RegionSlot(region, frame)]);
  }
  RecordCellSteps(event, k);
  return LooksLikeALight(event);
}

void LedDetector::Impl::RecordCellSteps(StepEvent& event, int64_t k) {
  const int block_column = event.region % block_columns, block_row = event.region / block_columns;
  for (int dy = 0; dy < 4; ++dy) {
    for (int dx = 0; dx < 4; ++dx) {
      const int column = block_column - 1 + dx, row = block_row - 1 + dy;
      float cell_step = 0.0f;
      if (column >= 0 && column < grid.columns && row >= 0 && row < grid.rows) {
        const auto cell = static_cast<size_t>(row * grid.columns + column);
        cell_step =
            static_cast<float>(WindowStep(cell_sums, Cells(), cell, k, event.rise, window_sums));
      }
      event.cell_steps[static_cast<size_t>(dy * 4 + dx)] = cell_step;
    }
  }
}

void LedDetector::Impl::Confirm(size_t slot) {
  size_t kept = 0;
  for (StepEvent& event : pending) {
    const double value =
        region_sums[slot * static_cast<size_t>(regions) + static_cast<size_t>(event.region)];
    const double tolerance = FlatFrac() * event.signal_step;
    const double held = event.rise ? event.signal_on : event.signal_off;
    const double left = event.rise ? event.signal_off : event.signal_on;
    const double beyond = (event.rise ? 1.0 : -1.0) * (value - held);
    // (with an ROI a light may go on brightening for good: a codec refines a tiny LED's
    // spot over several frames, sometimes by more than the step itself)
    const bool holds = std::abs(value - held) <= tolerance ||
                       (beyond > 0 && (!located || beyond <= kCreepFrac * event.signal_step));
    bool done = false;
    if (std::abs(value - left) <= tolerance) {
      done = true;  // back already: a short pulse
    } else if (!holds && ++event.between > 1) {
      level[static_cast<size_t>(event.region)] = event.level_before;
      level_step[static_cast<size_t>(event.region)] = event.level_step_before;
      --events_per_region[static_cast<size_t>(event.region)];
      continue;
    }
    if (done || --event.frames_to_confirm <= 0) {
      events.push_back(std::move(event));
      continue;
    }
    if (&pending[kept] != &event) pending[kept] = std::move(event);
    ++kept;
  }
  pending.resize(kept);
}

bool LedDetector::Impl::LooksLikeALight(const StepEvent& event) {
  const auto cell = [&](int row, int column) {
    return static_cast<double>(event.cell_steps[static_cast<size_t>(row * 4 + column)]);
  };
  const double centre = cell(1, 1) + cell(1, 2) + cell(2, 1) + cell(2, 2);
  if (centre <= 0) return false;
  double opposite = 0.0, largest = 0.0;
  for (const float step : event.cell_steps) {
    opposite += std::max(0.0, -static_cast<double>(step));
    largest = std::max(largest, static_cast<double>(step));
  }
  if (opposite > kOppositeFrac * centre) return false;
  // the widest row and the tallest column of cells that step by a good part of the most
  int wide = 0, tall = 0;
  for (int i = 0; i < 4; ++i) {
    int in_row = 0, in_column = 0;
    for (int j = 0; j < 4; ++j) {
      in_row += cell(i, j) >= kExtentFrac * largest;
      in_column += cell(j, i) >= kExtentFrac * largest;
    }
    wide = std::max(wide, in_row);
    tall = std::max(tall, in_column);
  }
  return std::abs(wide - tall) < 2;
}

Status LedDetector::Impl::Process(const Frame& frame) {
  LIFTOFF_RETURN_IF_ERROR(options_status);
  if (frame.bgr.empty() || frame.bgr.type() != CV_8UC3) {
    return InvalidArgumentError("frame " + std::to_string(frame.index) +
                                ": expected an 8-bit BGR picture");
  }
  if (frames == 0) {
    LIFTOFF_RETURN_IF_ERROR(Setup(frame));
  } else {
    if (frame.bgr.cols != width_px || frame.bgr.rows != height_px) {
      return InvalidArgumentError("frame " + std::to_string(frame.index) + " is " +
                                  std::to_string(frame.bgr.cols) + "x" +
                                  std::to_string(frame.bgr.rows) + ", the first was " +
                                  std::to_string(width_px) + "x" + std::to_string(height_px));
    }
    if (frame.t_ns <= last_t_ns) {
      return InvalidArgumentError("frame " + std::to_string(frame.index) + " at " +
                                  std::to_string(frame.t_ns) +
                                  " ns is not after the previous frame");
    }
    intervals_ns[interval_count % kIntervalWindow] = frame.t_ns - last_t_ns;
    ++interval_count;
  }
  last_t_ns = frame.t_ns;
  const size_t slot = Slot(frames);
  ring_index[slot] = frame.index;
  ring_t_ns[slot] = frame.t_ns;
  Measure(frame, slot);
  if (!located) {
    trace_t_ns.push_back(frame.t_ns);
    trace_brightness_levels.push_back(roi_mean_levels);
  }
  Confirm(slot);
  ++frames;
  if (frames >= window) Evaluate();
  if (!located) TestBuildUp();
  return Status::Ok();
}

LedPulse LedDetector::Impl::DatePulse(const StepEvent& event) const {
  const auto exposure_ns = static_cast<double>(NsFromSeconds(options.exposure_s));
  const ExposureRange exposure = exposure_ns > 0
                                     ? ExposureRange{exposure_ns, exposure_ns}
                                     : ExposureRange{0.0, static_cast<double>(event.period_ns)};
  const double scale = event.on - event.off;
  const double noise_fraction = event.noise / scale;
  const double band = std::max(kFractionSigmas * noise_fraction, kFractionMargin);
  const double lit_above = std::max(kFractionSigmas * noise_fraction, kLitFraction);
  const auto fraction = [&](size_t i) { return (event.value[i] - event.off) / scale; };
  // what the partly lit frame saw: its fraction within the noise band; when the LED's
  // pixels clip, a partly lit frame looks brighter than it was, so only the upper bound
  // holds. A dim step through a lossy codec moves each frame's fraction by up to
  // kDimCodecFrac either way (a codec copies or drops a step of a few grey levels whole: a
  // half-lit frame of hard3d-06's 0.6 px LED, 9 levels, is as lit as the next; another,
  // --seed 1000, as dark as the one before)
  const bool dim = event.contrast_levels < options.dim_warning_levels;
  const double shift = dim ? kDimCodecFrac : band;
  const auto lit_band = [&](double f) {
    return LitFraction{event.clipped ? 0.0 : std::max(0.0, f - shift - event.creep),
                       std::min(1.0, f + shift)};
  };
  const LitFraction dark{0.0, dim ? std::max(lit_above, kDimCodecFrac) : lit_above};
  const size_t count = event.value.size();
  LedPulse pulse;
  if (event.rise) {
    // the first frame above the threshold (the before-window frames are below it), or
    // the partly lit one just before it
    size_t lit = kBeforeFrames;
    for (size_t i = 0; i < count; ++i) {
      if (fraction(i) > options.threshold_frac) {
        lit = i;
        break;
      }
    }
    if (lit >= 2 && fraction(lit - 1) > lit_above && fraction(lit) >= 1.0 - band) --lit;
    // a build-up: its first frame, lit for an unknown part of its exposure (a codec held it)
    const bool built_up = event.build_up_frames > 1;
    if (built_up) lit = kBeforeFrames;
    const double f = std::clamp(fraction(lit), 0.0, 1.0);
    internal::SwitchOnDating dating = internal::DateSwitchOn(
        static_cast<double>(event.t_ns[lit - 1]), dark, static_cast<double>(event.t_ns[lit]),
        built_up ? LitFraction{0.0, 1.0} : lit_band(f), exposure,
        static_cast<double>(event.period_ns));
    pulse.first_lit_frame = event.index[lit];
    pulse.first_lit_fraction = f;
    // the frames lit part way around the dated one (a build-up has its own rule): two or
    // more in a row, and the switch-on may be anywhere between the last dark frame and the
    // first wholly lit one
    size_t first_partial = lit, first_whole = lit;
    while (first_partial >= 2 && fraction(first_partial - 1) > lit_above) --first_partial;
    while (first_whole + 1 < count && fraction(first_whole) < 1.0 - band) ++first_whole;
    pulse.spread_frames = built_up ? 0 : static_cast<int>(first_whole - first_partial);
    if (pulse.spread_frames >= 2) {
      const bool whole = fraction(first_whole) >= 1.0 - band;
      const InstantInterval spread = internal::SwitchOnInterval(
          static_cast<double>(event.t_ns[first_partial - 1]), dark,
          static_cast<double>(event.t_ns[first_whole]),
          whole ? LitFraction{1.0 - band, 1.0} : LitFraction{0.0, 1.0}, exposure);
      dating.surely = {std::min(dating.surely.low_ns, spread.low_ns),
                       std::max(dating.surely.high_ns, spread.high_ns)};
      // dated where the spread frames cross half lit, not by the first to pass the
      // threshold (a build-up's frame lit 49 % is the switch-on's own)
      size_t above = first_partial;
      while (above < first_whole && fraction(above) < 0.5) ++above;
      dating.estimate_ns = std::clamp(
          internal::HalfLitInstant(static_cast<double>(event.t_ns[above - 1]), fraction(above - 1),
                                   static_cast<double>(event.t_ns[above]), fraction(above)),
          dating.surely.low_ns, dating.surely.high_ns);
      dating.missing_frames = 0;  // (the crossing dates it, not a missing frame)
      pulse.first_lit_frame = event.index[first_partial];
      pulse.first_lit_fraction = std::clamp(fraction(first_partial), 0.0, 1.0);
    }
    pulse.on_ns = static_cast<int64_t>(std::llround(dating.estimate_ns));
    pulse.on_uncertainty_ns = dating.HalfWidth();
    pulse.missing_frames_before_on = dating.missing_frames;
  } else {
    // the last frame above the threshold (the after-window frames are below it), or the
    // partly lit one just after it
    size_t lit = kBeforeFrames - 1;
    for (size_t i = count; i-- > 0;) {
      if (fraction(i) > options.threshold_frac) {
        lit = i;
        break;
      }
    }
    if (lit + 2 < count && fraction(lit + 1) > lit_above && fraction(lit) >= 1.0 - band) ++lit;
    const double f = std::clamp(fraction(lit), 0.0, 1.0);
    const InstantInterval interval =
        internal::SwitchOffInterval(static_cast<double>(event.t_ns[lit]), lit_band(f),
                                    static_cast<double>(event.t_ns[lit + 1]), dark, exposure);
    pulse.off_ns = interval.Middle();
    pulse.off_uncertainty_ns = interval.HalfWidth();
  }
  return pulse;
}

cv::Rect LedDetector::Impl::LocatedRect(const StepEvent& event) const {
  const cv::Rect block = RegionRect(event.region);
  double weight = 0.0, x = 0.0, y = 0.0;
  const int block_column = event.region % block_columns, block_row = event.region / block_columns;
  for (int dy = 0; dy < 4; ++dy) {
    for (int dx = 0; dx < 4; ++dx) {
      const int column = block_column - 1 + dx, row = block_row - 1 + dy;
      const double cell_step = event.cell_steps[static_cast<size_t>(dy * 4 + dx)];
      if (cell_step <= 0 || column < 0 || row < 0 || column >= grid.columns || row >= grid.rows) {
        continue;
      }
      weight += cell_step;
      x += cell_step * (grid.x0_px[static_cast<size_t>(column)] + 0.5 * grid.cell_px);
      y += cell_step * (grid.y0_px[static_cast<size_t>(row)] + 0.5 * grid.cell_px);
    }
  }
  if (weight <= 0) return block;
  cv::Rect rect(static_cast<int>(std::lround(x / weight - 0.5 * block.width)),
                static_cast<int>(std::lround(y / weight - 0.5 * block.height)), block.width,
                block.height);
  rect.x = std::clamp(rect.x, 0, width_px - rect.width);
  rect.y = std::clamp(rect.y, 0, height_px - rect.height);
  return rect;
}

namespace {

// the contrast a switch-on of `steps` needs to be near the best one's: kEligibleContrastFrac
// of the largest
double EligibleContrast(const std::vector<const StepEvent*>& steps) {
  double best_contrast = 0.0;
  for (const StepEvent* step : steps) {
    if (step->rise) best_contrast = std::max(best_contrast, step->contrast_levels);
  }
  return kEligibleContrastFrac * best_contrast;
}

}  // namespace

int LedDetector::Impl::ChooseRegion(const std::vector<const StepEvent*>& steps) {
  const double eligible = EligibleContrast(steps);
  int best = -1;
  double best_step = 0.0;
  for (const StepEvent* event : steps) {
    if (event->rise && event->contrast_levels >= eligible && event->signal_step > best_step) {
      best_step = event->signal_step;
      best = event->region;
    }
  }
  return best;
}

int LedDetector::Impl::ChooseRoiSignal(const std::vector<const StepEvent*>& steps) {
  const double eligible = EligibleContrast(steps);
  int best = -1;
  for (const StepEvent* event : steps) {
    if (event->rise && event->contrast_levels >= eligible && (best < 0 || event->region < best)) {
      best = event->region;
    }
  }
  return best;
}

Status LedDetector::Impl::NoSwitchOn(const std::vector<const StepEvent*>& steps,
                                     const std::string& where) const {
  for (const StepEvent* step : steps) {
    const StepEvent& event = *step;
    if (!event.rise) {
      return NotFoundError("the LED never switches on: the only light step " + where +
                           " goes off, at " +
                           FormatFixed(SecondsFromNs(*DatePulse(event).off_ns), 4) +
                           " s (was the LED already on at the start?)");
    }
  }
  std::string message = "the LED never switches on: no brightness step " + where +
                        " rises and holds for " + Plural(options.min_on_frames, "frame");
  if (rejected_region >= 0) {
    message += " with enough contrast (the best: " + FormatFixed(rejected_contrast, 0) +
               " grey levels at " + RectText(RegionRect(rejected_region)) +
               ", min_contrast_levels " + FormatFixed(options.min_contrast_levels, 0) + ")";
  }
  return NotFoundError(message);
}

Result<LedResult> LedDetector::Impl::Finish() const {
  LIFTOFF_RETURN_IF_ERROR(options_status);
  if (frames == 0) return InvalidArgumentError("LED detector: no frame was given");
  const std::string where =
      located ? "anywhere in the frame" : "in the ROI " + RectText(options.roi_px);
  // every step, confirmed or still being confirmed at the end, in the order they happened
  std::vector<const StepEvent*> steps;
  for (const StepEvent& event : events) steps.push_back(&event);
  for (const StepEvent& event : pending) steps.push_back(&event);
  std::sort(steps.begin(), steps.end(), [](const StepEvent* a, const StepEvent* b) {
    return a->index[kBeforeFrames] < b->index[kBeforeFrames];
  });
  const int best = located ? ChooseRegion(steps) : ChooseRoiSignal(steps);
  if (best < 0) return NoSwitchOn(steps, where);

  // the LED's own steps: every pulse of one LED has about the same contrast, so the
  // region's fainter steps are something else (a shadow, a shifted edge)
  double best_contrast = 0.0;
  for (const StepEvent* event : steps) {
    if (event->region == best && event->rise) {
      best_contrast = std::max(best_contrast, event->contrast_levels);
    }
  }
  LedResult result;
  result.roi_located = located;
  result.trace_t_ns = trace_t_ns;
  result.trace_brightness_levels = trace_brightness_levels;
  bool first_rise_seen = false;
  bool already_on = false;
  int first_build_up_frames = 1;
  for (const StepEvent* step : steps) {
    const StepEvent& event = *step;
    if (event.region != best || event.contrast_levels < kEligibleContrastFrac * best_contrast) {
      continue;
    }
    if (!event.rise) {
      if (!first_rise_seen) already_on = true;
      if (!result.pulses.empty() && !result.pulses.back().off_ns) {
        const LedPulse off = DatePulse(event);
        result.pulses.back().off_ns = off.off_ns;
        result.pulses.back().off_uncertainty_ns = off.off_uncertainty_ns;
      }
      continue;
    }
    if (!first_rise_seen) {
      first_rise_seen = true;
      result.off_level = event.off_levels;
      result.on_level = event.on_levels;
      result.contrast_levels = event.contrast_levels;
      result.roi_px = located ? LocatedRect(event) : options.roi_px;
      first_build_up_frames = event.build_up_frames;
    }
    result.pulses.push_back(DatePulse(event));
  }
  if (!result.pulses.empty() && result.pulses.front().missing_frames_before_on > 0) {
    const LedPulse& first = result.pulses.front();
    result.warnings.push_back(
        Plural(first.missing_frames_before_on, "frame") + " missing just before the switch-on" +
        " (before frame " + std::to_string(first.first_lit_frame) +
        "): dated as seen by the first missing frame; its +- " +
        FormatFixed(1e-6 * static_cast<double>(first.on_uncertainty_ns), 1) +
        " ms covers the whole gap");
  }
  if (first_build_up_frames > 1) {
    const LedPulse& first = result.pulses.front();
    result.warnings.push_back(
        "built up over " + std::to_string(first_build_up_frames) + " frames from frame " +
        std::to_string(first.first_lit_frame) +
        " (a codec held the light at a partial level or let it wobble): dated from the first "
        "frame that changed, lit for an unknown part of its exposure, +- " +
        FormatFixed(1e-6 * static_cast<double>(first.on_uncertainty_ns), 1) + " ms");
  }
  if (first_build_up_frames <= 1 && !result.pulses.empty() &&
      result.pulses.front().spread_frames >= 2) {
    const LedPulse& first = result.pulses.front();
    result.warnings.push_back(
        "switched on part way over " + std::to_string(first.spread_frames) +
        " frames in a row from frame " + std::to_string(first.first_lit_frame) +
        " (an exposure no longer than the frame interval lights one frame part way: a codec "
        "spread the step, building a small light up or blending it over H.264's B-frames): "
        "its +- " +
        FormatFixed(1e-6 * static_cast<double>(first.on_uncertainty_ns), 1) +
        " ms reaches from the last dark frame to the first wholly lit one");
  }
  if (already_on) {
    result.warnings.push_back(
        "already on at the start: it went off before its first switch-on, which may have "
        "been missed");
  }
  if (result.contrast_levels < options.dim_warning_levels) {
    result.warnings.push_back(
        "dim: on-off contrast " + FormatFixed(result.contrast_levels, 0) +
        " grey levels (expected >= " + FormatFixed(options.dim_warning_levels, 0) + ")");
  }
  return result;
}

LedDetector::LedDetector(const Options& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->options_status = options.Validate().WithContext("LED detector options");
  impl_->located = options.roi_px.area() == 0;
}
LedDetector::LedDetector(LedDetector&&) noexcept = default;
LedDetector& LedDetector::operator=(LedDetector&&) noexcept = default;
LedDetector::~LedDetector() = default;

Status LedDetector::Process(const Frame& frame) { return impl_->Process(frame); }

std::vector<cv::Rect> LedDetector::RegionsRead(cv::Size frame_px) const {
  const cv::Rect whole(cv::Point(0, 0), frame_px);
  const cv::Rect& roi = impl_->options.roi_px;
  if (impl_->located || (roi & whole) != roi) return {whole};
  // the ROI's rows across the frame (the ROI and its strips), and the reference cells
  std::vector<cv::Rect> regions = {cv::Rect(0, roi.y, frame_px.width, roi.height)};
  const int cell_px = impl_->options.cell_px;
  if (frame_px.width < cell_px || frame_px.height < cell_px) return {whole};
  const Grid grid = Grid::Make(frame_px.width, frame_px.height, cell_px, kReferenceStride);
  for (const int y0 : grid.y0_px) {
    for (const int x0 : grid.x0_px) regions.emplace_back(x0, y0, cell_px, cell_px);
  }
  return regions;
}

Result<LedResult> LedDetector::Finish() const { return impl_->Finish(); }

}  // namespace liftoff::video
