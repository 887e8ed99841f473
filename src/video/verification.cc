#include "liftoff/video/verification.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "video_util.h"

namespace liftoff::video {
namespace {

// colours, BGR
const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrey(150, 150, 150);
const cv::Scalar kLightGrey(225, 225, 225);
const cv::Scalar kPaper(250, 250, 250);
const cv::Scalar kRoi(255, 200, 0);        // cyan-blue: regions of interest
const cv::Scalar kRest(60, 180, 60);       // green: rest
const cv::Scalar kThreshold(40, 40, 230);  // red: threshold
const cv::Scalar kTracked(0, 215, 255);    // yellow: the tracked bottom of the foot
const cv::Scalar kLed(0, 140, 255);        // orange: LED on
const cv::Scalar kOnset(200, 80, 160);     // purple: onset

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kShift = 4;  // sub-pixel bits of cv::line
constexpr double kSubPixel = 16.0;
constexpr int kPngCompressionLevel = 3;  // zlib, 0 .. 9 (WritePng)

void Text(cv::Mat& image, const std::string& text, cv::Point at, double scale,
          const cv::Scalar& colour, int thickness = 1) {
  cv::putText(image, text, at, kFont, scale, colour, thickness, cv::LINE_AA);
}

// a horizontal line at a sub-pixel row
void HLine(cv::Mat& image, double y, double x0, double x1, const cv::Scalar& colour,
           int thickness = 1) {
  const auto at = [](double v) { return static_cast<int>(std::lround(v * kSubPixel)); };
  cv::line(image, {at(x0), at(y)}, {at(x1), at(y)}, colour, thickness, cv::LINE_AA, kShift);
}

std::string SecondsText(int64_t ns) { return FormatSeconds(ns, 3) + " s"; }

// ---------------------------------------------------------------------------------------
// what the image needs from the clip

// The crops the image shows, by frame index, with their captions.
struct Shot {
  int64_t frame = 0;
  std::string label;
};

// the frame of the rest window's middle (the rest frame), by the track's samples
int64_t RestFrame(const ClipAnalysis& analysis) {
  const FootTrack& track = *analysis.foot;
  const int64_t middle_ns =
      analysis.rest_from_ns + (analysis.rest_to_ns - analysis.rest_from_ns) / 2;
  int64_t best = 0;
  int64_t best_distance = std::numeric_limits<int64_t>::max();
  for (const HeightSample& sample : track.samples) {
    const int64_t distance = std::abs(sample.t_ns - middle_ns);
    if (distance < best_distance) {
      best_distance = distance;
      best = sample.frame_index;
    }
  }
  return best;
}

std::vector<Shot> LedShots(const ClipAnalysis& analysis) {
  const int64_t last = analysis.timing.frames - 1;
  const LedPulse& pulse = analysis.led_on();
  std::vector<Shot> shots;
  if (pulse.first_lit_frame > 0) shots.push_back({pulse.first_lit_frame - 1, "last dark"});
  shots.push_back({pulse.first_lit_frame,
                   "first lit (" + FormatFixed(100.0 * pulse.first_lit_fraction, 0) + " %)"});
  if (pulse.first_lit_frame < last) shots.push_back({pulse.first_lit_frame + 1, "next"});
  return shots;
}

std::vector<Shot> FootShots(const ClipAnalysis& analysis) {
  std::vector<Shot> shots;
  if (!analysis.foot) return shots;
  const FootTrack& track = *analysis.foot;
  const int64_t last = analysis.timing.frames - 1;
  const int64_t after = track.above_threshold.frame_after;
  // a later frame, about 0.2 s on, where the lift is plain to see
  const int64_t interval_ns = std::max<int64_t>(analysis.timing.median_interval_ns, 1);
  const int64_t later =
      std::min(last, after + std::max<int64_t>(2, NsFromSeconds(0.2) / interval_ns));
  shots.push_back({RestFrame(analysis), "rest"});
  shots.push_back({track.onset.frame_after, "onset"});
  shots.push_back({track.above_threshold.frame_before, "last below"});
  shots.push_back({after, "first above"});
  if (later > after) shots.push_back({later, "later"});
  return shots;
}

// ---------------------------------------------------------------------------------------
// drawing on frames

// Rows of the three foot lines in one frame, image px: the foot's bottom edge as the
// tracker located it in the first frame (its reference), moved by the rest level, the
// threshold, or the frame's rise, and by the frame's camera shake.
struct FootLines {
  double rest = 0.0;
  double threshold = 0.0;
  double tracked = 0.0;
};

FootLines LinesAt(const FootTrack& track, const HeightSample& sample) {
  FootLines lines;
  lines.rest = track.foot_bottom_px - track.rest_rise_px + sample.shake_y_px;
  lines.threshold = lines.rest - track.threshold_px;
  lines.tracked = track.foot_bottom_px - sample.rise_px + sample.shake_y_px;
  return lines;
}

// A region grown by `margin` of its size on every side (at least `min_margin_px`), inside
// the frame.
cv::Rect Grown(const cv::Rect& rect, double margin, int min_margin_px, const cv::Size& frame) {
  const int dx = std::max(min_margin_px, static_cast<int>(std::lround(margin * rect.width)));
  const int dy = std::max(min_margin_px, static_cast<int>(std::lround(margin * rect.height)));
  const cv::Rect grown(rect.x - dx, rect.y - dy, rect.width + 2 * dx, rect.height + 2 * dy);
  return grown & cv::Rect(0, 0, frame.width, frame.height);
}

// The crop of `bgr` at `region`, enlarged to `height_px` (pixels kept square and sharp
// when enlarged), with a caption strip below.
struct Crop {
  cv::Mat image;
  double scale = 1.0;
  cv::Rect region;
  // crop coordinates of an image point (pixel centres at integers)
  cv::Point2d Map(double x, double y) const {
    return {(x - region.x + 0.5) * scale - 0.5, (y - region.y + 0.5) * scale - 0.5};
  }
};

Crop MakeCrop(const cv::Mat& bgr, const cv::Rect& region, int height_px) {
  Crop crop;
  crop.region = region;
  crop.scale = static_cast<double>(height_px) / region.height;
  const int width_px = std::max(1, static_cast<int>(std::lround(region.width * crop.scale)));
  cv::resize(bgr(region), crop.image, cv::Size(width_px, height_px), 0, 0,
             crop.scale >= 2.0 ? cv::INTER_NEAREST : cv::INTER_AREA);
  return crop;
}

void DrawRect(Crop& crop, const cv::Rect& rect, const cv::Scalar& colour) {
  const cv::Point2d a = crop.Map(rect.x - 0.5, rect.y - 0.5);
  const cv::Point2d b = crop.Map(rect.x + rect.width - 0.5, rect.y + rect.height - 0.5);
  cv::rectangle(crop.image,
                cv::Point(static_cast<int>(std::lround(a.x)), static_cast<int>(std::lround(a.y))),
                cv::Point(static_cast<int>(std::lround(b.x)), static_cast<int>(std::lround(b.y))),
                colour, 1, cv::LINE_AA);
}

// the crop with its caption lines below it
cv::Mat Captioned(const cv::Mat& image, const std::vector<std::string>& lines) {
  constexpr int kLine = 17;
  cv::Mat out(image.rows + 6 + kLine * static_cast<int>(lines.size()), std::max(image.cols, 150),
              CV_8UC3, kPaper);
  image.copyTo(out(cv::Rect(0, 0, image.cols, image.rows)));
  for (size_t i = 0; i < lines.size(); ++i) {
    Text(out, lines[i], {2, image.rows + 14 + kLine * static_cast<int>(i)}, 0.42, kBlack);
  }
  return out;
}

// ---------------------------------------------------------------------------------------
// the height plot

double NiceStep(double span, int ticks) {
  const double raw = span / std::max(1, ticks);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  for (const double nice : {1.0, 2.0, 2.5, 5.0, 10.0}) {
    if (nice * power >= raw) return nice * power;
  }
  return 10.0 * power;
}

// one panel: samples over [t0, t1] with the rest, threshold and event marks
struct Panel {
  cv::Mat& image;
  cv::Rect area;  // the plotting area inside image
  double t0_s, t1_s, y0, y1;
  int X(double t_s) const {
    return area.x + static_cast<int>(std::lround((t_s - t0_s) / (t1_s - t0_s) * area.width));
  }
  int Y(double value) const {
    return area.y + area.height -
           static_cast<int>(std::lround((value - y0) / (y1 - y0) * area.height));
  }
};

void DrawAxes(Panel& panel, const std::string& unit, const std::string& title) {
  cv::Mat& image = panel.image;
  cv::rectangle(image, panel.area, kGrey, 1);
  const double t_step = NiceStep(panel.t1_s - panel.t0_s, 8);
  for (double t = std::ceil(panel.t0_s / t_step) * t_step; t <= panel.t1_s + 1e-9; t += t_step) {
    const int x = panel.X(t);
    cv::line(image, {x, panel.area.y}, {x, panel.area.y + panel.area.height}, kLightGrey, 1);
    Text(image, FormatFixed(std::abs(t) < 1e-9 ? 0.0 : t, t_step < 0.1 ? 2 : 1),
         {x - 12, panel.area.y + panel.area.height + 15}, 0.4, kBlack);
  }
  const double y_step = NiceStep(panel.y1 - panel.y0, 5);
  const int y_decimals = std::abs(y_step - std::round(y_step)) > 1e-9 ? (y_step < 0.1 ? 2 : 1) : 0;
  for (double v = std::ceil(panel.y0 / y_step) * y_step; v <= panel.y1 + 1e-9; v += y_step) {
    const int y = panel.Y(v);
    cv::line(image, {panel.area.x, y}, {panel.area.x + panel.area.width, y}, kLightGrey, 1);
    const double shown = std::abs(v) < 1e-9 ? 0.0 : v;  // no "-0"
    Text(image, FormatFixed(shown, y_decimals), {panel.area.x - 44, y + 4}, 0.4, kBlack);
  }
  Text(image, title, {panel.area.x, panel.area.y - 8}, 0.5, kBlack);
  Text(image, "s", {panel.area.x + panel.area.width + 6, panel.area.y + panel.area.height + 15},
       0.4, kBlack);
  Text(image, unit, {panel.area.x - 40, panel.area.y - 8}, 0.4, kBlack);
}

void DrawEvent(Panel& panel, const TimedEvent& event, const cv::Scalar& colour,
               const std::string& label, int label_row) {
  const double t_s = SecondsFromNs(event.t_ns);
  const double half_s = SecondsFromNs(event.uncertainty_ns);
  const int x = panel.X(t_s);
  const int x0 = std::max(panel.area.x, panel.X(t_s - half_s));
  const int x1 = std::min(panel.area.x + panel.area.width, panel.X(t_s + half_s));
  if (x1 > x0) {
    cv::Mat band = panel.image(cv::Rect(x0, panel.area.y, x1 - x0, panel.area.height));
    cv::Mat tint(band.size(), band.type(), colour);
    cv::addWeighted(band, 0.8, tint, 0.2, 0.0, band);
  }
  cv::line(panel.image, {x, panel.area.y}, {x, panel.area.y + panel.area.height}, colour, 1);
  Text(panel.image, label, {x + 4, panel.area.y + 16 + 16 * label_row}, 0.42, colour);
}

// The height above rest over [t0, t1] s in mm (px without a scale).
void DrawHeightPanel(cv::Mat& image, const cv::Rect& area, const ClipAnalysis& analysis,
                     double t0_s, double t1_s, bool dots, const std::string& title) {
  const FootTrack& track = *analysis.foot;
  const double per_px = track.px_per_mm > 0 ? 1.0 / track.px_per_mm : 1.0;
  const std::string unit = track.px_per_mm > 0 ? "mm" : "px";
  const double threshold = track.threshold_px * per_px;
  // value range: the samples shown, rest and threshold
  double low = -0.5 * threshold, high = 2.0 * threshold;
  for (const HeightSample& sample : track.samples) {
    const double t_s = SecondsFromNs(sample.t_ns);
    if (t_s < t0_s || t_s > t1_s) continue;
    const double value = (sample.rise_px - track.rest_rise_px) * per_px;
    low = std::min(low, value);
    high = std::max(high, value);
  }
  const double pad = 0.08 * (high - low);
  Panel panel{image, area, t0_s, t1_s, low - pad, high + pad};
  DrawAxes(panel, unit, title);

  // rest window, rest and threshold lines
  const int wx0 = std::max(area.x, panel.X(SecondsFromNs(analysis.rest_from_ns)));
  const int wx1 = std::min(area.x + area.width, panel.X(SecondsFromNs(analysis.rest_to_ns)));
  if (wx1 > wx0) {
    cv::Mat band = image(cv::Rect(wx0, area.y, wx1 - wx0, area.height));
    cv::Mat tint(band.size(), band.type(), kRest);
    cv::addWeighted(band, 0.85, tint, 0.15, 0.0, band);
  }
  cv::line(image, {area.x, panel.Y(0.0)}, {area.x + area.width, panel.Y(0.0)}, kRest, 1);
  cv::line(image, {area.x, panel.Y(threshold)}, {area.x + area.width, panel.Y(threshold)},
           kThreshold, 1);
  Text(image, "rest", {area.x + area.width - 34, panel.Y(0.0) - 4}, 0.4, kRest);
  Text(image, "threshold " + FormatFixed(threshold, 2) + " " + unit,
       {area.x + area.width - 150, panel.Y(threshold) - 4}, 0.4, kThreshold);

  // events
  const double led_s = SecondsFromNs(analysis.led_on().on_ns);
  if (led_s >= t0_s && led_s <= t1_s) {
    TimedEvent led_event;
    led_event.t_ns = analysis.led_on().on_ns;
    led_event.uncertainty_ns = analysis.led_on().on_uncertainty_ns;
    DrawEvent(panel, led_event, kLed, "LED on", 0);
  }
  DrawEvent(panel, track.onset, kOnset, "onset", 1);
  DrawEvent(panel, track.above_threshold, kThreshold, "liftoff", 2);

  // the curve
  cv::Point previous(-1, -1);
  for (const HeightSample& sample : track.samples) {
    const double t_s = SecondsFromNs(sample.t_ns);
    if (t_s < t0_s || t_s > t1_s) continue;
    const cv::Point point(panel.X(t_s), panel.Y((sample.rise_px - track.rest_rise_px) * per_px));
    if (previous.x >= 0) cv::line(image, previous, point, kBlack, 1, cv::LINE_AA);
    if (dots) cv::circle(image, point, 2, kBlack, cv::FILLED, cv::LINE_AA);
    previous = point;
  }
}

// ---------------------------------------------------------------------------------------
// the annotated video's overlay

bool LedLitAt(const LedResult& led, int64_t t_ns) {
  for (const LedPulse& pulse : led.pulses) {
    if (t_ns >= pulse.on_ns && (!pulse.off_ns || t_ns < *pulse.off_ns)) return true;
  }
  return false;
}

void DrawOverlay(cv::Mat& frame, const ClipAnalysis& analysis, const Frame& decoded) {
  const bool lit = LedLitAt(analysis.led, decoded.t_ns);
  cv::rectangle(frame, analysis.led.roi_px, lit ? kLed : kGrey, 2);
  std::string status = "frame " + std::to_string(decoded.index) + "  " + SecondsText(decoded.t_ns);
  if (lit) status += "  LED on";
  if (analysis.foot) {
    const FootTrack& track = *analysis.foot;
    const cv::Rect& roi = track.foot_roi_px;
    cv::rectangle(frame, roi, kRoi, 1);
    for (const cv::Rect& patch : track.reference_patches_px) cv::rectangle(frame, patch, kGrey, 1);
    const auto index = static_cast<size_t>(decoded.index);
    if (index < track.samples.size()) {
      const FootLines lines = LinesAt(track, track.samples[index]);
      HLine(frame, lines.rest, roi.x, roi.x + roi.width - 1.0, kRest);
      HLine(frame, lines.threshold, roi.x, roi.x + roi.width - 1.0, kThreshold);
      HLine(frame, lines.tracked, track.foot_center_x_px - 0.5 * track.foot_width_px,
            track.foot_center_x_px + 0.5 * track.foot_width_px, kTracked);
    }
    if (decoded.t_ns >= track.above_threshold.t_ns) status += "  lifted";
  }
  Text(frame, status, {11, 25}, 0.6, kBlack, 3);
  Text(frame, status, {10, 24}, 0.6, kWhite, 1);
}

// ---------------------------------------------------------------------------------------
// the image

// Lays out captioned crops left to right, wrapping at `width`.
cv::Mat Row(const std::vector<cv::Mat>& tiles, int width, const std::string& heading) {
  constexpr int kGap = 10, kHeading = 26;
  int x = kGap, y = kHeading, row_height = 0;
  std::vector<cv::Point> at;
  for (const cv::Mat& tile : tiles) {
    if (x + tile.cols > width - kGap && x > kGap) {
      x = kGap;
      y += row_height + kGap;
      row_height = 0;
    }
    at.emplace_back(x, y);
    x += tile.cols + kGap;
    row_height = std::max(row_height, tile.rows);
  }
  cv::Mat row(y + row_height + kGap, width, CV_8UC3, kWhite);
  Text(row, heading, {kGap, 18}, 0.55, kBlack);
  for (size_t i = 0; i < tiles.size(); ++i) {
    const cv::Mat& tile = tiles[i];
    const cv::Rect place(at[i].x, at[i].y, std::min(tile.cols, width - at[i].x), tile.rows);
    tile(cv::Rect(0, 0, place.width, place.height)).copyTo(row(place));
  }
  return row;
}

cv::Mat Stack(const std::vector<cv::Mat>& parts) {
  cv::Mat stacked;
  cv::vconcat(parts, stacked);
  return stacked;
}

}  // namespace

Status VerificationOptions::Validate() const {
  const auto check = [](std::string_view field, int value, int min, int max) {
    if (value >= min && value <= max) return Status::Ok();
    return InvalidArgumentError(std::string(field) + ": expected an integer in [" +
                                std::to_string(min) + ", " + std::to_string(max) + "], got " +
                                std::to_string(value));
  };
  LIFTOFF_RETURN_IF_ERROR(check("crop_height_px", crop_height_px, 64, 1024));
  LIFTOFF_RETURN_IF_ERROR(check("image_width_px", image_width_px, 640, 4096));
  LIFTOFF_RETURN_IF_ERROR(check("video_quality", video_quality, 1, 100));
  if (image_path.empty() && video_path.empty()) {
    return InvalidArgumentError("image_path, video_path: name at least one file to write");
  }
  return Status::Ok();
}

std::string VerificationReport::Brief() const {
  std::string text;
  if (!image_path.empty()) text += image_path.string();
  if (!video_path.empty()) text += (text.empty() ? "" : " and ") + video_path.string();
  return text + ", " + std::to_string(frames_decoded) + " of " + Plural(clip_frames, "frame") +
         " decoded";
}

// ---------------------------------------------------------------------------------------
// WriteVerification's steps

namespace {

// a frame the image shows, kept from the second decode, by index
struct KeptFrame {
  cv::Mat bgr;
  int64_t t_ns = 0;
};
using KeptFrames = std::map<int64_t, KeptFrame>;

// The annotated video's writer: OpenCV's own Motion JPEG writer (no GStreamer or
// image-sequence backend to try and complain about on stderr), its log quiet while it
// opens. Left closed when no video is asked for.
Status OpenVideoWriter(const ClipAnalysis& analysis, const VerificationOptions& options,
                       cv::VideoWriter& writer) {
  if (options.video_path.empty()) return Status::Ok();
  LIFTOFF_RETURN_IF_ERROR(CreateParentFolder(options.video_path));
  const double interval_s = SecondsFromNs(analysis.timing.median_interval_ns);
  const double fps =
      analysis.timing.fps > 0 ? analysis.timing.fps : (interval_s > 0 ? 1.0 / interval_s : 30.0);
  const internal::QuietOpenCvLog quiet;
  const bool opened = writer.open(options.video_path.string(), cv::CAP_OPENCV_MJPEG,
                                  cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), fps,
                                  cv::Size(analysis.width_px, analysis.height_px));
  if (!opened) {
    return UnsupportedError(DisplayPath(options.video_path) +
                            ": cannot write a Motion JPEG AVI there (OpenCV's writer refused)");
  }
  writer.set(cv::VIDEOWRITER_PROP_QUALITY, options.video_quality);
  return Status::Ok();
}

// The second decode: each frame checked against the analysis, the `wanted` frames kept
// for the image (when one is asked for), every frame annotated into the open writer; with
// no video it stops after the last wanted frame.
Status DecodeAgain(const ClipAnalysis& analysis, const std::vector<int64_t>& wanted,
                   bool want_image, VideoReader& reader, cv::VideoWriter& writer, KeptFrames& kept,
                   VerificationReport& report) {
  int64_t last_needed = 0;
  for (const int64_t index : wanted) last_needed = std::max(last_needed, index);
  Frame frame;
  cv::Mat annotated;
  while (true) {
    LIFTOFF_ASSIGN_OR_RETURN(const bool more, reader.Next(frame));
    if (!more) break;
    ++report.frames_decoded;
    if (analysis.foot) {
      const std::vector<HeightSample>& samples = analysis.foot->samples;
      const auto index = static_cast<size_t>(frame.index);
      if (index >= samples.size() || samples[index].t_ns != frame.t_ns) {
        return InvalidArgumentError(DisplayPath(analysis.video_path) + ": frame " +
                                    std::to_string(frame.index) +
                                    " differs from the analysed one; analyse the clip again");
      }
    }
    if (want_image && std::find(wanted.begin(), wanted.end(), frame.index) != wanted.end()) {
      kept[frame.index] = {frame.bgr.clone(), frame.t_ns};
    }
    if (writer.isOpened()) {
      frame.bgr.copyTo(annotated);
      DrawOverlay(annotated, analysis, frame);
      writer.write(annotated);
    } else if (frame.index >= last_needed) {
      break;
    }
  }
  return Status::Ok();
}

// the image's title: the clip's name and the analysis in brief
cv::Mat TitlePart(const ClipAnalysis& analysis, int width) {
  cv::Mat title(58, width, CV_8UC3, kWhite);
  Text(title, analysis.video_path.filename().string(), {10, 22}, 0.65, kBlack, 2);
  Text(title, analysis.Brief(), {10, 46}, 0.45, kBlack);
  return title;
}

// the LED crops, captioned, and the switch-on in words
cv::Mat LedPart(const ClipAnalysis& analysis, const std::vector<Shot>& shots,
                const KeptFrames& kept, const VerificationOptions& options) {
  const cv::Size frame_size(analysis.width_px, analysis.height_px);
  std::vector<cv::Mat> tiles;
  const cv::Rect led_region = Grown(analysis.led.roi_px, 1.0, 8, frame_size);
  for (const Shot& shot : shots) {
    const auto found = kept.find(shot.frame);
    if (found == kept.end()) continue;
    Crop crop = MakeCrop(found->second.bgr, led_region, options.crop_height_px);
    DrawRect(crop, analysis.led.roi_px, kRoi);
    tiles.push_back(Captioned(crop.image, {shot.label, "frame " + std::to_string(shot.frame),
                                           SecondsText(found->second.t_ns)}));
  }
  const LedPulse& pulse = analysis.led_on();
  return Row(tiles, options.image_width_px,
             "LED: on at " + FormatSeconds(pulse.on_ns, 4) + " s +- " +
                 FormatFixed(1e-6 * static_cast<double>(pulse.on_uncertainty_ns), 1) +
                 " ms (region " + std::string(analysis.led.roi_located ? "located" : "given") +
                 ", levels off " + FormatFixed(analysis.led.off_level, 0) + " / on " +
                 FormatFixed(analysis.led.on_level, 0) + ")");
}

// one foot crop: the region, the ground patches where the camera's shake put them, the
// foot's where its rise did, the rest, threshold and tracked lines, and the rise in words
cv::Mat FootTile(const FootTrack& track, const Shot& shot, const KeptFrame& frame,
                 const cv::Rect& foot_region, int crop_height_px) {
  const HeightSample& sample = track.samples[static_cast<size_t>(shot.frame)];
  Crop crop = MakeCrop(frame.bgr, foot_region, crop_height_px);
  DrawRect(crop, track.foot_roi_px, kRoi);
  const FootLines lines = LinesAt(track, sample);
  const double x0 = crop.Map(track.foot_roi_px.x, 0).x;
  const double x1 = crop.Map(track.foot_roi_px.x + track.foot_roi_px.width - 1.0, 0).x;
  const double xm0 = crop.Map(track.foot_center_x_px - 0.5 * track.foot_width_px, 0).x;
  const double xm1 = crop.Map(track.foot_center_x_px + 0.5 * track.foot_width_px, 0).x;
  const int shake_px = static_cast<int>(std::lround(sample.shake_y_px));
  const int lift_px = static_cast<int>(std::lround(sample.shake_y_px - sample.rise_px));
  for (const cv::Rect& patch : track.reference_patches_px) {
    DrawRect(crop, patch + cv::Point(0, shake_px), kGrey);
  }
  for (const cv::Rect& patch : track.foot_patches_px) {
    DrawRect(crop, patch + cv::Point(0, lift_px), kTracked);
  }
  HLine(crop.image, crop.Map(0, lines.rest).y, x0, x1, kRest);
  HLine(crop.image, crop.Map(0, lines.threshold).y, x0, x1, kThreshold);
  HLine(crop.image, crop.Map(0, lines.tracked).y, xm0, xm1, kTracked, 2);
  const double above = sample.rise_px - track.rest_rise_px;
  const std::string height = track.px_per_mm > 0 ? FormatFixed(above / track.px_per_mm, 2) + " mm"
                                                 : FormatFixed(above, 2) + " px";
  return Captioned(crop.image, {shot.label, "frame " + std::to_string(shot.frame),
                                SecondsText(sample.t_ns), "rise " + height});
}

// the foot crops and what their colours mean
cv::Mat FootPart(const ClipAnalysis& analysis, const std::vector<Shot>& shots,
                 const KeptFrames& kept, const VerificationOptions& options) {
  const FootTrack& track = *analysis.foot;
  const cv::Size frame_size(analysis.width_px, analysis.height_px);
  const cv::Rect foot_region = Grown(track.foot_roi_px, 0.25, 4, frame_size);
  std::vector<cv::Mat> tiles;
  for (const Shot& shot : shots) {
    const auto found = kept.find(shot.frame);
    if (found == kept.end()) continue;
    tiles.push_back(FootTile(track, shot, found->second, foot_region, options.crop_height_px));
  }
  std::string heading =
      "foot: region blue, ground patches grey, foot patches yellow (moved by the rise), rest "
      "green, threshold red (" +
      FormatFixed(track.threshold_px, 2) + " px";
  if (track.px_per_mm > 0) {
    heading += " = " + FormatFixed(track.threshold_px / track.px_per_mm, 2) + " mm";
  }
  heading += "); rest window " + FormatSeconds(analysis.rest_from_ns) + "-" +
             FormatSeconds(analysis.rest_to_ns) + " s";
  return Row(tiles, options.image_width_px, heading);
}

// close-ups of the bottom edge, enlarged until the threshold is plain to see: the rows
// around the rest line (moved with each frame's shake), the foot's width and a margin
cv::Mat EdgePart(const ClipAnalysis& analysis, const std::vector<Shot>& shots,
                 const KeptFrames& kept, int width) {
  const FootTrack& track = *analysis.foot;
  const double rest_row = track.foot_bottom_px - track.rest_rise_px;
  const double half_rows = std::max(6.0, 4.0 * track.threshold_px);
  const int tiles = std::max(1, static_cast<int>(shots.size()));
  std::vector<cv::Mat> edge_tiles;
  for (const Shot& shot : shots) {
    const auto found = kept.find(shot.frame);
    if (found == kept.end()) continue;
    const HeightSample& sample = track.samples[static_cast<size_t>(shot.frame)];
    const double top = rest_row - half_rows + sample.shake_y_px;
    const cv::Rect asked(
        static_cast<int>(std::lround(track.foot_center_x_px - 0.75 * track.foot_width_px)),
        static_cast<int>(std::lround(top)),
        std::max(4, static_cast<int>(std::lround(1.5 * track.foot_width_px))),
        std::max(4, static_cast<int>(std::lround(2.0 * half_rows))));
    const cv::Rect region = asked & cv::Rect(0, 0, analysis.width_px, analysis.height_px);
    if (region.area() == 0) continue;
    const double fit = static_cast<double>(width - 10 * (tiles + 1)) / tiles / region.width;
    const double scale = std::clamp(fit, 1.0, 24.0);
    Crop crop =
        MakeCrop(found->second.bgr, region, static_cast<int>(std::lround(region.height * scale)));
    const FootLines lines = LinesAt(track, sample);
    const double x1 = crop.image.cols - 1.0;
    HLine(crop.image, crop.Map(0, lines.rest).y, 0, x1, kRest);
    HLine(crop.image, crop.Map(0, lines.threshold).y, 0, x1, kThreshold);
    HLine(crop.image, crop.Map(0, lines.tracked).y, 0.25 * x1, 0.75 * x1, kTracked);
    edge_tiles.push_back(
        Captioned(crop.image, {shot.label + ", frame " + std::to_string(shot.frame)}));
  }
  return Row(edge_tiles, width,
             "the foot's bottom edge enlarged (one square per pixel): rest green, "
             "threshold red, tracked bottom yellow");
}

// the height plots: the whole clip, then the close-up around liftoff
cv::Mat PlotsPart(const ClipAnalysis& analysis, int width) {
  const FootTrack& track = *analysis.foot;
  constexpr int kPlotHeight = 230, kLeft = 60, kRight = 30, kTop = 28, kBottom = 28;
  cv::Mat plots(2 * (kPlotHeight + kTop + kBottom), width, CV_8UC3, kWhite);
  const cv::Rect whole(kLeft, kTop, width - kLeft - kRight, kPlotHeight);
  const cv::Rect close(kLeft, kTop + kPlotHeight + kBottom + kTop, width - kLeft - kRight,
                       kPlotHeight);
  DrawHeightPanel(plots, whole, analysis, SecondsFromNs(analysis.timing.first_ns),
                  SecondsFromNs(analysis.timing.last_ns), false, "height above rest, whole clip");
  const double liftoff_s = SecondsFromNs(track.above_threshold.t_ns);
  const double onset_s = SecondsFromNs(track.onset.t_ns);
  const double interval_s = SecondsFromNs(std::max<int64_t>(analysis.timing.median_interval_ns, 1));
  const double half_s = std::max({0.15, 10.0 * interval_s, 1.3 * (liftoff_s - onset_s)});
  DrawHeightPanel(plots, close, analysis, liftoff_s - half_s, liftoff_s + half_s, true,
                  "close-up around liftoff (one dot per frame)");
  return plots;
}

// encode, then write in one go (zlib level 3 with its default strategy: half the size of
// OpenCV's default run-length one on these flat panels, for about 0.1 s more)
Status WritePng(const cv::Mat& image, const std::filesystem::path& path) {
  std::vector<uchar> png;
  try {
    if (!cv::imencode(".png", image, png, {cv::IMWRITE_PNG_COMPRESSION, kPngCompressionLevel})) {
      return IoError(DisplayPath(path) + ": PNG encoding failed");
    }
  } catch (const cv::Exception& error) {
    return IoError(DisplayPath(path) + ": PNG encoding failed: " + error.what());
  }
  return WriteFileAtomically(
      path, std::string_view(reinterpret_cast<const char*>(png.data()), png.size()));
}

}  // namespace

Result<VerificationReport> WriteVerification(const ClipAnalysis& analysis,
                                             const VerificationOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate());
  if (analysis.led.pulses.empty()) {
    return InvalidArgumentError(DisplayPath(analysis.video_path) +
                                ": the analysis holds no LED pulse");
  }
  VerificationReport report;
  report.clip_frames = analysis.timing.frames;
  report.foot_rest_bottom_px = analysis.foot
                                   ? analysis.foot->foot_bottom_px - analysis.foot->rest_rise_px
                                   : std::numeric_limits<double>::quiet_NaN();

  // the frames the image shows
  const std::vector<Shot> led_shots = LedShots(analysis);
  const std::vector<Shot> foot_shots = FootShots(analysis);
  std::vector<int64_t> wanted;
  for (const Shot& shot : led_shots) wanted.push_back(shot.frame);
  for (const Shot& shot : foot_shots) wanted.push_back(shot.frame);

  // the second decode, writing the video as it goes
  LIFTOFF_ASSIGN_OR_RETURN(VideoReader reader, VideoReader::Open(analysis.video_path));
  if (reader.width_px() != analysis.width_px || reader.height_px() != analysis.height_px) {
    return InvalidArgumentError(DisplayPath(analysis.video_path) +
                                ": the clip's size differs from the analysis'; analyse it again");
  }
  cv::VideoWriter writer;
  LIFTOFF_RETURN_IF_ERROR(OpenVideoWriter(analysis, options, writer));
  const bool want_image = !options.image_path.empty();
  KeptFrames kept;
  LIFTOFF_RETURN_IF_ERROR(DecodeAgain(analysis, wanted, want_image, reader, writer, kept, report));
  if (writer.isOpened()) {
    writer.release();
    report.video_path = options.video_path;
    if (report.frames_decoded != analysis.timing.frames) {
      return InvalidArgumentError(DisplayPath(analysis.video_path) + ": " +
                                  Plural(report.frames_decoded, "frame") + " decoded, " +
                                  std::to_string(analysis.timing.frames) +
                                  " analysed; analyse the clip again");
    }
  }
  if (!want_image) return report;

  // the image: title, LED, then the foot's crops, edges and plots
  std::vector<cv::Mat> parts = {TitlePart(analysis, options.image_width_px),
                                LedPart(analysis, led_shots, kept, options)};
  if (analysis.foot) {
    parts.push_back(FootPart(analysis, foot_shots, kept, options));
    parts.push_back(EdgePart(analysis, foot_shots, kept, options.image_width_px));
    parts.push_back(PlotsPart(analysis, options.image_width_px));
  }
  LIFTOFF_RETURN_IF_ERROR(WritePng(Stack(parts), options.image_path));
  report.image_path = options.image_path;
  return report;
}

}  // namespace liftoff::video
