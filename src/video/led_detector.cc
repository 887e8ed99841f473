#include "liftoff/video/led_detector.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <utility>

#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "video_util.h"

namespace liftoff::video {
namespace {

using internal::MedianOf;
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
// Automatic locating samples every other row; the gain uses every other cell column and
// row. With an ROI, the frame-wide statistics use every kReferenceStride-th cell.
constexpr int kAutoRowStep = 2;
constexpr int kGainStride = 2;
constexpr int kReferenceStride = 4;
// A measured fraction of the exposure is known to within max(sigmas * its noise, margin):
// the margin covers what noise estimates from a few frames miss (codec effects at the
// step), so a frame lit 92 % or more may have been lit all along.
constexpr double kFractionSigmas = 2.0;
constexpr double kFractionMargin = 0.08;
// A frame next to the step counts as partly lit above this fraction (or the noise band):
// H.264's B-frames borrow a little of the next frame's light, so the frame before a
// switch-on can look lit by a few percent.
constexpr double kLitFraction = 0.15;
// Intervals kept for the usual frame interval (the bound of an unknown exposure).
constexpr size_t kIntervalWindow = 31;
// Recorded steps per region at most (a region that keeps stepping is no sync LED).
constexpr size_t kMaxEventsPerRegion = 4096;

// Every how many of `count` values a quantile looks at (about kQuantileSamples of them).
size_t SampleStride(size_t count) { return std::max<size_t>(1, count / kQuantileSamples); }

// The value below which `fraction` of `values` lie (reorders them).
double QuantileOf(std::vector<double>& values, double fraction) {
  const auto position = values.begin() + static_cast<std::ptrdiff_t>(
                                             fraction * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), position, values.end());
  return *position;
}

// The cells of the automatic locator: origins of every cell column and row (the last one
// flush with the frame's edge, so the whole frame is covered).
struct Grid {
  int cell_px = 16;
  int columns = 0, rows = 0;
  std::vector<int> x0_px, y0_px;
  int sampled_px_per_cell = 0;

  // every `stride`-th cell of the full grid
  static Grid Make(int width_px, int height_px, int cell_px, int stride) {
    Grid grid;
    grid.cell_px = cell_px;
    const int columns = (width_px + cell_px - 1) / cell_px;
    const int rows = (height_px + cell_px - 1) / cell_px;
    for (int i = 0; i < columns; i += stride) {
      grid.x0_px.push_back(std::min(i * cell_px, width_px - cell_px));
    }
    for (int i = 0; i < rows; i += stride) {
      grid.y0_px.push_back(std::min(i * cell_px, height_px - cell_px));
    }
    grid.columns = static_cast<int>(grid.x0_px.size());
    grid.rows = static_cast<int>(grid.y0_px.size());
    grid.sampled_px_per_cell = cell_px * ((cell_px + kAutoRowStep - 1) / kAutoRowStep);
    return grid;
  }
  int cells() const { return columns * rows; }
};

#if defined(__SSE2__)
// one cell at a time, its sampled rows 16 bytes per instruction, the sum and the
// maximum kept in registers
void MeasureCellsSse2(const cv::Mat& bgr, const Grid& grid, float* sums, uint8_t* peaks) {
  const int chunks = grid.cell_px * 3 / 16;
  const size_t row_stride = bgr.step[0] * static_cast<size_t>(kAutoRowStep);
  const __m128i zero = _mm_setzero_si128();
  for (int row = 0; row < grid.rows; ++row) {
    const uint8_t* band = bgr.ptr<uint8_t>(grid.y0_px[static_cast<size_t>(row)]);
    for (int column = 0; column < grid.columns; ++column) {
      __m128i sum = zero, peak = zero;
      const uint8_t* line = band + grid.x0_px[static_cast<size_t>(column)] * 3;
      for (int y = 0; y < grid.cell_px; y += kAutoRowStep, line += row_stride) {
        for (int chunk = 0; chunk < chunks; ++chunk) {
          __m128i value;
          std::memcpy(&value, line + 16 * chunk, sizeof value);
          sum = _mm_add_epi64(sum, _mm_sad_epu8(value, zero));
          peak = _mm_max_epu8(peak, value);
        }
      }
      peak = _mm_max_epu8(peak, _mm_srli_si128(peak, 8));
      peak = _mm_max_epu8(peak, _mm_srli_si128(peak, 4));
      peak = _mm_max_epu8(peak, _mm_srli_si128(peak, 2));
      peak = _mm_max_epu8(peak, _mm_srli_si128(peak, 1));
      std::array<uint64_t, 2> halves{};
      std::memcpy(halves.data(), &sum, sizeof halves);
      const auto cell = static_cast<size_t>(row * grid.columns + column);
      sums[cell] = static_cast<float>(halves[0] + halves[1]);
      peaks[cell] = static_cast<uint8_t>(_mm_cvtsi128_si32(peak) & 0xff);
    }
  }
}
#endif

// Sum of B + G + R and the brightest channel value of every cell, every other row.
void MeasureCells(const cv::Mat& bgr, const Grid& grid, float* sums, uint8_t* peaks) {
  const int bytes_per_cell = grid.cell_px * 3;
#if defined(__SSE2__)
  if (bytes_per_cell % 16 == 0) {
    MeasureCellsSse2(bgr, grid, sums, peaks);
    return;
  }
#endif
  for (int row = 0; row < grid.rows; ++row) {
    for (int column = 0; column < grid.columns; ++column) {
      uint32_t sum = 0;
      uint8_t peak = 0;
      for (int y = 0; y < grid.cell_px; y += kAutoRowStep) {
        const uint8_t* pixel = bgr.ptr<uint8_t>(grid.y0_px[static_cast<size_t>(row)] + y) +
                               grid.x0_px[static_cast<size_t>(column)] * 3;
        for (int u = 0; u < bytes_per_cell; ++u) {
          sum += pixel[u];
          peak = std::max(peak, pixel[u]);
        }
      }
      const size_t cell = static_cast<size_t>(row * grid.columns + column);
      sums[cell] = static_cast<float>(sum);
      peaks[cell] = peak;
    }
  }
}

// Sum of B + G + R and the brightest channel value over a rectangle, every row.
std::pair<double, uint8_t> MeasureRect(const cv::Mat& bgr, const cv::Rect& rect) {
  uint64_t sum = 0;
  uint8_t peak = 0;
  const int bytes = rect.width * 3;
  for (int y = rect.y; y < rect.y + rect.height; ++y) {
    const uint8_t* pixel = bgr.ptr<uint8_t>(y) + rect.x * 3;
    int u = 0;
#if defined(__SSE2__)
    const __m128i zero = _mm_setzero_si128();
    __m128i sums = zero, peaks = zero;
    for (; u + 16 <= bytes; u += 16) {
      __m128i value;
      std::memcpy(&value, pixel + u, sizeof value);
      sums = _mm_add_epi64(sums, _mm_sad_epu8(value, zero));
      peaks = _mm_max_epu8(peaks, value);
    }
    std::array<uint64_t, 2> halves{};
    std::memcpy(halves.data(), &sums, sizeof halves);
    std::array<uint8_t, 16> lanes{};
    std::memcpy(lanes.data(), &peaks, sizeof lanes);
    sum += halves[0] + halves[1];
    peak = std::max(peak, *std::max_element(lanes.begin(), lanes.end()));
#endif
    for (; u < bytes; ++u) {
      sum += pixel[u];
      peak = std::max(peak, pixel[u]);
    }
  }
  return {static_cast<double>(sum), peak};
}

// The instants consistent with what the frames around a step saw, ns.
struct Interval {
  double low_ns = 0.0, high_ns = 0.0;
  int64_t Middle() const { return static_cast<int64_t>(std::llround(0.5 * (low_ns + high_ns))); }
  int64_t HalfWidth() const {
    return static_cast<int64_t>(std::llround(0.5 * std::max(0.0, high_ns - low_ns)));
  }
};

// A switch-on seen first by frame `lit` (start t_lit, lit for the last fraction in
// [f_low, f_high] of its exposure) after frame `dark` (start t_dark, lit for at most the
// last dark_high of its exposure, which passes for noise). exposure_ns > 0: known; else
// any exposure in (0, period_ns].
Interval SwitchOnInterval(double t_dark, double t_lit, double f_low, double f_high,
                          double dark_high, double exposure_ns, double period_ns) {
  Interval interval;
  if (exposure_ns > 0) {
    interval.low_ns = t_lit + (1 - f_high) * exposure_ns;
    interval.high_ns = t_lit + (1 - f_low) * exposure_ns;
    // fully lit: on between (the end of) the dark frame's exposure and this one's start
    if (f_high >= 1.0) interval.low_ns = std::min(t_dark + (1 - dark_high) * exposure_ns, t_lit);
  } else {
    interval.low_ns = f_high >= 1.0 ? t_dark : t_lit;
    interval.high_ns = t_lit + (1 - f_low) * period_ns;
  }
  return interval;
}

// A switch-off seen last by frame `lit` (lit for the first fraction in [f_low, f_high] of
// its exposure) before frame `dark` (lit for at most the first dark_high of its exposure).
Interval SwitchOffInterval(double t_lit, double t_dark, double f_low, double f_high,
                           double dark_high, double exposure_ns, double period_ns) {
  Interval interval;
  const double exposure_or_period_ns = exposure_ns > 0 ? exposure_ns : period_ns;
  interval.low_ns = exposure_ns > 0 ? t_lit + f_low * exposure_ns : t_lit;
  interval.high_ns = t_lit + f_high * exposure_or_period_ns;
  // fully lit: off between this exposure's end and (early in) the dark frame's
  if (f_high >= 1.0)
    interval.high_ns = std::max(interval.high_ns, t_dark + dark_high * exposure_or_period_ns);
  return interval;
}

enum class Level : uint8_t { kUnknown, kLow, kHigh };

// One step a region made, with what is needed to date it: the frames around it.
struct StepEvent {
  int region = 0;
  bool rise = true;
  double step = 0.0;             // on - off, region sum
  double off = 0.0, on = 0.0;    // region sum levels
  double noise = 0.0;            // region sum noise
  double contrast_levels = 0.0;  // brightest channel step
  int64_t period_ns = 0;         // usual frame interval at the time
  std::vector<int64_t> index, t_ns;
  std::vector<double> value;
  std::array<float, 16> cell_steps{};  // auto: the 4 x 4 cells around the block
  // while it is being confirmed: frames still to watch, frames seen between the levels,
  // and the region's level before it
  int frames_to_confirm = 0;
  int between = 0;
  Level level_before = Level::kUnknown;
};

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
                                std::to_string(threshold_frac));
  }
  if (min_on_frames < 1 || min_on_frames > 100) {
    return InvalidArgumentError("min_on_frames: expected 1 .. 100, got " +
                                std::to_string(min_on_frames));
  }
  if (!(min_contrast_levels > 0.0 && min_contrast_levels <= 255.0)) {
    return InvalidArgumentError("min_contrast_levels: expected 0 < x <= 255, got " +
                                std::to_string(min_contrast_levels));
  }
  if (!(dim_warning_levels >= min_contrast_levels && dim_warning_levels <= 255.0)) {
    return InvalidArgumentError("dim_warning_levels: expected min_contrast_levels .. 255, got " +
                                std::to_string(dim_warning_levels));
  }
  if (!(exposure_s >= 0.0 && exposure_s <= 1.0)) {
    return InvalidArgumentError("exposure_s: expected 0 (unknown) .. 1 s, got " +
                                std::to_string(exposure_s));
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
  // brightest channels, the regions' sums (and the ROI's brightest channel)
  int after_frames = 3;
  int ring = 0;
  int64_t frames = 0;
  std::vector<int64_t> ring_index, ring_t_ns;
  std::vector<double> ring_gain;
  std::vector<float> cell_sums;     // ring x cells
  std::vector<uint8_t> cell_peaks;  // ring x cells
  std::vector<double> region_sums;  // ring x regions
  std::vector<uint8_t> roi_peaks;   // ring (with an ROI)

  // per cell and region: the flicker reference, the usual frame-to-frame change, the level
  std::vector<float> cell_reference;
  double roi_reference = 0.0;
  std::vector<float> region_noise;
  std::vector<Level> level;

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
  double FlatFrac() const { return located ? kFlatFracLocated : kFlatFracRoi; }
  size_t Cells() const { return static_cast<size_t>(grid.cells()); }

  cv::Rect RegionRect(int region) const {
    if (!located) return options.roi_px;
    const auto column = static_cast<size_t>(region % block_columns);
    const auto row = static_cast<size_t>(region / block_columns);
    const int x0 = grid.x0_px[column], y0 = grid.y0_px[row];
    return cv::Rect(x0, y0, grid.x0_px[column + 1] + grid.cell_px - x0,
                    grid.y0_px[row + 1] + grid.cell_px - y0);
  }

  Status Setup(const Frame& frame) {
    width_px = frame.bgr.cols;
    height_px = frame.bgr.rows;
    after_frames = options.min_on_frames;
    ring = kBeforeFrames + 1 + after_frames;
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
      if (roi.x < 0 || roi.y < 0 || roi.x + roi.width > width_px ||
          roi.y + roi.height > height_px) {
        return InvalidArgumentError("LED ROI " + RectText(roi) + " is outside the " +
                                    std::to_string(width_px) + "x" + std::to_string(height_px) +
                                    " frame");
      }
      grid = Grid::Make(width_px, height_px, options.cell_px, kReferenceStride);
      regions = 1;
      pixels_per_region = static_cast<double>(roi.area());
    }
    const auto slots = static_cast<size_t>(ring);
    ring_index.assign(slots, 0);
    ring_t_ns.assign(slots, 0);
    ring_gain.assign(slots, 1.0);
    cell_sums.assign(slots * Cells(), 0.0f);
    region_sums.assign(slots * static_cast<size_t>(regions), 0.0);
    cell_peaks.assign(slots * Cells(), 0);
    roi_peaks.assign(slots, 0);
    cell_reference.assign(Cells(), 0.0f);
    region_noise.assign(static_cast<size_t>(regions), 0.0f);
    level.assign(static_cast<size_t>(regions), Level::kUnknown);
    events_per_region.assign(static_cast<size_t>(regions), 0);
    raw_sums.assign(Cells(), 0.0f);
    window_values.resize(static_cast<size_t>(ring));
    window_copy.resize(static_cast<size_t>(ring));
    window_peaks.resize(static_cast<size_t>(ring));
    window_sums.resize(static_cast<size_t>(ring));
    return Status::Ok();
  }

  // the frame's brightness against the cells' references: flicker of the lighting scales
  // the whole scene (not the LED's own light), so it is taken out additively
  double Gain() {
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

  void Measure(const Frame& frame, size_t slot) {
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
      const auto [sum, peak] = MeasureRect(frame.bgr, options.roi_px);
      if (frames == 0) roi_reference = sum;
      sums[0] = sum - (gain - 1.0) * roi_reference;
      roi_peaks[slot] = peak;
      roi_reference += (sum - roi_reference) * follow_rate;
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

  int64_t PeriodNs() const {
    if (interval_count == 0) return 0;
    std::array<int64_t, kIntervalWindow> copy = intervals_ns;
    return MedianOf(copy.data(), static_cast<int>(std::min(interval_count, kIntervalWindow)));
  }

  // what a step's jump must exceed to stand out from the frame at k (with an ROI: the
  // reference cells' sharp jumps, scaled to the ROI's size)
  double OutlierJump(int64_t k) {
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
    return kOutlierFactor * QuantileOf(jumps, kOutlierQuantile);
  }

  // what a step's contrast must reach to stand out from the frame at k: the brightest
  // channel of most cells stays put, except where many step together
  double OutlierContrast(int64_t k) {
    jumps.clear();
    const uint8_t* previous = &cell_peaks[Slot(k - 1) * Cells()];
    const uint8_t* next = &cell_peaks[Slot(k + 1) * Cells()];
    const double previous_gain = ring_gain[Slot(k - 1)], next_gain = ring_gain[Slot(k + 1)];
    for (size_t c = 0; c < Cells(); c += SampleStride(Cells())) {
      jumps.push_back(std::abs(next[c] / next_gain - previous[c] / previous_gain));
    }
    return kOutlierFactor * QuantileOf(jumps, kOutlierQuantile);
  }

  // the step test for frame k = newest - after_frames, every region
  void Evaluate() {
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
      const bool rise = jump > needed && level[r] != Level::kHigh;
      const bool fall = jump < -needed && level[r] != Level::kLow;
      if (rise || fall) {
        TestStep(region, k, rise, min_step, std::abs(jump), outlier_jump, outlier_contrast);
      }
    }
  }

  // the step of one series of the ring (medians of the windows before and after k),
  // signed so that the step's direction is positive
  template <typename T>
  double WindowStep(const std::vector<T>& series, size_t stride, size_t offset, int64_t k,
                    bool rise, std::vector<T>& window) const {
    for (int i = 0; i < ring; ++i) {
      window[static_cast<size_t>(i)] = series[Slot(k - kBeforeFrames + i) * stride + offset];
    }
    const double before = MedianOf(window.data(), kBeforeFrames);
    const double after = MedianOf(window.data() + kBeforeFrames + 1, after_frames);
    return rise ? after - before : before - after;
  }

  // the LED's own contrast, grey levels: the step of the brightest channel, or of the mean
  // where that is larger (a brighter object beside the LED hides its brightest pixel);
  // when locating, of the block's best cell
  double Contrast(int region, int64_t k, bool rise, double step) {
    if (!located) {
      const double peak_step = WindowStep(roi_peaks, 1, 0, k, rise, window_peaks);
      return std::max(peak_step, step / (3.0 * pixels_per_region));
    }
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

  void TestStep(int region, int64_t k, bool rise, double min_step, double jump,
                double& outlier_jump, double& outlier_contrast) {
    const auto at = [&](int64_t frame) {
      return Slot(frame) * static_cast<size_t>(regions) + static_cast<size_t>(region);
    };
    const auto count = static_cast<size_t>(ring);
    for (size_t i = 0; i < count; ++i) {
      window_values[i] = region_sums[at(k - kBeforeFrames + static_cast<int64_t>(i))];
    }
    const auto before = window_values.cbegin();
    const auto before_end = before + kBeforeFrames;
    const auto after = before_end + 1;
    const auto after_end = window_values.cend();
    const auto [before_low, before_high] = std::minmax_element(before, before_end);
    const auto [after_low, after_high] = std::minmax_element(after, after_end);
    const double before_spread = *before_high - *before_low;
    const double after_spread = *after_high - *after_low;
    std::copy(window_values.begin(), window_values.end(), window_copy.begin());
    const double before_level = MedianOf(window_copy.data(), kBeforeFrames);
    const double after_level = MedianOf(window_copy.data() + kBeforeFrames + 1, after_frames);
    const double step = rise ? after_level - before_level : before_level - after_level;
    if (step < min_step) return;
    const double flat = FlatFrac();
    if (before_spread > flat * step || after_spread > flat * step) return;
    // a partly lit frame just after k is the next frame's transition: wait for it
    if (std::abs(*after - after_level) > 0.5 * flat * step) return;
    const double off = rise ? before_level : after_level;
    const double threshold = off + options.threshold_frac * step;
    if (rise ? !(*before_high<threshold&& * after_low> threshold)
             : !(*before_low > threshold && *after_high < threshold)) {
      return;
    }
    if (outlier_jump < 0) outlier_jump = OutlierJump(k);
    if (jump < outlier_jump) return;

    const double contrast = Contrast(region, k, rise, step);
    if (outlier_contrast < 0) outlier_contrast = OutlierContrast(k);
    if (contrast < outlier_contrast) return;
    if (contrast < options.min_contrast_levels) {
      if (rise && contrast > rejected_contrast) {
        rejected_contrast = contrast;
        rejected_region = region;
      }
      return;
    }
    if (events_per_region[static_cast<size_t>(region)] >= kMaxEventsPerRegion) return;

    StepEvent event;
    event.region = region;
    event.rise = rise;
    event.step = step;
    event.off = off;
    event.on = off + step;
    event.noise = 0.5 * std::max(before_spread, after_spread);
    event.contrast_levels = contrast;
    event.period_ns = PeriodNs();
    for (int64_t frame = k - kBeforeFrames; frame <= k + after_frames; ++frame) {
      event.index.push_back(ring_index[Slot(frame)]);
      event.t_ns.push_back(ring_t_ns[Slot(frame)]);
      event.value.push_back(region_sums[at(frame)]);
    }
    if (located) {
      RecordCellSteps(event, k);
      if (!LooksLikeALight(event)) return;
    }
    event.frames_to_confirm = kConfirmFrames;
    event.level_before = level[static_cast<size_t>(region)];
    level[static_cast<size_t>(region)] = rise ? Level::kHigh : Level::kLow;
    ++events_per_region[static_cast<size_t>(region)];
    pending.push_back(std::move(event));
  }

  // the step of each of the 4 x 4 cells around the block (medians of the same windows)
  void RecordCellSteps(StepEvent& event, int64_t k) {
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

  // the steps being confirmed against the newest frame: confirmed ones join `events`,
  // rejected ones give their region back its level
  void Confirm(size_t slot) {
    size_t kept = 0;
    for (StepEvent& event : pending) {
      const double value =
          region_sums[slot * static_cast<size_t>(regions) + static_cast<size_t>(event.region)];
      const double tolerance = FlatFrac() * event.step;
      const double held = event.rise ? event.on : event.off;
      const double left = event.rise ? event.off : event.on;
      bool done = false;
      if (std::abs(value - left) <= tolerance) {
        done = true;  // back already: a short pulse
      } else if (std::abs(value - held) > tolerance && ++event.between > 1) {
        level[static_cast<size_t>(event.region)] = event.level_before;
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

  // a light switching is local and one-signed: the cells around the block do not step the
  // other way (an edge moving by, with camera shake or a passing foot, darkens one side as
  // it brightens the other), and its step is about as wide as it is tall (an edge or a
  // band shifted across the region steps a row or a column of cells)
  static bool LooksLikeALight(const StepEvent& event) {
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

  Status Process(const Frame& frame) {
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
    Confirm(slot);
    ++frames;
    if (frames >= ring) Evaluate();
    return Status::Ok();
  }

  // the instant of one step, from its frames
  LedPulse DatePulse(const StepEvent& event) const {
    const double exposure_ns = static_cast<double>(NsFromSeconds(options.exposure_s));
    const auto period_ns = static_cast<double>(event.period_ns);
    const double scale = event.on - event.off;
    const double noise_fraction = event.noise / scale;
    const double band = std::max(kFractionSigmas * noise_fraction, kFractionMargin);
    const double lit_above = std::max(kFractionSigmas * noise_fraction, kLitFraction);
    const auto fraction = [&](size_t i) { return (event.value[i] - event.off) / scale; };
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
      if (lit >= 2 && fraction(lit - 1) > lit_above) --lit;
      const double f = std::clamp(fraction(lit), 0.0, 1.0);
      const Interval interval = SwitchOnInterval(
          static_cast<double>(event.t_ns[lit - 1]), static_cast<double>(event.t_ns[lit]),
          std::max(0.0, f - band), std::min(1.0, f + band), lit_above, exposure_ns, period_ns);
      pulse.on_ns = interval.Middle();
      pulse.on_uncertainty_ns = interval.HalfWidth();
      pulse.first_lit_frame = event.index[lit];
      pulse.first_lit_fraction = f;
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
      if (lit + 2 < count && fraction(lit + 1) > lit_above) ++lit;
      const double f = std::clamp(fraction(lit), 0.0, 1.0);
      const Interval interval = SwitchOffInterval(
          static_cast<double>(event.t_ns[lit]), static_cast<double>(event.t_ns[lit + 1]),
          std::max(0.0, f - band), std::min(1.0, f + band), lit_above, exposure_ns, period_ns);
      pulse.off_ns = interval.Middle();
      pulse.off_uncertainty_ns = interval.HalfWidth();
    }
    return pulse;
  }

  // located: a square of the block's size around the centroid of the cells' steps
  cv::Rect LocatedRect(const StepEvent& event) const {
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

  // the LED's region: among the switch-ons with a brightest-channel contrast near the best
  // one, the largest step
  static int ChooseRegion(const std::vector<const StepEvent*>& steps) {
    double best_contrast = 0.0;
    for (const StepEvent* event : steps) {
      if (event->rise) best_contrast = std::max(best_contrast, event->contrast_levels);
    }
    int best = -1;
    double best_step = 0.0;
    for (const StepEvent* event : steps) {
      if (event->rise && event->contrast_levels >= kEligibleContrastFrac * best_contrast &&
          event->step > best_step) {
        best_step = event->step;
        best = event->region;
      }
    }
    return best;
  }

  Result<LedResult> Finish() const {
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
    const int best = ChooseRegion(steps);
    if (best < 0) {
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

    LedResult result;
    result.roi_located = located;
    bool first_rise_seen = false;
    bool already_on = false;
    for (const StepEvent* step : steps) {
      const StepEvent& event = *step;
      if (event.region != best) continue;
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
        result.off_level = event.off / (3.0 * pixels_per_region);
        result.on_level = event.on / (3.0 * pixels_per_region);
        result.contrast_levels = event.contrast_levels;
        result.roi_px = located ? LocatedRect(event) : options.roi_px;
      }
      result.pulses.push_back(DatePulse(event));
    }
    if (already_on) {
      result.warnings.push_back(
          "LED already on at the start: it went off before its first switch-on, which may have "
          "been missed");
    }
    if (result.contrast_levels < options.dim_warning_levels) {
      result.warnings.push_back(
          "LED dim: on-off contrast " + FormatFixed(result.contrast_levels, 0) +
          " grey levels (expected >= " + FormatFixed(options.dim_warning_levels, 0) + ")");
    }
    return result;
  }
};

LedDetector::LedDetector(const Options& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->options_status = options.Validate().WithContext("LED detector options");
  impl_->located = options.roi_px.area() == 0;
}
LedDetector::LedDetector(LedDetector&&) noexcept = default;
LedDetector& LedDetector::operator=(LedDetector&&) noexcept = default;
LedDetector::~LedDetector() = default;

Status LedDetector::Process(const Frame& frame) { return impl_->Process(frame); }
Result<LedResult> LedDetector::Finish() const { return impl_->Finish(); }

}  // namespace liftoff::video
