#include "liftoff/video/foot_tracker.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "area_resize.h"
#include "height_curve.h"
#include "liftoff/core/field_checker.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "patch_registration.h"
#include "patch_selection.h"
#include "rise_fit.h"
#include "row_levels.h"
#include "video_util.h"

namespace liftoff::video {
namespace {

using internal::kGroundTolerancePx;
using internal::MedianCurve;
using internal::MovingWithTheOthers;
using internal::RestingWithTheOthers;

using internal::PatchMatch;
using internal::PatchTemplate;
using internal::RectText;

// The work image: the foot region and a margin of this fraction of its size on every side
// (static ground for the camera's shake), scaled so that the region's smaller side is
// kWorkRegionPx: down from larger (registration keeps its sub-pixel precision; large
// regions cost no more than small ones), up from under kEnlargeBelowPx (a small foot still
// holds several patches); 48 .. 64 px stay as they are. Enlarged, the larger side stays
// under kWorkLargestPx (a thin region).
constexpr double kMarginFraction = 0.3;
constexpr double kWorkRegionPx = 64.0;
// A region whose smaller side is under this is enlarged to kWorkRegionPx (at 48 rather
// than 32, the dev set at half size had d05 at +0.0012 rad instead of -0.0068).
constexpr int kEnlargeBelowPx = 48;
constexpr double kWorkLargestPx = 256.0;
// Patch side in work px, and the spacing of candidate patches.
constexpr int kPatchPx = 9;
constexpr int kPatchStridePx = 3;
// Patches kept: inside the foot region, and in the margin around it.
constexpr size_t kRegionPatches = 56;
constexpr size_t kMarginPatches = 24;
// Frames averaged into the templates (noise of a single frame would be in every sample).
constexpr int kTemplateFrames = 4;
// Rolling bands: each frame's rows are levelled to the templates' (row_levels.h) in a clip
// whose rows' gains, measured beside the work region (the frame's same rows every
// kStripStepPx px, up to kStripSpan work regions' widths left and right of it) against the
// template frames' and smoothed over 2 * kLevelSmoothRows + 1 frame rows, differ by more
// than kLevelMinRange from row to row in the median of its first kLevelDecideFrames frames
// after the templates (before that: in each frame whose gains differ so). Mains flicker
// bands a clip throughout; a frame's noise in low light with shake, or the robot's parts
// entering the rows beside the region, do not. Samples darker than kLevelMinGrey in the
// templates are not measured.
constexpr int kStripStepPx = 8;
constexpr int kStripSpan = 3;
// Fewer columns beside the region than this (a region as wide as the frame) measure no
// bands; a row gain under kMinLevelGain (a black frame) is not divided by.
constexpr size_t kStripMinColumns = 8;
constexpr float kMinLevelGain = 0.05f;
constexpr int kLevelSmoothRows = 7;
constexpr float kLevelMinRange = 0.15f;
constexpr float kLevelMinGrey = 10.0f;
constexpr size_t kLevelDecideFrames = 15;
// A patch whose residual exceeds this multiple of its running typical residual (plus a
// floor in grey levels) is not measured in that frame; after kLostFrames such frames in a
// row it is dropped.
constexpr double kResidualFactor = 2.5;
constexpr double kResidualFloor = 6.0;
constexpr int kLostFrames = 8;
// Largest camera shake searched between the templates and a frame, work px; a step from
// the last frame's shift under kGroundLocalStepPx, fitting within kGroundResidualFactor of
// the usual residual, is taken without the search.
constexpr int kShakeSearchPx = 8;
constexpr double kGroundLocalStepPx = 1.0;
constexpr double kGroundResidualFactor = 1.25;
// ... plus this, grey levels (a still, noiseless camera's residual is 0).
constexpr double kGroundResidualFloor = 1.0;
// A search's shift within this of the local registration's confirms it, px.
constexpr double kGroundConfirmPx = 0.25;
// Largest gain change accepted for a patch (a patch that needs more is not the same thing).
constexpr double kMaxGain = 0.5;
// A patch is the foot's when its final rise is at least this fraction of the foot's largest
// (patches on the foot's border with the ground move only in part).
constexpr double kFootFraction = 0.8;
// The fit ends where the rising curve reaches this many thresholds (at least this many
// px): from a lossy codec, high enough to see past its lag (the model bridges the rest);
// from a lossless one, close to the threshold, where the two-term model holds best.
constexpr double kFitTopThresholdsLossy = 8.0;
constexpr double kFitTopPxLossy = 4.0;
constexpr double kFitTopThresholdsLossless = 3.0;
constexpr double kFitTopPxLossless = 1.5;
// A key frame this soon after the fit's top extends the fit to it, s.
constexpr double kKeyframeReachS = 1.5;
// ... while the curve stays within this multiple of the fit's top.
constexpr double kKeyframeReachTops = 3.0;
// Weight of samples within a codec's possible lag below the model, and the least lag
// allowed for when frames are predicted (internal::RiseFitOptions).
constexpr double kLagWeight = 0.02;
constexpr double kMinLagPx = 0.3;
// A catch-up is partial: the lag allowed for is this multiple of the largest one seen.
constexpr double kLagBoundFactor = 1.5;
// A catch-up counts beyond this many sigmas of the still foot's frame-to-frame change (its
// rest noise times sqrt(2)): a noisy curve's changes stand out of their neighbours' by chance.
constexpr double kCatchUpNoiseSigmas = 3.0;
// Longest stretch of rest fitted before the rise, s.
constexpr double kFitRestS = 3.0;
// A key frame that resets a drift (internal::ResetsADrift) begins the rest when at least
// this long lies between it and the cut, s.
constexpr double kRestAfterResetS = 1.0;
// The curve's running median for the search, s either side.
constexpr double kSmoothHalfS = 0.15;
// A lift is sustained for this long (and this many frames at least), s; the rest before
// it counts as reached after kRestingS flat.
constexpr double kSustainS = 0.5;
constexpr size_t kSustainFrames = 5;
constexpr double kRestingS = 0.5;
// Where a patch ends: its median over the clip's last this long, s.
constexpr double kFinalS = 0.5;
// A rising patch lost this many final windows before the last rising one is stale.
constexpr size_t kStaleFinals = 4;
// Weak evidence: fewer foot (ground) patches than these, a curve noisier than this
// fraction of the threshold, an instant more uncertain than this, a clip ending fewer
// thresholds up than this.
constexpr size_t kFewFootPatches = 3;
constexpr size_t kFewGroundPatches = 3;
constexpr double kNoisyFraction = 0.5;
constexpr double kWideUncertaintyS = 0.25;
constexpr double kShortRiseThresholds = 6.0;
// A foot that lifts goes on rising: through a lossy codec, a curve that never gets this many
// thresholds above rest did not lift (a codec renewing a still picture can move a small
// foot's edge by a threshold or more: the never-lifting d12 of shared/video-dev, encoded
// again by OpenCV's H.264 writer, stayed above the threshold to its end).
constexpr double kMinLiftThresholds = 4.0;
// ... and never fewer px than this (a small robot's threshold is a fraction of a pixel:
// d12 at half its size, 0.21 px a mm, had one foot patch step 1.1 px and stay there)
constexpr double kMinLiftPxLossy = 2.0;
// A lagging curve this many of its still noise's sigmas above the threshold (three frames)
// bounds the liftoff from above (BoundByTheCurve).
constexpr double kSurelyAboveSigmas = 2.0;
// A key frame between still stretches of this long (and this many frames at least), each
// within this many thresholds, renews the picture's quality only.
constexpr double kQuietS = 0.15;
constexpr size_t kQuietFrames = 5;
constexpr double kQuietThresholds = 0.1;
// A curve this many thresholds below rest before its rise measures more than the foot.
constexpr double kSunkThresholds = 2.0;
// Patches lost during the rise widen the interval down to their crossing when that came at
// most this long before it, s (further back they rose with something else: hard3d-07,
// --seed 2000, had lost patches cross 1.8 s before the foot did).
constexpr double kLostRiseReachS = 0.5;
// The height curve's own error, px: a registration reads a sharp edge moved by a fraction
// of a pixel with a sawtooth error (~0.1 px on the 2D renderer's row-blended sprite), and a
// shaken camera adds to it (0.16 px rms under 1 px-a-frame shake: foot_tracker_test).
constexpr double kRegistrationErrorPx = 0.15;
// Below this rest noise (px) a lossless curve is crossed by a line through its own frames;
// above it, by the fitted model (which averages over many frames).
constexpr double kLocalCrossingNoisePx = 0.05;
// The largest uncertainty reported, s (a day: a bound on the arithmetic, not a result).
constexpr double kLongestUncertaintyS = 86400.0;
// Scale uncertainty assumed for an estimated px_per_mm (a fraction).
constexpr double kEstimatedScaleFraction = 0.03;

int64_t RoundNs(double value) { return static_cast<int64_t>(std::llround(value)); }
double Seconds(int64_t t_ns) { return static_cast<double>(t_ns) * 1e-9; }
std::string MsText(int64_t t_ns) { return FormatFixed(static_cast<double>(t_ns) / 1e6, 1); }
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

}  // namespace

// ---------------------------------------------------------------------------------------
// options and results

Status FootTracker::Options::Validate() const {
  if (foot_roi_px.width < 8 || foot_roi_px.height < 8) {
    return InvalidArgumentError("foot_roi_px: expected at least 8 x 8 px, got " +
                                std::to_string(foot_roi_px.width) + " x " +
                                std::to_string(foot_roi_px.height));
  }
  return ValidateAllButRegion();
}

Status FootTracker::Options::ValidateAllButRegion() const {
  FieldChecker check;
  if (threshold_px) {
    check.Number("threshold_px", *threshold_px, {.min = 0, .max = 1000, .min_exclusive = true});
  } else {
    check.Number("threshold_mm", threshold_mm, {.min = 0, .max = 100, .min_exclusive = true});
  }
  check.Number("px_per_mm", px_per_mm, {.min = 0, .max = 1000});
  check.Number("foot_width_mm", foot_width_mm, {.min = 0, .max = 10000, .min_exclusive = true});
  check.Integer("rest_frames", rest_frames, {.min = 2, .max = 100000});
  check.Number("compression_error_px", compression_error_px, {.min = 0, .max = 10});
  check.Number("exposure_s", exposure_s, {.min = 0, .max = 10});
  check.Number("min_quality", min_quality, {.min = 0, .max = 1});
  return check.status();
}

std::string FootTrack::Brief() const {
  std::string scale;
  if (px_per_mm > 0) {
    scale = FormatFixed(threshold_px / px_per_mm, 2) + " mm = " + FormatFixed(threshold_px, 2) +
            " px" + (px_per_mm_estimated ? ", scale estimated" : "");
  } else {
    scale = FormatFixed(threshold_px, 2) + " px";
  }
  return "liftoff (" + scale + ") at " + FormatSeconds(above_threshold.t_ns, 4) + " s +- " +
         MsText(above_threshold.uncertainty_ns) + " ms, onset " + FormatSeconds(onset.t_ns, 4) +
         " s +- " + MsText(onset.uncertainty_ns) + " ms";
}

// ---------------------------------------------------------------------------------------
// the tracker: every frame, every patch registered against its template

namespace {

struct TrackedPatch {
  PatchTemplate templ;
  // current top-left corner, work px; running typical residual, grey levels
  cv::Point2d position_px;
  double typical_residual = 0;
  int misses = 0;
  bool lost = false;
  bool in_region = false;
};

struct PatchSelection;  // which patches are the foot and the ground (at the end)

}  // namespace

struct FootTracker::Impl {
  Options options;
  Status options_status;
  int64_t rest_from_ns = 0, rest_to_ns = 0;

  cv::Size frame_size;
  bool size_known = false;
  cv::Rect work_px;  // frame px
  double scale = 1;  // work px per frame px
  cv::Rect region_work_px;  // the foot region in work px
  cv::Mat work, accumulated;
  // the work region's rows beside it (grey: the mean of B, G, R): this frame's every
  // kStripStepPx px (strip_columns, frame px), and the template frames' mean over the whole
  // span, which the rows are levelled to (moved as the ground moved)
  cv::Rect strip_span_px;
  std::vector<int> strip_columns;
  cv::Mat strips, span_reference, aligned_reference;
  std::vector<float> level_ranges;  // the first frames' gain ranges, until `banded` is known
  std::optional<bool> banded;
  internal::AreaResizer resizer;  // the work region to the work image (scale < 1)
  // the ground around the region as one weighted template, and without a border as the
  // template of the integer search; the last frame's shift of it (work px): a shaken camera
  // moves every patch at once, further than a small patch can follow alone
  PatchTemplate ground_fine;
  cv::Mat ground_search, ground_mask, search_scores, grey;
  cv::Point2d global_shift_px;
  double ground_residual = -1;  // the ground's usual residual, grey levels (-1: not yet)
  int accumulated_frames = 0;
  bool initialised = false;
  std::vector<TrackedPatch> patches;
  // frames x patches: each patch's rise since its template, frame px (up positive)
  std::vector<float> rises;
  size_t measured_from = 0;  // first sample with rises
  std::vector<HeightSample> samples;
  int64_t last_t_ns = 0;

  void ChooseWorkRegion(const cv::Size& size);
  void MakeWorkImage(const cv::Mat& bgr);
  // the work region's rows beside it into `strips`; during the template frames also their
  // whole span into span_reference
  void SampleStrips(const cv::Mat& bgr);
  // divides the work image's rows by their gains against the templates' where they are
  // banded (a rolling shutter's flicker), so that patches see the templates' banding; the
  // templates' rows moved by the ground's shift since them (work px)
  void LevelToTheTemplates(const cv::Point2d& shift);
  void InitialisePatches();
  // every patch registered, from where it was moved as the ground moved (`shift`, work px,
  // since the templates)
  void MeasurePatches(const cv::Point2d& shift);
  void AccumulateTemplates(const cv::Mat& bgr);
  void MakeGroundTemplates();
  cv::Point2d GroundShift();
  cv::Rect2d PlacePatches(const PatchSelection& selection, FootTrack& track) const;
  Result<FootTrack> Measure(const PatchSelection& selection, const std::vector<size_t>& rest,
                            std::vector<HeightSample> curve) const;
};

namespace {

// the foot region with a margin around it, inside the frame
cv::Rect WorkRegion(const cv::Rect& roi, const cv::Size& size) {
  const int margin_x = static_cast<int>(std::lround(kMarginFraction * roi.width));
  const int margin_y = static_cast<int>(std::lround(kMarginFraction * roi.height));
  return cv::Rect(roi.x - margin_x, roi.y - margin_y, roi.width + 2 * margin_x,
                  roi.height + 2 * margin_y) &
         cv::Rect(0, 0, size.width, size.height);
}

// a pixel's grey level for the strips: the mean of B, G and R
float MeanGrey(const uint8_t* bgr) { return static_cast<float>(bgr[0] + bgr[1] + bgr[2]) / 3.0f; }

// the work region's rows, kStripSpan of its widths either side of it, inside the frame
cv::Rect StripRegion(const cv::Rect& work, const cv::Size& size) {
  const int span = kStripSpan * work.width;
  return cv::Rect(work.x - span, work.y, work.width + 2 * span, work.height) &
         cv::Rect(0, 0, size.width, size.height);
}

}  // namespace

void FootTracker::Impl::ChooseWorkRegion(const cv::Size& size) {
  const cv::Rect& roi = options.foot_roi_px;
  work_px = WorkRegion(roi, size);
  // shrunk to kWorkRegionPx; a small region enlarged to it, so that a small foot still holds
  // several patches (the dev set at half size: d07's 7 px foot in a 25 px region was
  // "never lifts" at its own size, -0.0026 rad enlarged; hard3d-04 at seed 3000, -0.0151
  // rad in a 24 px region, -0.0004 enlarged)
  const int smaller = std::min(roi.width, roi.height);
  const int larger = std::max(roi.width, roi.height);
  scale = smaller < kEnlargeBelowPx
              ? std::max(1.0, std::min(kWorkRegionPx / smaller, kWorkLargestPx / larger))
              : std::min(1.0, kWorkRegionPx / smaller);
  if (scale < 1) resizer = internal::AreaResizer(work_px.size(), scale);
  const auto to_work = [&](int v, int origin) {
    return static_cast<int>(std::lround((v - origin) * scale));
  };
  region_work_px = cv::Rect(cv::Point(to_work(roi.x, work_px.x), to_work(roi.y, work_px.y)),
                            cv::Point(to_work(roi.x + roi.width, work_px.x),
                                      to_work(roi.y + roi.height, work_px.y)));
}

void FootTracker::Impl::MakeWorkImage(const cv::Mat& bgr) {
  const cv::Mat crop = bgr(work_px);
  if (scale < 1) {
    resizer.Apply(crop, work);
  } else if (scale > 1) {
    cv::Mat real;
    crop.convertTo(real, CV_32FC3);
    cv::resize(real, work, cv::Size(), scale, scale, cv::INTER_CUBIC);
  } else {
    crop.convertTo(work, CV_32FC3);
  }
}

// Candidates on a grid, strongest vertical texture first, none overlapping another by more
// than half; up to kRegionPatches inside the foot region and kMarginPatches around it.
void FootTracker::Impl::InitialisePatches() {
  struct Candidate {
    PatchTemplate templ;
    bool in_region;
  };
  std::vector<Candidate> candidates;
  for (int y = 1; y + kPatchPx + 1 < work.rows; y += kPatchStridePx) {
    for (int x = 1; x + kPatchPx + 1 < work.cols; x += kPatchStridePx) {
      PatchTemplate templ = internal::MakePatchTemplate(work, cv::Point(x, y), kPatchPx);
      if (!templ.usable || templ.texture_y < 1.0) continue;
      const cv::Point centre(x + kPatchPx / 2, y + kPatchPx / 2);
      candidates.push_back({std::move(templ), region_work_px.contains(centre)});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return a.templ.texture_y > b.templ.texture_y;
  });
  size_t in_region = 0, in_margin = 0;
  for (Candidate& candidate : candidates) {
    size_t& count = candidate.in_region ? in_region : in_margin;
    if (count >= (candidate.in_region ? kRegionPatches : kMarginPatches)) continue;
    const bool overlaps = std::any_of(patches.begin(), patches.end(), [&](const TrackedPatch& p) {
      return std::abs(p.templ.origin_px.x - candidate.templ.origin_px.x) < kPatchPx / 2.0 &&
             std::abs(p.templ.origin_px.y - candidate.templ.origin_px.y) < kPatchPx / 2.0;
    });
    if (overlaps) continue;
    TrackedPatch patch;
    patch.position_px = candidate.templ.origin_px;
    patch.in_region = candidate.in_region;
    patch.templ = std::move(candidate.templ);
    patches.push_back(std::move(patch));
    ++count;
  }
}

// The templates: the mean of the first kTemplateFrames frames (a single frame's noise would
// be in every sample), each moved back by the ground's shift from the first (a shaken
// camera would blur the mean).
void FootTracker::Impl::AccumulateTemplates(const cv::Mat& bgr) {
  if (accumulated_frames == 0) {
    MakeGroundTemplates();
    accumulated = work.clone();
  } else {
    const cv::Point2d shift = GroundShift();
    global_shift_px = shift;
    const cv::Matx23d back(1, 0, -shift.x, 0, 1, -shift.y);
    cv::Mat aligned;
    cv::warpAffine(work, aligned, back, work.size(), cv::INTER_LINEAR, cv::BORDER_REPLICATE);
    accumulated += aligned;
  }
  if (++accumulated_frames < kTemplateFrames) return;
  work = accumulated / kTemplateFrames;
  span_reference /= kTemplateFrames;
  InitialisePatches();
  MakeGroundTemplates();
  global_shift_px = cv::Point2d(0, 0);
  initialised = true;
  accumulated.release();
  MakeWorkImage(bgr);
}

// The ground: the work image in grey less the foot region (weight 0 there and at the
// image's edge), whole for the sub-pixel registration, and less a border of
// kShakeSearchPx for the search of the integer shift.
void FootTracker::Impl::MakeGroundTemplates() {
  cv::cvtColor(work, grey, cv::COLOR_BGR2GRAY);
  cv::Mat weights(grey.size(), CV_32F, cv::Scalar(1.0f));
  weights(region_work_px & cv::Rect(0, 0, grey.cols, grey.rows)).setTo(0.0f);
  const cv::Rect inner(1, 1, grey.cols - 2, grey.rows - 2);
  ground_fine = internal::MakeWeightedTemplate(grey, inner, weights(inner));
  const cv::Rect searched(kShakeSearchPx, kShakeSearchPx, grey.cols - 2 * kShakeSearchPx,
                          grey.rows - 2 * kShakeSearchPx);
  if (searched.width < kPatchPx || searched.height < kPatchPx) return;
  ground_search = grey(searched).clone();
  ground_mask = weights(searched).clone();
}

// The ground's shift since the templates, work px: registered from the last frame's when
// that fits as well as usual and moved under kGroundLocalStepPx; else the best normalised
// correlation over every integer shift within kShakeSearchPx (textured ground is often
// periodic: a local search would slip by a period), refined to sub-pixel with gain and
// offset; the last frame's when it cannot be measured.
cv::Point2d FootTracker::Impl::GroundShift() {
  if (!ground_fine.usable || ground_search.empty()) return global_shift_px;
  cv::cvtColor(work, grey, cv::COLOR_BGR2GRAY);
  // from the last frame's shift: accepted when it fits as well as usual and moved little
  const PatchMatch local = internal::RegisterPatch(
      ground_fine, grey, ground_fine.origin_px + global_shift_px, 10, 0.005);
  const cv::Point2d local_shift = local.origin_px - ground_fine.origin_px;
  const bool usual = ground_residual >= 0 && local.residual_rms <= kGroundResidualFactor *
                                                                     ground_residual +
                                                                 kGroundResidualFloor;
  if (local.ok && usual && cv::norm(local_shift - global_shift_px) < kGroundLocalStepPx) {
    ground_residual = 0.9 * ground_residual + 0.1 * local.residual_rms;
    return local_shift;
  }
  // else every integer shift
  cv::matchTemplate(grey, ground_search, search_scores, cv::TM_CCORR_NORMED, ground_mask);
  cv::Point best;
  cv::minMaxLoc(search_scores, nullptr, nullptr, nullptr, &best);
  const cv::Point2d guess(best.x - kShakeSearchPx, best.y - kShakeSearchPx);
  const PatchMatch fine =
      internal::RegisterPatch(ground_fine, grey, ground_fine.origin_px + guess, 10, 0.005);
  const cv::Point2d shift = fine.origin_px - ground_fine.origin_px;
  const bool near = std::abs(shift.x - guess.x) <= 1 && std::abs(shift.y - guess.y) <= 1;
  if (!(fine.ok && near)) return guess;
  // the search confirmed the local registration: its residual is the usual one now (the
  // scene around the foot changes slowly: light, the robot's own parts)
  const bool confirmed = local.ok && cv::norm(shift - local_shift) < kGroundConfirmPx;
  ground_residual = ground_residual >= 0 && !confirmed
                        ? 0.9 * ground_residual + 0.1 * fine.residual_rms
                        : fine.residual_rms;
  return shift;
}

void FootTracker::Impl::SampleStrips(const cv::Mat& bgr) {
  if (strip_span_px.empty()) {
    strip_span_px = StripRegion(work_px, frame_size);
    const cv::Rect& span = strip_span_px;
    for (int x = span.x + kStripStepPx / 2; x < span.x + span.width; x += kStripStepPx) {
      if (x < work_px.x - kStripStepPx || x >= work_px.x + work_px.width + kStripStepPx) {
        strip_columns.push_back(x);
      }
    }
    if (strip_columns.size() < kStripMinColumns) strip_columns.clear();
    span_reference = cv::Mat::zeros(strip_span_px.size(), CV_32F);
  }
  // nothing to measure: no columns, or a clip found not banded
  if (strip_columns.empty() || (banded && !*banded)) return;
  if (!initialised) {  // a template frame: its whole span
    for (int y = 0; y < strip_span_px.height; ++y) {
      const uint8_t* pixel = bgr.ptr<uint8_t>(strip_span_px.y + y) + 3 * strip_span_px.x;
      float* out = span_reference.ptr<float>(y);
      for (int x = 0; x < strip_span_px.width; ++x, pixel += 3) out[x] += MeanGrey(pixel);
    }
  }
  strips.create(work_px.height, static_cast<int>(strip_columns.size()), CV_32F);
  for (int y = 0; y < work_px.height; ++y) {
    const uint8_t* row = bgr.ptr<uint8_t>(work_px.y + y);
    float* out = strips.ptr<float>(y);
    for (size_t s = 0; s < strip_columns.size(); ++s) out[s] = MeanGrey(row + 3 * strip_columns[s]);
  }
}

void FootTracker::Impl::LevelToTheTemplates(const cv::Point2d& shift) {
  if (strip_columns.empty() || (banded && !*banded)) return;
  // the templates' pixels where this frame's are now (a shaken camera moves them)
  const auto moved_x = static_cast<int>(std::lround(shift.x / scale));
  const auto moved_y = static_cast<int>(std::lround(shift.y / scale));
  aligned_reference.create(strips.size(), CV_32F);
  for (int y = 0; y < strips.rows; ++y) {
    const float* from = span_reference.ptr<float>(std::clamp(y - moved_y, 0, strips.rows - 1));
    float* out = aligned_reference.ptr<float>(y);
    for (size_t s = 0; s < strip_columns.size(); ++s) {
      const int x =
          std::clamp(strip_columns[s] - moved_x - strip_span_px.x, 0, strip_span_px.width - 1);
      out[s] = from[x];
    }
  }
  const std::vector<float> frame_gains =
      internal::RowGains(strips, aligned_reference, kLevelSmoothRows, kLevelMinGrey);
  if (frame_gains.empty()) return;
  // the work image's rows: the frame row each shows
  std::vector<float> gains(static_cast<size_t>(work.rows));
  for (int y = 0; y < work.rows; ++y) {
    const auto row = static_cast<int>(std::lround((y + 0.5) / scale - 0.5));
    gains[static_cast<size_t>(y)] =
        frame_gains[static_cast<size_t>(std::clamp(row, 0, work_px.height - 1))];
  }
  const float range = internal::GainRange(gains);
  if (!banded) {
    level_ranges.push_back(range);
    if (level_ranges.size() >= kLevelDecideFrames) {
      banded = MedianOf(level_ranges) > kLevelMinRange;
    }
  }
  const bool usable = *std::min_element(gains.begin(), gains.end()) >= kMinLevelGain;
  if (usable && (banded ? *banded : range > kLevelMinRange)) internal::LevelRows(work, gains);
}

void FootTracker::Impl::MeasurePatches(const cv::Point2d& shift) {
  // each patch starts from where it was, moved as much as the ground moved since the last
  // frame
  const cv::Point2d moved = shift - global_shift_px;
  global_shift_px = shift;
  for (TrackedPatch& patch : patches) {
    float rise = kNaN;
    if (!patch.lost) {
      const PatchMatch match =
          internal::RegisterPatch(patch.templ, work, patch.position_px + moved);
      const double limit =
          patch.typical_residual > 0 ? kResidualFactor * patch.typical_residual + kResidualFloor
                                     : std::numeric_limits<double>::infinity();
      const cv::Point2d step = match.origin_px - patch.position_px;
      const bool jumped = std::abs(step.y) > kPatchPx / 2.0 + std::abs(moved.y) ||
                          std::abs(step.x) > kPatchPx / 2.0 + std::abs(moved.x);
      if (match.ok && !jumped && match.residual_rms <= limit && std::abs(match.gain) < kMaxGain) {
        patch.position_px = match.origin_px;
        patch.typical_residual = patch.typical_residual > 0
                                     ? 0.9 * patch.typical_residual + 0.1 * match.residual_rms
                                     : match.residual_rms;
        patch.misses = 0;
        rise = static_cast<float>((patch.templ.origin_px.y - match.origin_px.y) / scale);
      } else if (++patch.misses >= kLostFrames) {
        patch.lost = true;
      }
    }
    rises.push_back(rise);
  }
}

FootTracker::FootTracker(const Options& options) : impl_(std::make_unique<Impl>()) {
  impl_->options = options;
  impl_->options_status = options.Validate();
  impl_->rest_from_ns = options.rest_from_ns;
  impl_->rest_to_ns = options.rest_to_ns;
}

FootTracker::FootTracker(FootTracker&&) noexcept = default;
FootTracker& FootTracker::operator=(FootTracker&&) noexcept = default;
FootTracker::~FootTracker() = default;

const std::vector<HeightSample>& FootTracker::samples() const { return impl_->samples; }

cv::Rect FootTracker::RegionRead(cv::Size frame_px) const {
  return StripRegion(WorkRegion(impl_->options.foot_roi_px, frame_px), frame_px);
}

void FootTracker::SetRestWindow(int64_t rest_from_ns, int64_t rest_to_ns) {
  impl_->rest_from_ns = rest_from_ns;
  impl_->rest_to_ns = rest_to_ns;
}

Status FootTracker::Process(const Frame& frame) {
  Impl& s = *impl_;
  if (!s.options_status.ok()) return s.options_status;
  const cv::Mat& bgr = frame.bgr;
  if (bgr.empty() || bgr.type() != CV_8UC3) {
    return InvalidArgumentError("frame " + std::to_string(frame.index) +
                                ": expected a BGR 8-bit picture");
  }
  const cv::Rect image(0, 0, bgr.cols, bgr.rows);
  const std::string size_text = std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows);
  if (!s.size_known) {
    const cv::Rect& roi = s.options.foot_roi_px;
    if ((roi & image) != roi) {
      return InvalidArgumentError("foot ROI " + RectText(roi) + " is outside the " + size_text +
                                  " frame");
    }
    s.frame_size = bgr.size();
    s.size_known = true;
    s.ChooseWorkRegion(s.frame_size);
  } else {
    if (bgr.size() != s.frame_size) {
      return InvalidArgumentError("frame " + std::to_string(frame.index) + " is " + size_text +
                                  ", the first was " + std::to_string(s.frame_size.width) + "x" +
                                  std::to_string(s.frame_size.height));
    }
    if (frame.t_ns <= s.last_t_ns) {
      return InvalidArgumentError("frame " + std::to_string(frame.index) + " at " +
                                  FormatSeconds(frame.t_ns, 4) +
                                  " s is not after the previous one at " +
                                  FormatSeconds(s.last_t_ns, 4) + " s (frames must come in order)");
    }
  }
  try {
    s.MakeWorkImage(bgr);
    s.SampleStrips(bgr);
    if (!s.initialised) s.AccumulateTemplates(bgr);
    if (s.initialised) {
      // levelled first (against the templates moved by the last frame's shift), so that the
      // ground is registered on a levelled picture too
      s.LevelToTheTemplates(s.global_shift_px);
      s.MeasurePatches(s.GroundShift());
    } else {
      s.measured_from = s.samples.size() + 1;
    }
    HeightSample sample;
    sample.frame_index = frame.index;
    sample.t_ns = frame.t_ns;
    sample.keyframe = frame.keyframe;
    s.samples.push_back(sample);
    s.last_t_ns = frame.t_ns;
  } catch (const cv::Exception& e) {
    return InvalidArgumentError("frame " + std::to_string(frame.index) + ": " + e.what());
  }
  return Status::Ok();
}

// ---------------------------------------------------------------------------------------
// finish: which patches are the foot and which the ground, the height curve, the liftoff

namespace {

constexpr double kNaNd = std::numeric_limits<double>::quiet_NaN();

// The patches' rises, frames x patches (rows before `measured_from` were not measured).
class RiseTable {
 public:
  RiseTable(const std::vector<float>& rises, size_t patches, size_t measured_from)
      : rises_(rises), patches_(patches), measured_from_(measured_from) {}
  size_t patches() const { return patches_; }
  double Raw(size_t frame, size_t patch) const {
    if (frame < measured_from_) return kNaNd;
    const size_t at = (frame - measured_from_) * patches_ + patch;
    return at < rises_.size() ? static_cast<double>(rises_[at]) : kNaNd;
  }

 private:
  const std::vector<float>& rises_;
  size_t patches_, measured_from_;
};

// Median of the last `count` finite values of value(f) over frames [first, frames).
template <typename Value>
double FinalLevel(size_t first, size_t frames, size_t count, const Value& value) {
  std::vector<double> values;
  for (size_t f = frames; f-- > first && values.size() < count;) {
    const double v = value(f);
    if (std::isfinite(v)) values.push_back(v);
  }
  return FiniteMedian(values);
}

// Running median over +-half frames (NaN stays NaN and is skipped).
std::vector<double> RunningMedian(const std::vector<double>& curve, size_t half) {
  std::vector<double> out(curve.size(), kNaNd);
  std::vector<double> window;
  for (size_t i = 0; i < curve.size(); ++i) {
    if (!std::isfinite(curve[i])) continue;
    window.assign(
        curve.begin() + static_cast<std::ptrdiff_t>(i >= half ? i - half : 0),
        curve.begin() + static_cast<std::ptrdiff_t>(std::min(curve.size(), i + half + 1)));
    out[i] = FiniteMedian(window);
  }
  return out;
}

// Frames of `samples` in `seconds` at the clip's median rate (at least 1).
size_t FramesIn(const std::vector<HeightSample>& samples, double seconds) {
  std::vector<double> intervals;
  for (size_t i = 1; i < samples.size(); ++i) {
    intervals.push_back(Seconds(samples[i].t_ns - samples[i - 1].t_ns));
  }
  const double interval = FiniteMedian(intervals);
  if (!(interval > 0)) return 1;
  return std::max<size_t>(1, static_cast<size_t>(std::lround(seconds / interval)));
}

// What the patches say.
struct PatchSelection {
  std::vector<size_t> foot, ground;
  std::vector<double> height_px;  // per frame, up positive, rest 0; NaN where unmeasured
  std::vector<double> shake_px;   // per frame, up positive
  std::vector<double> quality;    // per frame: fraction of the foot's patches measured
  // per frame, the median of the patches highest halfway up the rise when most of them were
  // lost before the end, less the foot's (HalfwayHighest; NaN where fewer than two of them
  // are measured, when there are two or more); empty when none is left
  std::vector<double> lost_rise_px;
  // per foot patch, its curve less the shake (foot order), px
  std::vector<std::vector<double>> foot_curves_px;
};

// Patches still over frames [first, until]: measured in at least half of them, and within
// kGroundTolerancePx of their rest level in every one (the ground template took the
// camera's shake out).
template <typename Value>
std::vector<size_t> StillPatches(const RiseTable& table, size_t first, size_t until,
                                 const Value& from_rest) {
  std::vector<size_t> still;
  for (size_t p = 0; p < table.patches(); ++p) {
    size_t measured = 0;
    bool moved = false;
    for (size_t f = first; f <= until && !moved; ++f) {
      const double v = from_rest(f, p);
      if (!std::isfinite(v)) continue;
      ++measured;
      moved = std::abs(v) > kGroundTolerancePx;
    }
    if (!moved && 2 * measured > until - first + 1) still.push_back(p);
  }
  return still;
}

// Where each of the region's patches ends, relative to the ground: the median of its last
// final_count measured frames. A rising patch lost more than kStaleFinals final windows
// before the last rising one to be lost says nothing of the end (a leg moved by the bend
// and lost seconds before the liftoff: re-drawn hard3d-07, --seed 3000) and is left out.
template <typename Value>
std::vector<std::pair<double, size_t>> FinalRises(const std::vector<size_t>& region, size_t first,
                                                  size_t frames, size_t final_count,
                                                  const Value& relative) {
  std::vector<std::pair<double, size_t>> finals;
  std::vector<size_t> last_seen;
  size_t latest_rising = 0;
  for (size_t p : region) {
    size_t last = frames;
    while (last > first && !std::isfinite(relative(last - 1, p))) --last;
    const double final_rise =
        FinalLevel(first, last, final_count, [&](size_t f) { return relative(f, p); });
    if (!std::isfinite(final_rise)) continue;
    finals.emplace_back(final_rise, p);
    last_seen.push_back(last);
    if (final_rise > kGroundTolerancePx) latest_rising = std::max(latest_rising, last);
  }
  std::vector<std::pair<double, size_t>> kept;
  for (size_t i = 0; i < finals.size(); ++i) {
    const bool stale = finals[i].first > kGroundTolerancePx &&
                       last_seen[i] + kStaleFinals * final_count < latest_rising;
    if (!stale) kept.push_back(finals[i]);
  }
  return kept;
}

// The rising patches highest halfway up: at the first frame where the second highest of
// them (a running median over three frames) reached half of `top`, those within
// kFootFraction of the second highest there; returned when most of them were lost more
// than a final window before the clip's end, else empty. Where patches end says which
// rose; when they were highest says which rose first: a fast lift outruns the registration
// of the foot's own patches, lost low, while a shadow or the other leg, followed to the
// clip's end, ends higher (hard3d-06, a side view at 0.44 px a mm, took its liftoff from a
// shadow 0.24 s late). Choosing the foot by this instead cost ci3d-02 its interval (a leg
// swinging faster than the foot above it), so it only widens a weak foot's interval
// (CheckLostRise).
template <typename Value>
std::vector<size_t> HalfwayHighest(const std::vector<std::pair<double, size_t>>& finals,
                                   size_t first, size_t frames, size_t final_count, double top,
                                   const Value& relative) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  std::vector<size_t> rising;
  for (const auto& [final_rise, p] : finals) {
    if (final_rise > kGroundTolerancePx) rising.push_back(p);
  }
  if (rising.size() < 2) return {};
  const auto second_highest = [&](size_t f) {
    double highest = -kInf, second = -kInf;
    for (size_t p : rising) {
      const double v = relative(f, p);
      if (!std::isfinite(v)) continue;
      second = std::max(second, std::min(highest, v));
      highest = std::max(highest, v);
    }
    return second;
  };
  std::vector<double> envelope(frames, -kInf);
  for (size_t f = first; f < frames; ++f) envelope[f] = second_highest(f);
  size_t halfway = frames;
  for (size_t f = first + 1; f + 1 < frames && halfway == frames; ++f) {
    const double middle =
        std::max(std::min(envelope[f - 1], envelope[f]),
                 std::min(std::max(envelope[f - 1], envelope[f]), envelope[f + 1]));
    if (middle >= 0.5 * top) halfway = f;
  }
  if (halfway == frames) return {};
  std::vector<std::pair<double, size_t>> levels;
  for (size_t p : rising) {
    std::vector<double> around;
    for (size_t f = halfway - 1; f <= halfway + 1; ++f) {
      if (std::isfinite(relative(f, p))) around.push_back(relative(f, p));
    }
    if (!around.empty()) levels.emplace_back(FiniteMedian(around), p);
  }
  if (levels.size() < 2) return {};
  std::sort(levels.rbegin(), levels.rend());
  const double reference = levels[1].first;
  if (!(reference > 0)) return {};  // the rising patches had not risen there
  std::vector<size_t> highest;
  size_t lost = 0;
  for (const auto& [level, p] : levels) {
    if (level < kFootFraction * reference) continue;
    highest.push_back(p);
    size_t last = frames;
    while (last > first && !std::isfinite(relative(last - 1, p))) --last;
    if (last + final_count < frames) ++lost;
  }
  if (2 * lost <= highest.size()) return {};
  return highest;
}

// Each patch's median over the rest frames; NaN where it was measured in under half of them.
std::vector<double> RestLevels(const RiseTable& table, const std::vector<size_t>& rest) {
  std::vector<double> rest_level(table.patches(), kNaNd);
  for (size_t p = 0; p < table.patches(); ++p) {
    std::vector<double> values;
    for (size_t f : rest) values.push_back(table.Raw(f, p));
    const double level = FiniteMedian(values);
    if (values.size() * 2 >= rest.size()) rest_level[p] = level;
  }
  return rest_level;
}

// The foot's candidates: patches, and the level they are judged against, px.
struct FootCandidates {
  std::vector<size_t> patches;
  double top_px = 0.0;
};

// The foot's candidates among the region's (final rise, patch) pairs `finals`: the rising
// patches that did not rest with the others before are dropped from `finals`, which is then
// sorted highest first; the candidates end within kFootFraction of the second highest final
// (none when no final is left).
template <typename Relative>
FootCandidates ChooseFootCandidates(std::vector<std::pair<double, size_t>>& finals, size_t first,
                                    size_t frames, const Relative& relative) {
  std::vector<size_t> rising;
  for (const auto& [final_rise, p] : finals) {
    if (final_rise > kGroundTolerancePx) rising.push_back(p);
  }
  const std::vector<size_t> resting = RestingWithTheOthers(rising, first, frames, relative);
  std::erase_if(finals, [&](const std::pair<double, size_t>& f) {
    return f.first > kGroundTolerancePx &&
           std::find(resting.begin(), resting.end(), f.second) == resting.end();
  });
  std::sort(finals.rbegin(), finals.rend());
  FootCandidates candidates;
  if (finals.empty()) return candidates;
  candidates.top_px = finals[std::min<size_t>(1, finals.size() - 1)].first;
  for (const auto& [final_rise, p] : finals) {
    if (final_rise >= kFootFraction * candidates.top_px && final_rise > kGroundTolerancePx) {
      candidates.patches.push_back(p);
    }
  }
  return candidates;
}

// Per frame, the share of `patches` measured (0 for none).
std::vector<double> MeasuredShare(const RiseTable& table, const std::vector<size_t>& patches,
                                  size_t frames) {
  std::vector<double> share(frames, 0.0);
  if (patches.empty()) return share;
  for (size_t f = 0; f < frames; ++f) {
    size_t measured = 0;
    for (size_t p : patches) measured += std::isfinite(table.Raw(f, p)) ? 1u : 0u;
    share[f] = static_cast<double>(measured) / static_cast<double>(patches.size());
  }
  return share;
}

// Rest levels, the ground (patches that end where they began: their median is the shake),
// the foot (patches of the region that end highest, less those that do not move with
// the others) and its height: the median of the foot's patches less the shake.
PatchSelection SelectPatches(const RiseTable& table, const std::vector<TrackedPatch>& patches,
                             const std::vector<size_t>& rest, size_t frames, size_t final_count,
                             size_t still_until) {
  PatchSelection selection;
  const size_t first = rest.front();
  const std::vector<double> rest_level = RestLevels(table, rest);
  const auto from_rest = [&](size_t f, size_t p) { return table.Raw(f, p) - rest_level[p]; };
  std::vector<size_t> margin, region;
  for (size_t p = 0; p < table.patches(); ++p) {
    if (std::isfinite(rest_level[p])) (patches[p].in_region ? region : margin).push_back(p);
  }
  const auto finite_or_zero = [](double v) { return std::isfinite(v) ? v : 0.0; };

  // ground and shake: a first shake from the margin, then the patches that end at rest;
  // or, when asked, the patches still all along up to frame still_until
  if (still_until > first) {
    selection.ground = StillPatches(table, first, still_until, from_rest);
  } else {
    const std::vector<double> margin_shake = MedianCurve(frames, margin, 1, from_rest);
    for (size_t p = 0; p < table.patches(); ++p) {
      if (!std::isfinite(rest_level[p])) continue;
      const double final_rise = FinalLevel(first, frames, final_count, [&](size_t f) {
        return from_rest(f, p) - finite_or_zero(margin_shake[f]);
      });
      if (std::abs(final_rise) <= kGroundTolerancePx) selection.ground.push_back(p);
    }
  }
  selection.shake_px = MedianCurve(frames, selection.ground, 1, from_rest);
  for (double& v : selection.shake_px) v = finite_or_zero(v);
  const auto relative = [&](size_t f, size_t p) { return from_rest(f, p) - selection.shake_px[f]; };

  // the foot: the region's patches that end highest ...
  std::vector<std::pair<double, size_t>> finals = FinalRises(region, first, frames, final_count,
                                                             relative);
  const FootCandidates candidates = ChooseFootCandidates(finals, first, frames, relative);
  if (finals.empty()) return selection;
  // ... and move with the others, all the way
  selection.foot = MovingWithTheOthers(candidates.patches, first, frames, relative);
  const size_t needed = std::max<size_t>(1, (selection.foot.size() * 3 + 9) / 10);
  selection.height_px = MedianCurve(frames, selection.foot, needed, relative);
  for (size_t p : selection.foot) {
    std::vector<double>& curve = selection.foot_curves_px.emplace_back(frames);
    for (size_t f = 0; f < frames; ++f) curve[f] = relative(f, p);
  }
  std::vector<size_t> halfway =
      HalfwayHighest(finals, first, frames, final_count, candidates.top_px, relative);
  std::erase_if(halfway, [&](size_t p) {
    return std::find(selection.foot.begin(), selection.foot.end(), p) != selection.foot.end();
  });
  if (!halfway.empty()) {
    selection.lost_rise_px =
        MedianCurve(frames, halfway, std::min<size_t>(2, halfway.size()), relative);
  }
  selection.quality = MeasuredShare(table, selection.foot, frames);
  return selection;
}

// The liftoff in the height curve: where the curve rises for good, the stretch of rest
// before it, and the model fitted over both.
struct LiftoffSearch {
  internal::RiseFit fit;
  double lag_bound_px = 0;             // a codec's lag allowed for, px (0: none)
  size_t fit_first = 0, fit_last = 0;  // frames fitted
  double max_rise_px = 0;              // of the smoothed curve
  double still_noise_px = 0;           // the rest window's noise, or its key frames' if larger
  std::vector<double> smooth_px;       // the height's running median (kSmoothHalfS either side)
  std::string not_found;               // why there is no liftoff, when there is none
};

// The first sample at or after t_ns (the last one when none is).
size_t FrameAtOrAfter(const std::vector<HeightSample>& samples, int64_t t_ns) {
  const auto at = std::lower_bound(samples.begin(), samples.end(), t_ns,
                                   [](const HeightSample& s, int64_t t) { return s.t_ns < t; });
  return at == samples.end() ? samples.size() - 1 : static_cast<size_t>(at - samples.begin());
}

// The still foot's noise, px: the rest window's, or its key frames' before the model's
// knee when larger (internal::KeyframeNoisePx).
double StillNoisePx(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                    size_t first, double rest_noise_px, const internal::RiseFit& fit) {
  const size_t knee = FrameAtOrAfter(samples, RoundNs(fit.knee_low_s * 1e9));
  return std::max(rest_noise_px, internal::KeyframeNoisePx(samples, height, first, knee));
}

// A codec's lag holds the curve back, never ahead: the foot was above the threshold once
// the curve stood kSurelyAboveSigmas of the still noise above it for three frames in a
// row (internal::SurelyAboveS), however the model's acceptable knees ended (a key frame's
// offset can pull them all early: re-drawn hard3d-07, --seed 4000, 0.47 px per mm, where
// the truth came 15 ms after them). Widens the fit's crossing interval to that instant,
// moving its middle.
void BoundByTheCurve(const std::vector<HeightSample>& samples, const std::vector<double>& height,
                     double threshold_px, LiftoffSearch& search) {
  internal::RiseFit& fit = search.fit;
  const double above_s =
      internal::SurelyAboveS(samples, height, search.fit_first, search.fit_last,
                             fit.level + threshold_px, kSurelyAboveSigmas * search.still_noise_px);
  if (!(above_s > fit.crossing_high_s)) return;
  fit.crossing_high_s = above_s;
  fit.crossing_middle_s = 0.5 * (fit.crossing_low_s + fit.crossing_high_s);
}

// A key frame among frames (f - half, f + half + 1], the latest; 0 for none.
size_t KeyframeNear(const std::vector<HeightSample>& samples, size_t f, size_t half) {
  const size_t last = std::min(samples.size() - 1, f + half + 1);
  for (size_t g = last; g > f - std::min(f, half) && g > 0; --g) {
    if (samples[g].keyframe) return g;
  }
  return 0;
}

// The rise for good: the first frame from which the smoothed curve stays above the
// threshold for kSustainS (or to the clip's end, if that is at least kSustainFrames frames
// and two thresholds up); the cut: where it then reaches the fit's top. smooth.size() when
// there is none.
size_t FindCut(const std::vector<HeightSample>& samples, const std::vector<double>& smooth,
               size_t first, double threshold_px, bool lossy) {
  const size_t sustain = std::max<size_t>(kSustainFrames, FramesIn(samples, kSustainS));
  size_t rise = smooth.size();
  for (size_t f = first; f < smooth.size() && rise == smooth.size(); ++f) {
    if (!(smooth[f] >= threshold_px)) continue;
    size_t above = 0, g = f;
    double highest = smooth[f];
    for (; g < smooth.size() && above < sustain; ++g) {
      if (!std::isfinite(smooth[g])) continue;
      if (smooth[g] < threshold_px) break;
      highest = std::max(highest, smooth[g]);
      ++above;
    }
    const bool to_the_end = g == smooth.size() && above >= kSustainFrames &&
                            highest >= 2 * threshold_px;
    if (above >= sustain || to_the_end) rise = f;
  }
  if (rise == smooth.size()) return rise;
  double highest = 0;
  for (size_t f = rise; f < smooth.size(); ++f) {
    if (std::isfinite(smooth[f])) highest = std::max(highest, smooth[f]);
  }
  const double top =
      std::min(lossy ? std::max(kFitTopThresholdsLossy * threshold_px, kFitTopPxLossy)
                     : std::max(kFitTopThresholdsLossless * threshold_px, kFitTopPxLossless),
               0.8 * highest);
  for (size_t f = rise; f < smooth.size(); ++f) {
    if (smooth[f] >= top) return f;
  }
  return smooth.size();
}

// Back from the cut: the climb, then up to kFitRestS of rest (a step in it ends the rest,
// but for a key frame's: a codec's new picture quality, not a motion, so the frames before
// it are levelled with those after, in `levelled`). Returns the first frame of the stretch.
size_t FindRestStart(const std::vector<HeightSample>& samples, const std::vector<double>& smooth,
                     size_t first, size_t cut, double threshold_px, double rest_noise_px,
                     bool lossy, std::vector<double>& levelled) {
  const double tolerance = std::max(3 * rest_noise_px, 0.3 * threshold_px);
  const size_t half = FramesIn(samples, kSmoothHalfS);
  std::vector<double> levelled_smooth = smooth;
  size_t flat_since = cut, start = cut;
  double anchor = smooth[cut];
  bool resting = false;
  size_t levelled_at = 0;  // the last key frame levelled at (its smoothed neighbours are mixed)
  for (size_t f = cut; f-- > first;) {
    if (!std::isfinite(levelled_smooth[f])) continue;
    if (levelled_at > 0 && f + half >= levelled_at) {
      start = f;
      continue;
    }
    // at rest, a wander within the threshold is noise for the robust fit, not a step
    const double allowed = resting ? std::max(tolerance, threshold_px) : tolerance;
    const bool below = levelled_smooth[f] < anchor - allowed;
    // climbing, the curve may wobble back up (patches lost and found in a fast rise): only
    // a level above the cut's is another, earlier rise
    const bool above = levelled_smooth[f] > anchor + allowed &&
                       (resting || levelled_smooth[f] > smooth[cut]);
    if ((below && resting) || above) {
      const size_t key = lossy && resting ? KeyframeNear(samples, f, half) : 0;
      if (key == 0) break;
      const double step = internal::LevelStep(levelled, key, 2 * half + 1);
      // a key frame that undoes its predicted frames' drift: levelling would leave the drift
      // as a rise into the rest, so the rest begins at it (when that leaves enough; a key
      // frame levelled already has no step left to judge)
      if (key != levelled_at &&
          internal::ResetsADrift(samples, levelled_smooth, key, step, 2 * half + 1) &&
          Seconds(samples[cut].t_ns - samples[key].t_ns) >= kRestAfterResetS) {
        start = std::max(start, key);
        break;
      }
      for (size_t g = first; g < key; ++g) {
        levelled[g] += step;
        levelled_smooth[g] += step;
      }
      levelled_at = key;
      start = f;
      continue;
    }
    if (below) {
      anchor = levelled_smooth[f];
      flat_since = f;
    }
    start = f;
    const double flat_s = Seconds(samples[flat_since].t_ns - samples[f].t_ns);
    if (flat_s >= kRestingS) resting = true;
    if (flat_s >= kFitRestS) break;
  }
  return start;
}

// Why the foot never lifts, or "" when it may have: no rise held above the threshold
// (`no_cut`), or, through a lossy codec, none that got kMinLiftThresholds up.
std::string NeverLifts(bool no_cut, double max_rise_px, double threshold_px, bool lossy) {
  const std::string largest =
      "the foot never lifts: its largest rise is " + FormatFixed(max_rise_px, 2) + " px above rest";
  if (no_cut) {
    return largest + ", below the " + FormatFixed(threshold_px, 2) + " px threshold held for " +
           FormatFixed(kSustainS, 1) + " s";
  }
  const double min_lift_px = std::max(kMinLiftThresholds * threshold_px, kMinLiftPxLossy);
  if (lossy && max_rise_px < min_lift_px) {
    return largest + ", under " + FormatFixed(min_lift_px, 2) + " px (" +
           FormatFixed(kMinLiftThresholds, 0) + " times the " + FormatFixed(threshold_px, 2) +
           " px threshold, at least " + FormatFixed(kMinLiftPxLossy, 0) +
           " px: a lift goes on rising)";
  }
  return "";
}

LiftoffSearch FindLiftoff(const std::vector<HeightSample>& samples,
                          const std::vector<double>& height, size_t first, double threshold_px,
                          double rest_noise_px, bool lossy) {
  LiftoffSearch search;
  const size_t smooth_half = FramesIn(samples, kSmoothHalfS);
  search.smooth_px = RunningMedian(height, smooth_half);
  const std::vector<double>& smooth = search.smooth_px;
  for (size_t f = first; f < smooth.size(); ++f) {
    if (std::isfinite(smooth[f])) search.max_rise_px = std::max(search.max_rise_px, smooth[f]);
  }
  const size_t cut = FindCut(samples, smooth, first, threshold_px, lossy);
  search.not_found = NeverLifts(cut == smooth.size(), search.max_rise_px, threshold_px, lossy);
  if (!search.not_found.empty()) return search;
  const size_t cut_with_key =
      lossy ? internal::ReachKeyframe(samples, height, smooth, cut, smooth_half, threshold_px,
                                      kKeyframeReachS, kKeyframeReachTops)
            : 0;
  std::vector<double> levelled = height;
  const size_t start = FindRestStart(samples, smooth, first, cut, threshold_px, rest_noise_px,
                                     lossy, levelled);
  if (lossy) {
    internal::LevelQuietKeyframes(samples, start, cut,
                                  std::max(kQuietFrames, FramesIn(samples, kQuietS)),
                                  kQuietThresholds * threshold_px, levelled);
  }
  // the model over the stretch (raw heights: the fit is robust to single frames)
  // a lossy codec may hold slow motion back: a predicted frame until the picture is renewed,
  // an intra-only codec (MJPEG) by quantising an edge's sub-pixel position; a key frame
  // among predicted ones renews the picture
  const bool predicted = std::any_of(samples.begin(), samples.end(),
                                     [](const HeightSample& sample) { return !sample.keyframe; });
  std::vector<double> t_s, h;
  std::vector<bool> lag_free;
  for (size_t f = start; f <= std::max(cut, cut_with_key); ++f) {
    if (!std::isfinite(levelled[f])) continue;
    t_s.push_back(Seconds(samples[f].t_ns - samples[start].t_ns));
    h.push_back(levelled[f]);
    lag_free.push_back(!lossy || (predicted && samples[f].keyframe));
  }
  internal::RiseFitOptions fit_options;
  fit_options.threshold = threshold_px;
  const bool may_lag = std::find(lag_free.begin(), lag_free.end(), false) != lag_free.end();
  if (may_lag) {
    // the catch-ups up to the fit's top, and the key frame's (higher up, where a fast rise
    // is tracked less well, other jumps are no codec's)
    // (a catch-up must stand out of the still foot's frame-to-frame noise; the key frame's
    // own, below, renews the picture: no noise)
    fit_options.lag_bound =
        internal::LagBoundPx(height, start, cut, kMinLagPx, kLagBoundFactor,
                             kCatchUpNoiseSigmas * std::sqrt(2.0) * rest_noise_px);
    if (cut_with_key > cut && cut_with_key + 1 < height.size()) {
      fit_options.lag_bound = std::max(
          fit_options.lag_bound, internal::LagBoundPx(height, cut_with_key - 2, cut_with_key + 1,
                                                      kMinLagPx, kLagBoundFactor));
    }
    fit_options.lag_weight = kLagWeight;
  }
  search.lag_bound_px = fit_options.lag_bound;
  search.fit = internal::FitRise(t_s, h, lag_free, fit_options);
  const double origin_s = Seconds(samples[start].t_ns);
  if (search.fit.ok) {
    for (double* t : {&search.fit.knee_s, &search.fit.knee_low_s, &search.fit.knee_high_s,
                      &search.fit.crossing_s, &search.fit.crossing_low_s,
                      &search.fit.crossing_high_s, &search.fit.crossing_middle_s}) {
      *t += origin_s;
    }
  } else {
    search.not_found = "the foot's rise could not be fitted between " +
                       FormatSeconds(samples[start].t_ns, 3) + " and " +
                       FormatSeconds(samples[cut].t_ns, 3) + " s";
  }
  search.fit_first = start;
  search.fit_last = std::max(cut, cut_with_key);
  if (!search.fit.ok) return search;
  search.still_noise_px = StillNoisePx(samples, height, first, rest_noise_px, search.fit);
  if (search.lag_bound_px > 0) BoundByTheCurve(samples, height, threshold_px, search);
  return search;
}

// The frames either side of t_ns and the instant with its uncertainty.
TimedEvent MakeEvent(const std::vector<HeightSample>& samples, double t_s, double uncertainty_s) {
  TimedEvent event;
  event.t_ns = RoundNs(t_s * 1e9);
  event.uncertainty_ns = RoundNs(uncertainty_s * 1e9);
  size_t after = 0;
  while (after < samples.size() && samples[after].t_ns < event.t_ns) ++after;
  after = std::min(after, samples.size() - 1);
  event.frame_after = samples[after].frame_index;
  event.frame_before = samples[after > 0 ? after - 1 : 0].frame_index;
  return event;
}

std::string PatchCount(size_t count) {
  return std::to_string(count) + (count == 1 ? " patch" : " patches");
}

// The liftoff instant's half-width, s, in quadrature: the spread of the acceptable knees'
// crossings, a codec's lag (up to the bound allowed for, at least compression_error_px),
// the registration's own error, the still foot's noise (the rest window's, or its key
// frames' when larger: internal::KeyframeNoisePx), the ground's drift and, with an estimated
// scale, 3 % of the threshold, each over the model's rise rate at the crossing.
double LiftoffUncertaintyS(const FootTrack& track, const LiftoffSearch& search,
                           double crossing_s, double compression_error_px,
                           double ground_drift_px) {
  const internal::RiseFit& fit = search.fit;
  const double fit_spread =
      std::max(crossing_s - fit.crossing_low_s, fit.crossing_high_s - crossing_s);
  const double rate = std::max(fit.rate_at_crossing, 1e-9);
  const double lag_px = search.lag_bound_px > 0
                            ? std::max(compression_error_px, search.lag_bound_px)
                            : compression_error_px;
  const double scale_px =
      track.px_per_mm_estimated ? kEstimatedScaleFraction * track.threshold_px : 0.0;
  const double px = std::sqrt(lag_px * lag_px + scale_px * scale_px +
                              kRegistrationErrorPx * kRegistrationErrorPx +
                              track.still_noise_px * track.still_noise_px +
                              ground_drift_px * ground_drift_px);
  return std::hypot(fit_spread, px / rate);
}

// Warnings where the evidence is weak; low_confidence when any is.
// (`few_patches_reach`: what a foot seen by few patches did to the interval, or "")
void AddConfidenceWarnings(FootTrack& track, const PatchSelection& selection,
                           const internal::RiseFit& fit, double uncertainty_s,
                           const std::string& few_patches_reach) {
  std::vector<std::string> weak;
  if (selection.foot.size() < kFewFootPatches) {
    weak.push_back("only " + PatchCount(selection.foot.size()) + " moved with the foot" +
                   (few_patches_reach.empty() ? "" : ": " + few_patches_reach));
  }
  if (fit.noise > kNoisyFraction * track.threshold_px) {
    weak.push_back("the height curve is noisy (" + FormatFixed(fit.noise, 2) +
                   " px rms against a " + FormatFixed(track.threshold_px, 2) + " px threshold)");
  }
  if (uncertainty_s > kWideUncertaintyS) {
    weak.push_back("the instant is uncertain by +- " + FormatFixed(uncertainty_s * 1e3, 0) + " ms");
  }
  if (track.max_rise_px < kShortRiseThresholds * track.threshold_px) {
    weak.push_back("the clip ends " + FormatFixed(track.max_rise_px / track.threshold_px, 1) +
                   " thresholds up");
  }
  for (const std::string& reason : weak) {
    track.warnings.push_back("low confidence: " + reason);
  }
  track.low_confidence = !weak.empty();
  if (selection.ground.size() < kFewGroundPatches) {
    track.warnings.push_back("only " +
                             PatchCount(selection.ground.size()) +
                             " of static ground around the foot: camera shake is removed poorly");
  }
}

// Whether the mean colour of the foot's patches leans towards the tape's hue.
bool ShowsTapeColour(const std::vector<TrackedPatch>& patches, const std::vector<size_t>& foot,
                     Foot tape) {
  cv::Vec3d sum(0, 0, 0);
  double count = 0;
  for (size_t p : foot) {
    const std::vector<float>& values = patches[p].templ.values;
    for (size_t i = 0; i + 2 < values.size(); i += 3) {
      sum += cv::Vec3d(values[i], values[i + 1], values[i + 2]);
      ++count;
    }
  }
  if (count == 0) return false;
  const cv::Vec3d mean = sum / count;
  const auto chroma = [](const cv::Vec3d& bgr) {
    const double grey = (bgr[0] + bgr[1] + bgr[2]) / 3;
    return bgr - cv::Vec3d(grey, grey, grey);
  };
  // the given tape's hue must be the nearest of the four, and near
  const auto similarity = [&](Foot candidate) {
    const std::array<double, 3> tape_bgr = FootTapeBgr(candidate);
    const cv::Vec3d a = chroma(mean), b = chroma(cv::Vec3d(tape_bgr[0], tape_bgr[1], tape_bgr[2]));
    const double norms = cv::norm(a) * cv::norm(b);
    return norms > 0 ? a.dot(b) / norms : -1.0;
  };
  const double given = similarity(tape);
  for (Foot other : kAllFeet) {
    if (other != tape && similarity(other) >= given) return false;
  }
  return given > 0.5;
}

}  // namespace

// The ground's and the foot's patches in frame px (at rest) into `track`; the foot's box:
// its patches' centres, a quarter patch beyond (a patch on the foot's edge is centred near
// it).
cv::Rect2d FootTracker::Impl::PlacePatches(const PatchSelection& selection,
                                           FootTrack& track) const {
  const auto frame_rect = [&](const PatchTemplate& templ) {
    return cv::Rect(static_cast<int>(std::lround(work_px.x + templ.origin_px.x / scale)),
                    static_cast<int>(std::lround(work_px.y + templ.origin_px.y / scale)),
                    static_cast<int>(std::lround(kPatchPx / scale)),
                    static_cast<int>(std::lround(kPatchPx / scale)));
  };
  for (size_t p : selection.ground) {
    track.reference_patches_px.push_back(frame_rect(patches[p].templ));
    track.reference_roi_px |= track.reference_patches_px.back();
  }
  cv::Rect2d foot_box;
  const double quarter_px = 0.25 * kPatchPx / scale;
  for (size_t p : selection.foot) {
    const cv::Rect rect = frame_rect(patches[p].templ);
    track.foot_patches_px.push_back(rect);
    const cv::Point2d centre(rect.x + 0.5 * (rect.width - 1), rect.y + 0.5 * (rect.height - 1));
    const cv::Rect2d around(centre.x - quarter_px, centre.y - quarter_px, 2 * quarter_px,
                            2 * quarter_px);
    foot_box = foot_box.area() > 0 ? (foot_box | around) : around;
  }
  return foot_box;
}

Result<FootTrack> FootTracker::Finish() const& { return FinishWith(impl_->samples); }

Result<FootTrack> FootTracker::Finish() && { return FinishWith(std::move(impl_->samples)); }

namespace {

// The rest window's frames among those measured from `first`: inside [from, to) when it is
// set, else the first `rest_frames`.
std::vector<size_t> RestFrames(const std::vector<HeightSample>& samples, size_t first,
                               int64_t from_ns, int64_t to_ns, int rest_frames) {
  std::vector<size_t> rest;
  for (size_t f = first; f < samples.size(); ++f) {
    const int64_t t = samples[f].t_ns;
    const bool inside = to_ns > from_ns ? (t >= from_ns && t < to_ns)
                                        : f < first + static_cast<size_t>(rest_frames);
    if (inside) rest.push_back(f);
  }
  return rest;
}

// The scale and the threshold: given, or the scale from the tracked foot's width.
void SetScale(const FootTracker::Options& o, double foot_width_px, FootTrack& track) {
  if (o.threshold_px) {
    track.threshold_px = *o.threshold_px;
    track.px_per_mm = o.px_per_mm;
    return;
  }
  track.px_per_mm = o.px_per_mm > 0 ? o.px_per_mm : foot_width_px / o.foot_width_mm;
  track.px_per_mm_estimated = !(o.px_per_mm > 0);
  track.threshold_px = o.threshold_mm * track.px_per_mm;
  if (track.px_per_mm_estimated) {
    track.warnings.push_back("scale estimated from the tracked foot's width (" +
                             FormatFixed(foot_width_px, 0) + " px taken as " +
                             FormatFixed(o.foot_width_mm, 0) +
                             " mm); give px_per_mm for a known scale");
  }
}

// Each sample's rise (held over frames not measured), shake and quality; the rest's noise.
void FillSamples(const PatchSelection& selection, const std::vector<size_t>& rest,
                 double min_quality, std::vector<HeightSample>& samples, FootTrack& track) {
  double held = 0;
  for (size_t f = 0; f < samples.size(); ++f) {
    HeightSample& sample = samples[f];
    const double h = selection.height_px[f];
    if (std::isfinite(h)) held = h;
    sample.rise_px = held;
    sample.shake_y_px = -selection.shake_px[f];
    sample.quality = std::isfinite(h) ? selection.quality[f] : 0.0;
    if (!std::isfinite(h) || sample.quality < min_quality) ++track.poor_frames;
  }
  std::vector<double> rest_heights;
  for (size_t f : rest) rest_heights.push_back(selection.height_px[f]);
  track.rest_rise_px = 0;
  track.rest_noise_px = MadSigma(rest_heights);
}

// The model's crossing checked against the curve's own (internal::CheckCrossing). Returns
// why it was replaced, or "" when the model held.
std::string CheckAgainstTheCurve(const std::vector<HeightSample>& samples,
                                 const std::vector<double>& height, const LiftoffSearch& search,
                                 const FootTrack& track, double& crossing_s,
                                 double& uncertainty_s) {
  const internal::CurveCheck check =
      internal::CheckCrossing(samples, height, search.fit_first, search.fit_last,
                              search.fit.level + track.threshold_px, crossing_s, uncertainty_s);
  if (!check.disagreed) return "";
  const std::string why = "the rise model crossed the threshold at " +
                          FormatFixed(crossing_s, 3) + " s, after the curve itself (" +
                          FormatFixed(check.crossing_s, 3) + " s): the curve's crossing is taken";
  crossing_s = check.crossing_s;
  uncertainty_s = check.uncertainty_s;
  return why;
}

// A foot does not sink into the ground: a curve whose running median goes below the rest
// level by more than kSunkThresholds thresholds before its rise measures more than the foot (a leg
// tilting as the robot starts to tip, a shadow on the foot's patches). The liftoff is then only
// known to lie between its running median's last frame within a threshold of rest and the crossing
// with its own uncertainty (internal::SunkCrossing): the instant moves to the middle of
// that interval. Returns why, or "" when the curve did not sink.
std::string CheckSinking(const std::vector<HeightSample>& samples, const LiftoffSearch& search,
                         const FootTrack& track, double& crossing_s, double& uncertainty_s) {
  size_t at = search.fit_first;
  while (at < search.fit_last && Seconds(samples[at].t_ns) < crossing_s) ++at;
  const double level = track.rest_rise_px, threshold = track.threshold_px;  // the rest window's
  // on the running median, as the rise is found: no few frames decide
  const internal::Sinking sank =
      internal::SankBefore(samples, search.smooth_px, search.fit_first, at, level, threshold,
                           kSunkThresholds * threshold);
  if (!sank.sank) return "";
  const double found_s = crossing_s;
  const internal::Instant between = internal::SunkCrossing(sank.rest_s, found_s, uncertainty_s);
  crossing_s = between.t_s;
  uncertainty_s = between.uncertainty_s;
  return "the height curve sank " + FormatFixed(sank.depth_px / threshold, 1) +
         " thresholds below rest before its rise (a tilting leg or a shadow among the foot's "
         "patches): the liftoff lies between " +
         FormatFixed(sank.rest_s, 3) + " s and the crossing at " + FormatFixed(found_s, 3) +
         " s";
}

// Patches lost during the rise (PatchSelection::lost_rise_px: highest halfway up, most of
// them lost before the end, less the foot's) whose median rose from the fit's level plus
// the threshold or below to above it for three frames in a row, before the crossing's
// interval and at most kLostRiseReachS before it, say the liftoff may be as early as the
// frame before those: the interval is widened down to it (internal::SunkCrossing) and its
// instant moves to the middle. Returns why, or "".
std::string CheckLostRise(const std::vector<HeightSample>& samples, const PatchSelection& selection,
                          const LiftoffSearch& search, const FootTrack& track, double& crossing_s,
                          double& uncertainty_s) {
  const std::vector<double>& lost = selection.lost_rise_px;
  if (lost.empty() || !std::isfinite(crossing_s) || !std::isfinite(uncertainty_s)) return "";
  // a run of three frames above the fit's level plus the threshold that starts, from a
  // frame at or below it, no earlier than kLostRiseReachS before the interval
  const double level = search.fit.level + track.threshold_px;
  const double from_s = crossing_s - uncertainty_s - kLostRiseReachS;
  size_t above = 0, crossed = samples.size();
  for (size_t f = std::max<size_t>(search.fit_first, 1); f < samples.size(); ++f) {
    if (Seconds(samples[f].t_ns) >= crossing_s - uncertainty_s) break;
    above = std::isfinite(lost[f]) && lost[f] > level ? above + 1 : 0;
    if (above != 3) continue;
    const size_t start = f - 2;
    if (start > 0 && Seconds(samples[start].t_ns) >= from_s && std::isfinite(lost[start - 1]) &&
        lost[start - 1] <= level) {
      crossed = start;
      break;
    }
  }
  if (crossed == samples.size()) return "";
  const double early_s = Seconds(samples[crossed - 1].t_ns);
  const double found_s = crossing_s;
  const internal::Instant between = internal::SunkCrossing(early_s, found_s, uncertainty_s);
  crossing_s = between.t_s;
  uncertainty_s = between.uncertainty_s;
  return "patches lost during the rise (a lift faster than their registration) were above "
         "the threshold from " +
         FormatFixed(Seconds(samples[crossed].t_ns), 3) + " s, before the crossing at " +
         FormatFixed(found_s, 3) + " s of the foot's " + std::to_string(selection.foot.size()) +
         " patches: the liftoff lies between " + FormatFixed(early_s, 3) + " s and that crossing";
}

// A foot measured by fewer than kFewFootPatches patches may be measured short: a small foot's
// patches that hold some still ground or its contact shadow follow a fraction of its rise
// (hard3d-06 with --rise-slowdown 3, --seed 10000: 0.18 px at a key frame where the foot was
// 0.75 px up, 242 ms late). A rise measured short starts at the same instant, so the liftoff
// lies between the fit's earliest knee and the crossing: the interval reaches down to the
// knee, its instant unchanged (the interval is symmetric: it widens as far later). Returns
// why, for the warning that the foot was seen by few patches, or "".
std::string ReachDownToTheKnee(const PatchSelection& selection, const internal::RiseFit& fit,
                               double crossing_s, double& uncertainty_s) {
  if (selection.foot.size() >= kFewFootPatches || !std::isfinite(crossing_s) ||
      !(fit.knee_low_s < crossing_s - uncertainty_s)) {
    return "";
  }
  uncertainty_s = crossing_s - fit.knee_low_s;
  return "they may measure it short (holding still ground), so the liftoff may be as early as "
         "the rise's start at " +
         FormatFixed(fit.knee_low_s, 3) + " s";
}

// How far the ground's level (the shake, a median over kSmoothHalfS either side) moved from
// the rest frames to the crossing at crossing_s, px. A still camera's ground does not move:
// a drift that comes with the rise is a shadow or a part of the robot among the ground
// patches, and moves the height curve by as much.
double GroundDriftPx(const std::vector<HeightSample>& samples, const std::vector<double>& shake_px,
                     const std::vector<size_t>& rest, double crossing_s) {
  std::vector<double> at_rest, at_crossing;
  for (size_t f : rest) at_rest.push_back(shake_px[f]);
  for (size_t f = 0; f < samples.size(); ++f) {
    if (std::abs(Seconds(samples[f].t_ns) - crossing_s) <= kSmoothHalfS) {
      at_crossing.push_back(shake_px[f]);
    }
  }
  const double drift = FiniteMedian(at_crossing) - FiniteMedian(at_rest);
  return std::isfinite(drift) ? std::abs(drift) : 0.0;
}

// The liftoff instant and its onset from the search. With a codec's lag the fit only
// bounds the instant: its middle; without, the curve itself is exact to noise, and a line
// through the frames around its crossing beats the model's two terms (when it lies inside
// the model's interval).
void SetLiftoff(const std::vector<HeightSample>& samples, const PatchSelection& selection,
                const std::vector<size_t>& rest, const LiftoffSearch& search,
                double compression_error_px, FootTrack& track) {
  const internal::RiseFit& fit = search.fit;
  double crossing_s = search.lag_bound_px > 0 ? fit.crossing_middle_s : fit.crossing_s;
  if (search.lag_bound_px == 0 && track.rest_noise_px < kLocalCrossingNoisePx) {
    const double local_s = internal::LocalCrossingS(samples, selection.height_px, search.fit_first,
                                          search.fit_last, fit.level + track.threshold_px);
    if (local_s >= fit.crossing_low_s && local_s <= fit.crossing_high_s) crossing_s = local_s;
  }
  const double drift_px = GroundDriftPx(samples, selection.shake_px, rest, crossing_s);
  track.still_noise_px = search.still_noise_px;
  double uncertainty_s =
      LiftoffUncertaintyS(track, search, crossing_s, compression_error_px, drift_px);
  // the foot's own patches disagreeing on the crossing (a tiny foot's patches that hold
  // some ground lag it: re-drawn hard3d-04, --seed 5000, at 0.25 px a mm)
  const size_t sustain_frames = std::max<size_t>(kSustainFrames, FramesIn(samples, kSustainS));
  uncertainty_s = std::hypot(uncertainty_s,
                             internal::PatchCrossingSpreadS(
                                 samples, selection.foot_curves_px, search.fit_first,
                                 fit.level + track.threshold_px, sustain_frames, kSustainFrames));
  const std::string disagreed =
      CheckAgainstTheCurve(samples, selection.height_px, search, track, crossing_s, uncertainty_s);
  const std::string sank =
      CheckSinking(samples, search, track, crossing_s, uncertainty_s);
  const std::string lost =
      CheckLostRise(samples, selection, search, track, crossing_s, uncertainty_s);
  const std::string few = ReachDownToTheKnee(selection, fit, crossing_s, uncertainty_s);
  // (bounded: a nearly flat model at the crossing must not overflow the nanoseconds)
  track.above_threshold =
      MakeEvent(samples, crossing_s, std::min(uncertainty_s, kLongestUncertaintyS));
  track.onset = MakeEvent(samples, fit.knee_s,
                          std::max(fit.knee_s - fit.knee_low_s, fit.knee_high_s - fit.knee_s));
  track.fit_first_frame = samples[search.fit_first].frame_index;
  track.fit_last_frame = samples[search.fit_last].frame_index;
  track.fit_noise_px = fit.noise;
  AddConfidenceWarnings(track, selection, fit, uncertainty_s, few);
  for (const std::string& why : {disagreed, sank, lost}) {
    if (why.empty()) continue;
    track.warnings.push_back("low confidence: " + why);
    track.low_confidence = true;
  }
}

}  // namespace

Result<FootTrack> FootTracker::FinishWith(std::vector<HeightSample> samples) const {
  const Impl& s = *impl_;
  const Options& o = s.options;
  if (!s.options_status.ok()) return s.options_status;
  if (samples.empty()) return InvalidArgumentError("no frame was given to the foot tracker");
  if (!s.initialised || s.patches.empty()) {
    return NotFoundError("the foot region " + RectText(o.foot_roi_px) +
                         " shows nothing to track (too few frames, or no edge or texture)");
  }
  const size_t frames = samples.size();
  const RiseTable table(s.rises, s.patches.size(), s.measured_from);
  const std::vector<size_t> rest =
      RestFrames(samples, s.measured_from, s.rest_from_ns, s.rest_to_ns, o.rest_frames);
  if (rest.empty()) {
    return InvalidArgumentError("the rest window " + FormatSeconds(s.rest_from_ns, 4) + " .. " +
                                FormatSeconds(s.rest_to_ns, 4) +
                                " s holds no frame the foot tracker measured");
  }
  // where patches end: their last 0.5 s
  const size_t final_count = std::max<size_t>(kSustainFrames, FramesIn(samples, kFinalS));
  const PatchSelection selection = SelectPatches(table, s.patches, rest, frames, final_count, 0);
  Result<FootTrack> track = s.Measure(selection, rest, samples);
  if (!track.ok()) return track;
  // a ground that rose with the foot was the robot (a small robot filling the region's
  // margin, tipping as the foot lifts): measured again against the patches still up to
  // the crossing, kept when their ground moved less
  const double drift_px = GroundDriftPx(samples, selection.shake_px, rest,
                                        Seconds(track->above_threshold.t_ns));
  if (drift_px <= track->threshold_px) return track;
  const size_t until = FrameAtOrAfter(samples, track->above_threshold.t_ns);
  const PatchSelection still =
      SelectPatches(table, s.patches, rest, frames, final_count, until);
  if (still.ground.size() < kFewGroundPatches) return track;
  Result<FootTrack> again = s.Measure(still, rest, samples);
  if (!again.ok()) return track;
  const double again_drift_px =
      GroundDriftPx(samples, still.shake_px, rest, Seconds(again->above_threshold.t_ns));
  return again_drift_px < drift_px ? again : track;
}

// The foot's track from a selection of patches: its place and scale, its samples, the
// liftoff.
Result<FootTrack> FootTracker::Impl::Measure(const PatchSelection& selection,
                                             const std::vector<size_t>& rest,
                                             std::vector<HeightSample> curve) const {
  const Options& o = options;
  FootTrack track;
  track.foot_roi_px = o.foot_roi_px;
  track.exposure_offset_ns = 0;  // a frame's time is the middle of its exposure
  if (selection.foot.empty()) {
    return NotFoundError("the foot never lifts: nothing in the foot region " +
                         RectText(o.foot_roi_px) + " rises against the ground around it");
  }
  const cv::Rect2d foot_box = PlacePatches(selection, track);
  track.foot_center_x_px = foot_box.x + (foot_box.width - 1) / 2.0;
  track.foot_width_px = foot_box.width;
  track.foot_bottom_px = foot_box.y + foot_box.height - 0.5;
  SetScale(o, foot_box.width, track);
  FillSamples(selection, rest, o.min_quality, curve, track);

  const LiftoffSearch search = FindLiftoff(curve, selection.height_px, rest.front(),
                                           track.threshold_px, track.rest_noise_px,
                                           o.compression_error_px > 0);
  track.max_rise_px = search.max_rise_px;
  if (!search.not_found.empty()) return NotFoundError(search.not_found);
  SetLiftoff(curve, selection, rest, search, o.compression_error_px, track);
  if (o.tape_colour) {
    track.located_by_tape = ShowsTapeColour(patches, selection.foot, *o.tape_colour);
    if (!track.located_by_tape) {
      track.warnings.push_back("the tracked foot does not show foot " +
                               std::string(FootName(*o.tape_colour)) +
                               "'s tape colour: check the verification image");
    }
  }
  track.samples = std::move(curve);
  return track;
}

}  // namespace liftoff::video
