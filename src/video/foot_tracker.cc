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

#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "video_util.h"

namespace liftoff::video {
namespace {

using internal::MedianOf;
using internal::RectText;

// Search radius around the previous frame's shift, px (the foot and the shake move less
// than this between two frames); beyond it a full search runs.
constexpr int kLocalSearchPx = 3;
// Largest camera shake searched on the reference patches, px.
constexpr int kMaxShakePx = 12;
// Half-width of the foot's measured columns, fraction of the foot's width.
constexpr double kColumnsHalfFraction = 0.15;
// The template ends this far above the foot's bottom edge, px (the ground and the shadow
// below the edge change as the foot rises; compression and blur spread them ~2 px).
constexpr double kTemplateBottomMarginPx = 2.0;
// Below this match quality a local search is retried as a full search.
constexpr double kRetryQuality = 0.6;
// Scale uncertainty assumed for an estimated px_per_mm (a fraction).
constexpr double kEstimatedScaleFraction = 0.03;
// A located foot wider than this fraction of its region draws a warning.
constexpr double kWideFootFraction = 0.8;
// The hinge is fitted up to where the foot is this many thresholds above rest: far enough
// to average over a codec's stepwise updates of slow sub-pixel motion (H.264 lets the
// decoded foot lag by up to ~0.4 px, then catch up, every ~10 frames).
constexpr double kFitEndThresholds = 5.0;

int Round(double value) { return static_cast<int>(std::lround(value)); }
int Floor(double value) { return static_cast<int>(std::floor(value)); }
int Ceil(double value) { return static_cast<int>(std::ceil(value)); }
int64_t RoundNs(double value) { return static_cast<int64_t>(std::llround(value)); }
size_t Index(int value) { return static_cast<size_t>(value); }

std::string MsText(int64_t t_ns) { return FormatFixed(static_cast<double>(t_ns) / 1e6, 1); }

// ---------------------------------------------------------------------------------------
// profiles

// Pixel weights that cover the continuous interval [lo, hi] (pixel i covers
// [i - 0.5, i + 0.5)), normalised to sum 1.
struct AxisWindow {
  int first = 0;
  std::vector<float> weights;
  int last() const { return first + static_cast<int>(weights.size()) - 1; }
};

AxisWindow MakeWindow(double lo, double hi) {
  AxisWindow window;
  window.first = Floor(lo + 0.5);
  const int last = std::max(window.first, Ceil(hi + 0.5) - 1);
  double sum = 0;
  for (int i = window.first; i <= last; ++i) {
    const double w = std::max(0.0, std::min(hi, i + 0.5) - std::max(lo, i - 0.5));
    window.weights.push_back(static_cast<float>(w));
    sum += w;
  }
  if (sum <= 0) {
    window.weights.assign(1, 1.0f);
    return window;
  }
  for (float& w : window.weights) w = static_cast<float>(static_cast<double>(w) / sum);
  return window;
}

// The window moved inside [0, size) when it pokes out (same weights).
AxisWindow ClampWindow(AxisWindow window, int size) {
  const int count = static_cast<int>(window.weights.size());
  window.first = std::clamp(window.first, 0, std::max(0, size - count));
  return window;
}

// Values at integer positions first .. first + length - 1, `channels` interleaved.
struct Profile {
  int first = 0;
  int length = 0;
  int channels = 1;
  std::vector<float> values;
  int last() const { return first + length - 1; }
  const float* at(int position) const {
    return values.data() + Index((position - first) * channels);
  }
};

// Mean over `columns` of rows [row_first, row_first + rows): B, G, R per row (channels 3)
// or B + G + R (channels 1). Rows and columns must lie inside the image.
void ColumnMean(const cv::Mat& bgr, const AxisWindow& columns, int row_first, int rows,
                int channels, Profile& out) {
  out.first = row_first;
  out.length = std::max(0, rows);
  out.channels = channels;
  out.values.assign(Index(out.length * channels), 0.0f);
  const size_t count = columns.weights.size();
  for (int r = 0; r < out.length; ++r) {
    const uint8_t* pixel = bgr.ptr<uint8_t>(row_first + r) + Index(columns.first * 3);
    float b = 0, g = 0, red = 0;
    for (size_t c = 0; c < count; ++c) {
      const float w = columns.weights[c];
      b += w * pixel[3 * c];
      g += w * pixel[3 * c + 1];
      red += w * pixel[3 * c + 2];
    }
    float* v = out.values.data() + Index(r * channels);
    if (channels == 3) {
      v[0] = b;
      v[1] = g;
      v[2] = red;
    } else {
      v[0] = b + g + red;
    }
  }
}

// Mean over `rows` of columns [col_first, col_first + cols), B + G + R.
void RowMean(const cv::Mat& bgr, const AxisWindow& rows, int col_first, int cols, Profile& out) {
  out.first = col_first;
  out.length = std::max(0, cols);
  out.channels = 1;
  out.values.assign(Index(out.length), 0.0f);
  for (size_t r = 0; r < rows.weights.size(); ++r) {
    const float w = rows.weights[r];
    const uint8_t* pixel =
        bgr.ptr<uint8_t>(rows.first + static_cast<int>(r)) + Index(col_first * 3);
    for (int c = 0; c < out.length; ++c) {
      const uint8_t* p = pixel + Index(3 * c);
      out.values[Index(c)] += w * static_cast<float>(p[0] + p[1] + p[2]);
    }
  }
}

// ---------------------------------------------------------------------------------------
// registration of a profile against its template

struct Match {
  double shift = 0;    // d: current(y) = gain * template(y - d) + offset
  double quality = 0;  // fraction of the current profile's variance the fit explains
  bool found = false;
  bool at_limit = false;  // the best integer shift is an end of the searched range
};

// Solves the symmetric 3 x 3 system a x = b; false when singular.
bool Solve3(std::array<std::array<double, 3>, 3> a, std::array<double, 3> b,
            std::array<double, 3>& x) {
  for (int col = 0; col < 3; ++col) {
    int pivot = col;
    for (int row = col + 1; row < 3; ++row) {
      if (std::abs(a[Index(row)][Index(col)]) > std::abs(a[Index(pivot)][Index(col)])) pivot = row;
    }
    if (std::abs(a[Index(pivot)][Index(col)]) < 1e-12) return false;
    std::swap(a[Index(col)], a[Index(pivot)]);
    std::swap(b[Index(col)], b[Index(pivot)]);
    for (int row = col + 1; row < 3; ++row) {
      const double factor = a[Index(row)][Index(col)] / a[Index(col)][Index(col)];
      for (int k = col; k < 3; ++k) a[Index(row)][Index(k)] -= factor * a[Index(col)][Index(k)];
      b[Index(row)] -= factor * b[Index(col)];
    }
  }
  for (int row = 2; row >= 0; --row) {
    double sum = b[Index(row)];
    for (int k = row + 1; k < 3; ++k) sum -= a[Index(row)][Index(k)] * x[Index(k)];
    x[Index(row)] = sum / a[Index(row)][Index(row)];
  }
  return true;
}

// Finds the shift d with current(y) ~ gain * template(y - d) + offset, the template
// interpolated linearly between positions, the integer part searched in [n_lo, n_hi].
// Coarse: the integer shift of best normalised correlation over at least `min_overlap`
// positions. Fine: on each pixel interval next to it, current(y) = alpha template(y - m) +
// beta template(y - m - 1) + offset is linear, so least squares gives the fraction
// beta / (alpha + beta) in closed form; the best fit among the two intervals and the three
// integer shifts wins.
Match Register(const Profile& templ, const Profile& current, int n_lo, int n_hi, int min_overlap) {
  const int channels = templ.channels;
  Match match;
  double best_score = -2;
  int best_n = 0;
  for (int n = n_lo; n <= n_hi; ++n) {
    const int y0 = std::max(templ.first + n, current.first);
    const int y1 = std::min(templ.last() + n, current.last());
    if (y1 - y0 + 1 < min_overlap) continue;
    double st = 0, sp = 0, stt = 0, spp = 0, stp = 0;
    const float* t = templ.at(y0 - n);
    const float* p = current.at(y0);
    const int count = (y1 - y0 + 1) * channels;
    for (int i = 0; i < count; ++i) {
      const double tv = t[i], pv = p[i];
      st += tv;
      sp += pv;
      stt += tv * tv;
      spp += pv * pv;
      stp += tv * pv;
    }
    const double var_t = stt - st * st / count, var_p = spp - sp * sp / count;
    if (var_t <= 1e-6 * count || var_p <= 1e-6 * count) continue;
    const double score = (stp - st * sp / count) / std::sqrt(var_t * var_p);
    if (score > best_score) {
      best_score = score;
      best_n = n;
    }
  }
  if (best_score < -1) return match;
  match.at_limit = best_n == n_lo || best_n == n_hi;

  // rows where template(y - n - 1) .. template(y - n + 1) all exist
  const int y0 = std::max(templ.first + best_n + 1, current.first);
  const int y1 = std::min(templ.last() + best_n - 1, current.last());
  if (y1 - y0 + 1 < std::max(3, min_overlap - 2)) {
    match.shift = best_n;
    match.quality = std::max(0.0, best_score);
    match.found = true;
    return match;
  }
  const int count = (y1 - y0 + 1) * channels;
  const float* p = current.at(y0);
  double sp = 0, spp = 0;
  for (int i = 0; i < count; ++i) {
    const double pv = p[i];
    sp += pv;
    spp += pv * pv;
  }
  const double sst = std::max(1e-9, spp - sp * sp / count);

  // integer shifts: current = a * template(y - k) + c
  double best_sse = std::numeric_limits<double>::infinity();
  double best_shift = best_n;
  for (int k = best_n - 1; k <= best_n + 1; ++k) {
    const float* t = templ.at(y0 - k);
    double st = 0, stt = 0, stp = 0;
    for (int i = 0; i < count; ++i) {
      const double tv = t[i], pv = p[i];
      st += tv;
      stt += tv * tv;
      stp += tv * pv;
    }
    const double var_t = stt - st * st / count;
    if (var_t <= 0) continue;
    const double cov = stp - st * sp / count;
    if (cov <= 0) continue;
    const double sse = sst - cov * cov / var_t;
    if (sse < best_sse) {
      best_sse = sse;
      best_shift = k;
    }
  }
  // pixel intervals [m, m + 1]: current = alpha template(y - m) + beta template(y - m - 1) + c
  for (int m = best_n - 1; m <= best_n; ++m) {
    const float* a = templ.at(y0 - m);
    const float* b = templ.at(y0 - m - 1);
    double saa = 0, sab = 0, sbb = 0, sa = 0, sb = 0, sap = 0, sbp = 0;
    for (int i = 0; i < count; ++i) {
      const double av = a[i], bv = b[i], pv = p[i];
      saa += av * av;
      sab += av * bv;
      sbb += bv * bv;
      sa += av;
      sb += bv;
      sap += av * pv;
      sbp += bv * pv;
    }
    std::array<double, 3> x{};
    if (!Solve3({{{saa, sab, sa}, {sab, sbb, sb}, {sa, sb, static_cast<double>(count)}}},
                {sap, sbp, sp}, x)) {
      continue;
    }
    const double gain = x[0] + x[1];
    if (gain <= 0) continue;
    const double fraction = x[1] / gain;
    if (fraction <= 0 || fraction >= 1) continue;
    const double sse = spp - (x[0] * sap + x[1] * sbp + x[2] * sp);
    if (sse < best_sse) {
      best_sse = sse;
      best_shift = m + fraction;
    }
  }
  if (!std::isfinite(best_sse)) return match;
  match.shift = best_shift;
  match.quality = std::clamp(1.0 - best_sse / sst, 0.0, 1.0);
  match.found = true;
  return match;
}

// ---------------------------------------------------------------------------------------
// locating the foot in the first frame

// A region's B + G + R per pixel, rows x columns (row-major).
struct GreyPatch {
  cv::Rect rect;
  std::vector<float> grey;
  float at(int x, int y) const { return grey[Index((y - rect.y) * rect.width + (x - rect.x))]; }
};

GreyPatch GreyOf(const cv::Mat& bgr, const cv::Rect& rect) {
  GreyPatch patch;
  patch.rect = rect;
  patch.grey.resize(Index(rect.area()));
  for (int y = 0; y < rect.height; ++y) {
    const uint8_t* p = bgr.ptr<uint8_t>(rect.y + y) + Index(rect.x * 3);
    for (int x = 0; x < rect.width; ++x) {
      patch.grey[Index(y * rect.width + x)] =
          static_cast<float>(p[3 * x] + p[3 * x + 1] + p[3 * x + 2]);
    }
  }
  return patch;
}

// The nominal tape colours of the synthetic scenes, BGR (A blue, B orange, C purple, D red).
cv::Vec3d NominalTapeBgr(Foot foot) {
  switch (foot) {
    case Foot::kA: return {200, 80, 20};
    case Foot::kB: return {20, 140, 255};
    case Foot::kC: return {160, 40, 130};
    case Foot::kD: return {30, 30, 210};
  }
  return {128, 128, 128};
}

// How much a pixel looks like the tape: its chroma along the tape's hue minus half the
// tape's saturation times its brightness (grey levels; > 0 on the tape, < 0 on greys and
// on weakly saturated surfaces of the same hue such as wood).
struct TapeScorer {
  cv::Vec3d hue;  // unit chroma direction
  double saturation_cut = 0;
  explicit TapeScorer(Foot foot) {
    const cv::Vec3d tape = NominalTapeBgr(foot);
    const double mean = (tape[0] + tape[1] + tape[2]) / 3;
    const cv::Vec3d chroma = tape - cv::Vec3d::all(mean);
    hue = chroma / cv::norm(chroma);
    saturation_cut = 0.5 * cv::norm(chroma) / mean;
  }
  double operator()(const uint8_t* p) const {
    const double mean = (p[0] + p[1] + p[2]) / 3.0;
    const double along = (p[0] - mean) * hue[0] + (p[1] - mean) * hue[1] + (p[2] - mean) * hue[2];
    return along - saturation_cut * mean;
  }
};

// An edge in a 1-D signal: where the signed gradient peaks, refined as the centroid of the
// gradient around the peak (exact for an area-sampled step), and its strength.
struct Edge {
  double position = 0;
  double strength = 0;
  bool found = false;
};

// Gradient g[i] = v[i + 1] - v[i] sits at position first + i + 0.5.
Edge CentroidEdge(const std::vector<double>& values, int first, int peak, double sign) {
  Edge edge;
  double sum = 0, moment = 0;
  const int count = static_cast<int>(values.size());
  for (int i = std::max(0, peak - 2); i <= std::min(count - 2, peak + 2); ++i) {
    const double g = sign * (values[Index(i + 1)] - values[Index(i)]);
    if (g <= 0) continue;
    sum += g;
    moment += g * (first + i + 0.5);
  }
  if (sum <= 0) return edge;
  edge.position = moment / sum;
  edge.strength = sign * (values[Index(peak + 1)] - values[Index(peak)]);
  edge.found = true;
  return edge;
}

// The strongest gradient of the given sign among gradients i in [lo, hi] (indices into
// `values`); sign 0: either sign (the chosen one is returned in `sign`).
int StrongestGradient(const std::vector<double>& values, int lo, int hi, double& sign) {
  int best = -1;
  double best_value = 0;
  for (int i = std::max(0, lo); i <= std::min(static_cast<int>(values.size()) - 2, hi); ++i) {
    const double g = values[Index(i + 1)] - values[Index(i)];
    const double v = sign == 0 ? std::abs(g) : sign * g;
    if (v > best_value) {
      best_value = v;
      best = i;
    }
  }
  if (best >= 0 && sign == 0) sign = values[Index(best + 1)] - values[Index(best)] > 0 ? 1 : -1;
  return best;
}

// The first gradient of the given sign, scanning [lo, hi] upwards in index, that reaches
// 40 % of the strongest one there: where the foot ends (the ground's texture and the
// shadow's flank below it may be stronger, but they come after it).
int FirstStrongGradient(const std::vector<double>& values, int lo, int hi, double sign) {
  lo = std::max(0, lo);
  hi = std::min(static_cast<int>(values.size()) - 2, hi);
  double strongest = 0;
  for (int i = lo; i <= hi; ++i) {
    strongest = std::max(strongest, sign * (values[Index(i + 1)] - values[Index(i)]));
  }
  if (strongest <= 0) return -1;
  for (int i = lo; i <= hi; ++i) {
    if (sign * (values[Index(i + 1)] - values[Index(i)]) >= 0.4 * strongest) return i;
  }
  return -1;
}

struct FootGeometry {
  double center_x = 0;
  double width = 0;
  double bottom = 0;
  double polarity = 1;  // sign of (ground - foot) brightness
  bool by_tape = false;
};

// Left and right edges of the foot in the mean over `rows` of columns [x0, x1]: the
// strongest gradient left of `center` and the strongest of the opposite sign right of it.
bool SideEdges(const cv::Mat& bgr, int row_lo, int row_hi, int x0, int x1, double center,
               double& left, double& right, double& polarity) {
  row_lo = std::max(row_lo, 0);
  row_hi = std::min(row_hi, bgr.rows - 1);
  if (row_hi < row_lo || x1 - x0 < 6) return false;
  const AxisWindow rows = MakeWindow(row_lo - 0.5, row_hi + 0.5);
  Profile profile;
  RowMean(bgr, rows, x0, x1 - x0 + 1, profile);
  const std::vector<double> values(profile.values.begin(), profile.values.end());
  const int split = Round(center) - x0;
  double left_sign = 0;
  const int l = StrongestGradient(values, 0, split - 1, left_sign);
  if (l < 0) return false;
  double right_sign = -left_sign;
  const int r = StrongestGradient(values, split, static_cast<int>(values.size()) - 2, right_sign);
  if (r < 0) return false;
  const Edge le = CentroidEdge(values, x0, l, left_sign);
  const Edge re = CentroidEdge(values, x0, r, right_sign);
  if (!le.found || !re.found || re.position - le.position < 4) return false;
  left = le.position;
  right = re.position;
  polarity = right_sign;  // foot -> ground going right
  return true;
}

// The tape band in the region: its rows and its left and right ends.
bool TapeBand(const cv::Mat& bgr, const cv::Rect& region, Foot foot, double& left, double& right,
              int& band_top, int& band_bottom) {
  const TapeScorer scorer(foot);
  std::vector<double> score(Index(region.area()));
  std::vector<int> row_count(Index(region.height), 0);
  for (int y = 0; y < region.height; ++y) {
    const uint8_t* p = bgr.ptr<uint8_t>(region.y + y) + Index(region.x * 3);
    for (int x = 0; x < region.width; ++x) {
      const double s = scorer(p + 3 * x);
      score[Index(y * region.width + x)] = s;
      if (s > 0) ++row_count[Index(y)];
    }
  }
  const int best_row =
      static_cast<int>(std::max_element(row_count.begin(), row_count.end()) - row_count.begin());
  if (row_count[Index(best_row)] < 3) return false;
  // the band: the run of rows around the best one with at least half its count
  const int half = (row_count[Index(best_row)] + 1) / 2;
  band_top = best_row;
  band_bottom = best_row;
  while (band_top > 0 && row_count[Index(band_top - 1)] >= half) --band_top;
  while (band_bottom + 1 < region.height && row_count[Index(band_bottom + 1)] >= half) {
    ++band_bottom;
  }
  // the ends: half-level crossings of the mean score over the band's rows
  std::vector<double> columns(Index(region.width), 0.0);
  for (int y = band_top; y <= band_bottom; ++y) {
    for (int x = 0; x < region.width; ++x) columns[Index(x)] += score[Index(y * region.width + x)];
  }
  const int peak =
      static_cast<int>(std::max_element(columns.begin(), columns.end()) - columns.begin());
  const double top_level = columns[Index(peak)];
  int l = peak, r = peak;
  while (l > 0 && columns[Index(l - 1)] > 0.5 * top_level) --l;
  while (r + 1 < region.width && columns[Index(r + 1)] > 0.5 * top_level) ++r;
  if (l == 0 || r == region.width - 1) return false;  // cut by the region: not the band's ends
  // linear interpolation of the half level between the columns either side of each end
  const auto crossing = [&](int inside, int outside) {
    const double vi = columns[Index(inside)], vo = columns[Index(outside)];
    const double level = 0.5 * top_level;
    const double f = vi == vo ? 0.5 : (vi - level) / (vi - vo);
    return region.x + inside + f * (outside - inside);
  };
  left = crossing(l, l - 1);
  right = crossing(r, r + 1);
  band_top += region.y;
  band_bottom += region.y;
  return right - left >= 4;
}

// Bottom edge of the foot in the mean over columns [center - half, center + half]: the
// first strong foot-to-ground edge (sign `polarity` going down) among rows [lo, hi].
Edge BottomEdge(const cv::Mat& bgr, double center, double half, int lo, int hi, double polarity) {
  Edge edge;
  lo = std::max(lo, 2);
  hi = std::min(hi, bgr.rows - 3);
  if (hi <= lo) return edge;
  const AxisWindow columns = ClampWindow(MakeWindow(center - half, center + half), bgr.cols);
  Profile profile;
  ColumnMean(bgr, columns, lo - 2, hi - lo + 5, 1, profile);
  const std::vector<double> values(profile.values.begin(), profile.values.end());
  const int first = FirstStrongGradient(values, 2, hi - lo + 2, polarity);
  if (first < 0) return edge;
  // the edge's position: the centroid of this gradient and the one before it (an
  // area-sampled edge spreads over two), not of the ones after (the shadow's flank)
  const double g0 = std::max(0.0, polarity * (values[Index(first)] - values[Index(first - 1)]));
  const double g1 = polarity * (values[Index(first + 1)] - values[Index(first)]);
  edge.position = lo - 2 + first + 0.5 - g0 / (g0 + g1);
  edge.strength = g1;
  edge.found = true;
  return edge;
}

// ---------------------------------------------------------------------------------------
// the shake references

struct ReferencePatch {
  cv::Rect rect;       // in the first frame
  Profile vertical;    // column mean (B + G + R) of its rows
  Profile horizontal;  // row mean of its columns
  double dx = 0, dy = 0;
  double quality = 0;
};

// Texture of a patch for vertical and horizontal registration: the mean squared gradient
// of its column-mean and row-mean profiles, (B + G + R)^2 per px^2.
std::pair<double, double> PatchTexture(const GreyPatch& grey, const cv::Rect& rect) {
  std::vector<double> rows(Index(rect.height), 0.0), cols(Index(rect.width), 0.0);
  for (int y = 0; y < rect.height; ++y) {
    for (int x = 0; x < rect.width; ++x) {
      const double v = grey.at(rect.x + x, rect.y + y);
      rows[Index(y)] += v / rect.width;
      cols[Index(x)] += v / rect.height;
    }
  }
  const auto energy = [](const std::vector<double>& values) {
    double sum = 0;
    for (size_t i = 0; i + 1 < values.size(); ++i) {
      sum += (values[i + 1] - values[i]) * (values[i + 1] - values[i]);
    }
    return values.size() > 1 ? sum / static_cast<double>(values.size() - 1) : 0.0;
  };
  return {energy(rows), energy(cols)};
}

// Up to three textured patches of the scene near the foot that avoid the foot, the leg
// above it, its shadow and the foot region (with room for the shake search). The shake is
// their median, so one of them may hold something that moves (another foot, the LED).
std::vector<cv::Rect> ChooseReferencePatches(const cv::Mat& bgr, const FootGeometry& foot,
                                             const cv::Rect& foot_roi) {
  const int size = std::clamp(Round(foot.width), 16, 48);
  const int margin = kMaxShakePx + 2;
  const cv::Rect usable(margin, margin, bgr.cols - 2 * margin, bgr.rows - 2 * margin);
  const cv::Rect search =
      cv::Rect(Floor(foot.center_x - 5 * foot.width), Floor(foot.bottom - 1.5 * foot.width),
               Ceil(10 * foot.width), Ceil(4.5 * foot.width)) &
      usable;
  if (search.width < size || search.height < size) return {};
  // the foot, its leg up to the top of the picture and its shadow, with room to spare
  const cv::Rect foot_zone(Floor(foot.center_x - 1.15 * foot.width), 0, Ceil(2.3 * foot.width) + 1,
                           Ceil(foot.bottom + 0.5 * foot.width));
  const cv::Rect roi_zone(foot_roi.x - margin, foot_roi.y - margin, foot_roi.width + 2 * margin,
                          foot_roi.height + 2 * margin);
  const GreyPatch grey = GreyOf(bgr, search);

  struct Candidate {
    cv::Rect rect;
    double score;
  };
  std::vector<Candidate> candidates;
  const int stride = std::max(4, size / 2);
  for (int y = search.y; y + size <= search.y + search.height; y += stride) {
    for (int x = search.x; x + size <= search.x + search.width; x += stride) {
      const cv::Rect rect(x, y, size, size);
      if ((rect & foot_zone).area() > 0 || (rect & roi_zone).area() > 0) continue;
      const auto [vertical, horizontal] = PatchTexture(grey, rect);
      // grey levels (B + G + R): 0.5 levels per px of mean grey is too smooth to register
      if (vertical < 2.25 || horizontal < 0.5) continue;
      const double dx = x + size / 2.0 - foot.center_x;
      const double dy = y + size / 2.0 - foot.bottom;
      const double distance = std::sqrt(dx * dx + dy * dy);
      candidates.push_back(
          {rect, std::min(vertical, 4 * horizontal) / (1 + distance / (4 * foot.width))});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  std::vector<cv::Rect> chosen;
  for (const Candidate& candidate : candidates) {
    const bool overlaps = std::any_of(chosen.begin(), chosen.end(), [&](const cv::Rect& other) {
      return (other & candidate.rect).area() > 0;
    });
    if (overlaps) continue;
    chosen.push_back(candidate.rect);
    if (chosen.size() == 3) break;
  }
  return chosen;
}

}  // namespace

// ---------------------------------------------------------------------------------------
// options and results

Status FootTracker::Options::Validate() const {
  if (foot_roi_px.width < 8 || foot_roi_px.height < 8) {
    return InvalidArgumentError("foot_roi_px: expected at least 8 x 8 px, got " +
                                std::to_string(foot_roi_px.width) + " x " +
                                std::to_string(foot_roi_px.height));
  }
  if (!(threshold_px >= 0) || !std::isfinite(threshold_px)) {
    return InvalidArgumentError("threshold_px: expected >= 0 (0: use threshold_mm), got " +
                                FormatFixed(threshold_px, 3));
  }
  if (threshold_px == 0 && (!(threshold_mm > 0) || !std::isfinite(threshold_mm))) {
    return InvalidArgumentError("threshold_mm: expected > 0, got " + FormatFixed(threshold_mm, 3));
  }
  if (!(px_per_mm >= 0) || !std::isfinite(px_per_mm)) {
    return InvalidArgumentError("px_per_mm: expected >= 0 (0: estimate it), got " +
                                FormatFixed(px_per_mm, 3));
  }
  if (!(foot_width_mm > 0) || !std::isfinite(foot_width_mm)) {
    return InvalidArgumentError("foot_width_mm: expected > 0, got " +
                                FormatFixed(foot_width_mm, 3));
  }
  if (rest_frames < 2) {
    return InvalidArgumentError("rest_frames: expected >= 2, got " + std::to_string(rest_frames));
  }
  if (!reference_roi_px.empty() && (reference_roi_px.width < 8 || reference_roi_px.height < 8)) {
    return InvalidArgumentError("reference_roi_px: expected empty or at least 8 x 8 px, got " +
                                std::to_string(reference_roi_px.width) + " x " +
                                std::to_string(reference_roi_px.height));
  }
  if (!(compression_error_px >= 0) || !(compression_error_px <= 10)) {
    return InvalidArgumentError("compression_error_px: expected 0 .. 10, got " +
                                FormatFixed(compression_error_px, 3));
  }
  if (!(exposure_s >= 0) || !(exposure_s <= 10)) {
    return InvalidArgumentError("exposure_s: expected 0 (unknown) .. 10, got " +
                                FormatFixed(exposure_s, 6));
  }
  if (confirm_frames < 1) {
    return InvalidArgumentError("confirm_frames: expected >= 1, got " +
                                std::to_string(confirm_frames));
  }
  if (!(min_quality >= 0 && min_quality <= 1)) {
    return InvalidArgumentError("min_quality: expected 0 .. 1, got " + FormatFixed(min_quality, 3));
  }
  return Status::Ok();
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
// the tracker

struct FootTracker::Impl {
  Options options;
  Status options_status;
  int64_t rest_from_ns = 0, rest_to_ns = 0;

  bool initialised = false;
  cv::Size frame_size;
  FootGeometry foot;
  double columns_half = 0;
  Profile foot_template;
  std::vector<ReferencePatch> patches;
  std::vector<std::string> warnings;

  // the last frame's state
  double shake_x = 0, shake_y = 0;
  double last_rise = 0, rise_before_last = 0;
  int64_t last_t_ns = 0;
  std::vector<HeightSample> samples;
  Profile scratch;

  void Initialise(const cv::Mat& bgr);
  void MeasureShake(const cv::Mat& bgr);
  HeightSample MeasureFoot(const cv::Mat& bgr);
  bool MeasurePatch(const cv::Mat& bgr, ReferencePatch& patch, int radius, bool& at_limit);
};

void FootTracker::Impl::Initialise(const cv::Mat& bgr) {
  const cv::Rect& roi = options.foot_roi_px;
  const cv::Rect image(0, 0, bgr.cols, bgr.rows);
  const int roi_bottom = roi.y + roi.height - 1;
  const int extra = Round(0.3 * roi.width);
  const int x0 = std::max(0, roi.x - extra),
            x1 = std::min(bgr.cols - 1, roi.x + roi.width - 1 + extra);

  // where the foot is across: the tape band's ends, or the foot's side edges
  foot.center_x = roi.x + (roi.width - 1) / 2.0;
  foot.width = 0.75 * roi.width;
  double band_top_row = -1, band_bottom_row = -1;
  if (options.tape_colour) {
    double left = 0, right = 0;
    int top = 0, bottom = 0;
    const cv::Rect region = cv::Rect(x0, roi.y, x1 - x0 + 1, roi.height) & image;
    if (TapeBand(bgr, region, *options.tape_colour, left, right, top, bottom)) {
      foot.center_x = 0.5 * (left + right);
      foot.width = right - left;
      foot.by_tape = true;
      band_top_row = top;
      band_bottom_row = bottom;
    } else {
      warnings.push_back("tape colour of foot " + std::string(FootName(*options.tape_colour)) +
                         " (" + std::string(FootTapeColour(*options.tape_colour)) +
                         ") not found in the foot region: located by brightness edges");
    }
  }
  double left = 0, right = 0, polarity = 1;
  bool sides = false;
  if (foot.by_tape) {
    sides = SideEdges(bgr, Round(band_top_row), Round(band_bottom_row), x0, x1, foot.center_x, left,
                      right, polarity);
  } else {
    sides = SideEdges(bgr, roi.y + roi.height / 2, roi_bottom - Round(0.15 * roi.width), x0, x1,
                      foot.center_x, left, right, polarity);
    if (sides) {
      foot.center_x = 0.5 * (left + right);
      foot.width = right - left;
    }
  }
  foot.polarity = sides ? polarity : 1.0;

  // the bottom edge: the first strong foot-to-ground edge near the region's bottom (below
  // the tape band when there is one)
  int lo = roi_bottom - Round(0.3 * foot.width) - 2, hi = roi_bottom + 3;
  if (foot.by_tape) {
    const double band = band_bottom_row - band_top_row + 1;
    lo = Round(band_bottom_row + 0.3 * band);
    hi = std::max(hi, Round(band_bottom_row + 1.7 * band) + 2);
  }
  Edge bottom =
      BottomEdge(bgr, foot.center_x, kColumnsHalfFraction * foot.width, lo, hi, foot.polarity);
  if (!bottom.found) {
    warnings.push_back("the foot's bottom edge is unclear: the foot region's bottom is used");
    bottom.position = roi_bottom + 0.5 - 0.1 * foot.width;
  }
  foot.bottom = bottom.position;

  // the width again, from the brightness edges on rows where the foot is at its widest (the
  // tape's colour edges are blurred by chroma subsampling); with the tape, only when they
  // agree with the tape's ends
  {
    const double w = foot.width;
    if (SideEdges(bgr, Round(foot.bottom - 0.55 * w), Round(foot.bottom - 0.3 * w), x0, x1,
                  foot.center_x, left, right, polarity) &&
        (!foot.by_tape || std::abs(right - left - w) < 0.25 * w)) {
      foot.center_x = 0.5 * (left + right);
      foot.width = right - left;
    } else if (!sides && !foot.by_tape) {
      warnings.push_back(
          "the foot's side edges are unclear: its width is taken as 75 % of the "
          "foot region's");
    }
  }

  // the template: the foot's central columns from one foot width above its bottom edge to
  // just above it
  columns_half = std::max(1.0, kColumnsHalfFraction * foot.width);
  const int first_row = std::max({roi.y, 0, Round(foot.bottom - foot.width)});
  const int last_row = std::min(Floor(foot.bottom - kTemplateBottomMarginPx), bgr.rows - 1);
  const AxisWindow columns =
      ClampWindow(MakeWindow(foot.center_x - columns_half, foot.center_x + columns_half), bgr.cols);
  ColumnMean(bgr, columns, first_row, std::max(0, last_row - first_row + 1), 3, foot_template);
  if (foot_template.length < 6) {
    warnings.push_back("the foot's template is only " + Plural(foot_template.length, "row") +
                       " tall: the foot region is too small or misplaced");
  }

  // the shake references
  std::vector<cv::Rect> rects;
  if (!options.reference_roi_px.empty()) {
    rects.push_back(options.reference_roi_px);
  } else {
    rects = ChooseReferencePatches(bgr, foot, roi);
    if (rects.empty()) {
      warnings.push_back("no textured ground beside the foot: camera shake is not removed");
    }
  }
  for (const cv::Rect& rect : rects) {
    ReferencePatch patch;
    patch.rect = rect;
    ColumnMean(bgr, MakeWindow(rect.x - 0.5, rect.x + rect.width - 0.5), rect.y, rect.height, 1,
               patch.vertical);
    RowMean(bgr, MakeWindow(rect.y - 0.5, rect.y + rect.height - 0.5), rect.x, rect.width,
            patch.horizontal);
    patches.push_back(std::move(patch));
  }
  initialised = true;
}

// Registers one patch: its horizontal shift on the rows moved by the last vertical one,
// then its vertical shift on the columns moved by the new horizontal one.
bool FootTracker::Impl::MeasurePatch(const cv::Mat& bgr, ReferencePatch& patch, int radius,
                                     bool& at_limit) {
  const cv::Rect& rect = patch.rect;
  const int cx = Round(patch.dx), cy = Round(patch.dy);
  const int n_lo_x = std::max(cx - radius, -rect.x + 1);
  const int n_hi_x = std::min(cx + radius, bgr.cols - rect.x - rect.width - 1);
  const int n_lo_y = std::max(cy - radius, -rect.y + 1);
  const int n_hi_y = std::min(cy + radius, bgr.rows - rect.y - rect.height - 1);
  if (n_lo_x > n_hi_x || n_lo_y > n_hi_y) return false;

  const AxisWindow rows = ClampWindow(
      MakeWindow(rect.y - 0.5 + patch.dy, rect.y + rect.height - 0.5 + patch.dy), bgr.rows);
  const int col_first = rect.x + n_lo_x - 1;
  RowMean(bgr, rows, col_first, rect.width + n_hi_x - n_lo_x + 2, scratch);
  const Match mx = Register(patch.horizontal, scratch, n_lo_x, n_hi_x, rect.width - radius);
  if (!mx.found) return false;

  const AxisWindow columns = ClampWindow(
      MakeWindow(rect.x - 0.5 + mx.shift, rect.x + rect.width - 0.5 + mx.shift), bgr.cols);
  const int row_first = rect.y + n_lo_y - 1;
  ColumnMean(bgr, columns, row_first, rect.height + n_hi_y - n_lo_y + 2, 1, scratch);
  const Match my = Register(patch.vertical, scratch, n_lo_y, n_hi_y, rect.height - radius);
  if (!my.found) return false;
  patch.dx = mx.shift;
  patch.dy = my.shift;
  patch.quality = std::min(mx.quality, my.quality);
  at_limit = mx.at_limit || my.at_limit;
  return true;
}

void FootTracker::Impl::MeasureShake(const cv::Mat& bgr) {
  if (patches.empty()) return;
  std::vector<double> xs, ys;
  for (ReferencePatch& patch : patches) {
    const double old_dx = patch.dx, old_dy = patch.dy;
    bool at_limit = false;
    bool ok = MeasurePatch(bgr, patch, kLocalSearchPx, at_limit);
    if (!ok || at_limit || patch.quality < kRetryQuality) {
      patch.dx = old_dx;
      patch.dy = old_dy;
      ok = MeasurePatch(bgr, patch, kMaxShakePx, at_limit);
    }
    if (ok && patch.quality >= 0.3) {
      xs.push_back(patch.dx);
      ys.push_back(patch.dy);
    } else {
      patch.dx = old_dx;
      patch.dy = old_dy;
    }
  }
  if (ys.empty()) return;  // keep the last shake
  shake_x = MedianOf(xs);
  shake_y = MedianOf(ys);
}

// The foot's vertical shift in the picture, searched first around where the last two
// rises and the shake put it, then over every shift when that fails.
HeightSample FootTracker::Impl::MeasureFoot(const cv::Mat& bgr) {
  HeightSample sample;
  sample.shake_y_px = shake_y;
  if (foot_template.length < 3) {
    sample.quality = 0;
    return sample;
  }
  const AxisWindow columns = ClampWindow(
      MakeWindow(foot.center_x - columns_half + shake_x, foot.center_x + columns_half + shake_x),
      bgr.cols);
  const int min_overlap = std::max(3, foot_template.length / 2);
  const auto search = [&](int n_lo, int n_hi) {
    const int first = std::max(0, foot_template.first + n_lo - 1);
    const int last = std::min(bgr.rows - 1, foot_template.last() + n_hi + 1);
    ColumnMean(bgr, columns, first, last - first + 1, 3, scratch);
    return Register(foot_template, scratch, n_lo, n_hi, min_overlap);
  };
  const int predicted = Round(shake_y - (2 * last_rise - rise_before_last));
  Match match = search(predicted - kLocalSearchPx, predicted + kLocalSearchPx);
  if (!match.found || match.at_limit || match.quality < kRetryQuality) {
    const Match wide = search(-(foot_template.last() - min_overlap + 1), kMaxShakePx);
    if (wide.found && (!match.found || wide.quality > match.quality)) match = wide;
  }
  if (!match.found) {
    sample.quality = 0;
    sample.rise_px = last_rise;
    return sample;
  }
  sample.rise_px = shake_y - match.shift;
  sample.quality = match.quality;
  rise_before_last = last_rise;
  last_rise = sample.rise_px;
  return sample;
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
  if (!s.initialised) {
    const cv::Rect& roi = s.options.foot_roi_px;
    if ((roi & image) != roi) {
      return InvalidArgumentError("foot ROI " + RectText(roi) + " is outside the " + size_text +
                                  " frame");
    }
    const cv::Rect& reference = s.options.reference_roi_px;
    if (!reference.empty() && (reference & image) != reference) {
      return InvalidArgumentError("reference ROI " + RectText(reference) + " is outside the " +
                                  size_text + " frame");
    }
    s.frame_size = bgr.size();
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
    if (!s.initialised) s.Initialise(bgr);
    s.MeasureShake(bgr);
    HeightSample sample = s.MeasureFoot(bgr);
    sample.frame_index = frame.index;
    sample.t_ns = frame.t_ns;
    s.samples.push_back(sample);
    s.last_t_ns = frame.t_ns;
  } catch (const cv::Exception& e) {
    return InvalidArgumentError("frame " + std::to_string(frame.index) + ": " + e.what());
  }
  return Status::Ok();
}

namespace {

// The hinge r0 + b * max(0, t - t0)^p, least squares for a given knee t0 and power p.
struct Hinge {
  double t0_s = 0, power = 1, level = 0, gain = 0;
  double sse = std::numeric_limits<double>::infinity();
  // First instant the hinge exceeds `height`, s (+inf when it never does).
  double CrossingS(double height) const {
    if (height <= level) return t0_s;
    if (gain <= 0) return std::numeric_limits<double>::infinity();
    return t0_s + std::pow((height - level) / gain, 1 / power);
  }
};

Hinge FitHinge(const std::vector<double>& t_s, const std::vector<double>& y, double t0_s,
               double power) {
  Hinge hinge;
  hinge.t0_s = t0_s;
  hinge.power = power;
  double sx = 0, sxx = 0, sy = 0, sxy = 0, syy = 0;
  const double n = static_cast<double>(y.size());
  for (size_t i = 0; i < y.size(); ++i) {
    const double x = t_s[i] > t0_s ? std::pow(t_s[i] - t0_s, power) : 0.0;
    sx += x;
    sxx += x * x;
    sy += y[i];
    sxy += x * y[i];
    syy += y[i] * y[i];
  }
  const double var_y = syy - sy * sy / n;
  const double var_x = sxx - sx * sx / n;
  const double cov = sxy - sx * sy / n;
  if (var_x <= 0 || cov <= 0) {  // no rise: the flat line
    hinge.level = sy / n;
    hinge.sse = var_y;
    return hinge;
  }
  hinge.gain = cov / var_x;
  hinge.level = (sy - hinge.gain * sx) / n;
  hinge.sse = var_y - cov * cov / var_x;
  return hinge;
}

}  // namespace

Result<FootTrack> FootTracker::Finish() const& {
  Result<FootTrack> track = FinishWithoutSamples();
  if (track.ok()) track->samples = impl_->samples;
  return track;
}

Result<FootTrack> FootTracker::Finish() && {
  Result<FootTrack> track = FinishWithoutSamples();
  if (track.ok()) track->samples = std::move(impl_->samples);
  return track;
}

Result<FootTrack> FootTracker::FinishWithoutSamples() const {
  const Impl& s = *impl_;
  if (!s.options_status.ok()) return s.options_status;
  if (s.samples.empty()) return InvalidArgumentError("no frame was given to the foot tracker");
  const Options& o = s.options;
  const std::vector<HeightSample>& samples = s.samples;

  FootTrack track;
  track.foot_roi_px = o.foot_roi_px;
  for (const ReferencePatch& patch : s.patches) {
    track.reference_patches_px.push_back(patch.rect);
    track.reference_roi_px =
        track.reference_roi_px.empty() ? patch.rect : (track.reference_roi_px | patch.rect);
  }
  track.foot_center_x_px = s.foot.center_x;
  track.foot_width_px = s.foot.width;
  track.foot_bottom_px = s.foot.bottom;
  track.template_first_row = s.foot_template.first;
  track.template_last_row = s.foot_template.last();
  track.located_by_tape = s.foot.by_tape;
  track.warnings = s.warnings;
  // a "foot" nearly as wide as its region is most likely the region's own edges
  std::string region_warning;
  if (s.foot.width > kWideFootFraction * o.foot_roi_px.width) {
    region_warning = "the located foot is " + FormatFixed(s.foot.width, 0) + " px wide, " +
                     FormatFixed(100 * s.foot.width / o.foot_roi_px.width, 0) +
                     " % of the foot region's width: the region is probably far too large "
                     "(give one around the foot only)";
    track.warnings.push_back(region_warning);
  }

  // frame interval and the mid-exposure offset
  std::vector<double> steps;
  for (size_t i = 1; i < samples.size(); ++i) {
    steps.push_back(static_cast<double>(samples[i].t_ns - samples[i - 1].t_ns));
  }
  const double interval_ns = steps.empty() ? 1e9 / 30 : MedianOf(std::move(steps));
  double offset_ns = 0, offset_uncertainty_ns = 0;
  if (o.exposure_s > 0) {
    offset_ns = 0.5 * o.exposure_s * 1e9;
  } else {
    offset_ns = 0.25 * interval_ns;
    offset_uncertainty_ns = 0.25 * interval_ns;
  }
  track.exposure_offset_ns = RoundNs(offset_ns);

  const auto good = [&](size_t i) { return samples[i].quality >= o.min_quality; };
  for (size_t i = 0; i < samples.size(); ++i) {
    if (!good(i)) ++track.poor_frames;
  }
  if (track.poor_frames > 0) {
    track.warnings.push_back(Plural(track.poor_frames, "frame") +
                             " with a poor match of the foot (quality < " +
                             FormatFixed(o.min_quality, 2) + ") left out");
  }

  // the rest window
  std::vector<size_t> rest;
  size_t rest_start = 0;
  if (s.rest_to_ns > s.rest_from_ns) {
    rest_start = samples.size();
    for (size_t i = 0; i < samples.size(); ++i) {
      if (samples[i].t_ns < s.rest_from_ns) continue;
      rest_start = std::min(rest_start, i);
      if (samples[i].t_ns < s.rest_to_ns && good(i)) rest.push_back(i);
    }
    if (rest.empty()) {
      return InvalidArgumentError("the rest window " + FormatSeconds(s.rest_from_ns, 4) + " .. " +
                                  FormatSeconds(s.rest_to_ns, 4) +
                                  " s holds no frame with a clear view of the foot");
    }
  } else {
    for (size_t i = 0; i < samples.size() && rest.size() < static_cast<size_t>(o.rest_frames);
         ++i) {
      if (good(i)) rest.push_back(i);
    }
    if (rest.empty()) return NotFoundError("no frame shows the foot clearly");
  }
  double sum = 0, sum2 = 0;
  for (size_t i : rest) sum += samples[i].rise_px;
  track.rest_rise_px = sum / static_cast<double>(rest.size());
  for (size_t i : rest) sum2 += std::pow(samples[i].rise_px - track.rest_rise_px, 2);
  track.rest_noise_px =
      rest.size() > 1 ? std::sqrt(sum2 / static_cast<double>(rest.size() - 1)) : 0.0;
  if (rest.size() < 3) {
    track.warnings.push_back("the rest window holds only " +
                             Plural(static_cast<int64_t>(rest.size()), "frame") +
                             ": the rest level is uncertain");
  }
  // noise floor: sub-pixel registration is not better than ~0.01 px, whatever the frames say
  const double noise_px = std::max(track.rest_noise_px, 0.01);
  const double rest_error_px = noise_px / std::sqrt(static_cast<double>(rest.size()));

  // the threshold
  if (o.threshold_px > 0) {
    track.threshold_px = o.threshold_px;
    track.px_per_mm = o.px_per_mm;
  } else {
    if (o.px_per_mm > 0) {
      track.px_per_mm = o.px_per_mm;
    } else {
      track.px_per_mm = s.foot.width / o.foot_width_mm;
      track.px_per_mm_estimated = true;
    }
    track.threshold_px = o.threshold_mm * track.px_per_mm;
  }
  const double threshold = track.threshold_px;
  const auto excess = [&](size_t i) { return samples[i].rise_px - track.rest_rise_px; };

  // the first sustained crossing
  std::vector<size_t> valid;  // good samples from the rest window's start
  for (size_t i = rest_start; i < samples.size(); ++i) {
    if (good(i)) valid.push_back(i);
  }
  track.max_rise_px = 0;
  for (size_t i : valid) track.max_rise_px = std::max(track.max_rise_px, excess(i));
  std::optional<size_t> crossing;  // position in `valid`
  for (size_t k = 0; k < valid.size(); ++k) {
    if (excess(valid[k]) <= threshold) continue;
    // sustained: the next frames (as many as the clip still has) stay above
    const size_t need = std::min(static_cast<size_t>(o.confirm_frames), valid.size() - k);
    size_t above = 0;
    while (above < need && excess(valid[k + above]) > threshold) ++above;
    if (above == need) {
      crossing = k;
      break;
    }
  }
  const std::string threshold_text =
      FormatFixed(threshold, 2) + " px" +
      (track.px_per_mm > 0 && o.threshold_px == 0
           ? " (" + FormatFixed(o.threshold_mm, 2) + " mm" +
                 (track.px_per_mm_estimated ? ", scale estimated" : "") + ")"
           : "");
  if (!crossing) {
    return NotFoundError("the foot never lifts: its largest rise is " +
                         FormatFixed(track.max_rise_px, 2) + " px above rest, below the " +
                         threshold_text + " threshold" +
                         (region_warning.empty() ? std::string() : "; " + region_warning));
  }
  const size_t k = *crossing;
  const auto t_of = [&](size_t i) {  // mid-exposure, ns
    return static_cast<double>(samples[i].t_ns) + offset_ns;
  };
  if (samples[valid[k]].t_ns < s.rest_to_ns) {
    track.warnings.push_back(
        "the foot rose above the threshold inside the rest window: the rest "
        "level is suspect");
  }

  // the local estimate: a line through the two frames either side of the crossing
  const size_t after = valid[k];
  const size_t before = k > 0 ? valid[k - 1] : after;
  const double origin = t_of(after);
  const double t_before = t_of(before) - origin;                  // ns, <= 0
  double local_ns = 0, local_spread_ns = interval_ns, slope = 0;  // slope: px per ns
  if (k == 0) {
    track.warnings.push_back("the foot was already above the threshold at the start");
  } else {
    double st = 0, sy = 0, stt = 0, sty = 0, n = 0;
    for (size_t j = (k >= 2 ? k - 2 : 0); j < std::min(valid.size(), k + 2); ++j) {
      const double t = t_of(valid[j]) - origin;
      st += t;
      sy += excess(valid[j]);
      stt += t * t;
      sty += t * excess(valid[j]);
      n += 1;
    }
    const double mean_t = st / n;
    const double var_t = stt - st * st / n;
    slope = var_t > 0 ? (sty - st * sy / n) / var_t : 0;
    if (slope > 0) {
      local_ns = std::clamp((threshold - (sy / n - slope * mean_t)) / slope, t_before, 0.0);
    } else {  // a line between the two bracketing frames
      const double e0 = excess(before), e1 = excess(after);
      slope = (e1 - e0) / -t_before;
      local_ns = t_before + (threshold - e0) / (e1 - e0) * -t_before;
    }
    // the line's standard error and the rest level's, over the slope (two deviations)
    const double line_error_px =
        noise_px *
        std::sqrt(1 / n + (var_t > 0 ? (local_ns - mean_t) * (local_ns - mean_t) / var_t : 0));
    local_spread_ns = std::min(2 * std::hypot(line_error_px, rest_error_px) / slope, -t_before);
  }

  // the hinge: flat, then rising as a power of the time since the knee, fitted from the rest
  // window (at most 6 s before the crossing) to where the foot is 5 thresholds up (at least
  // 6 frames past the crossing, at most 2 s); its knee is the onset and it smooths the
  // crossing over compression's stepwise updates of a slowly moving picture
  size_t end = k;
  while (end + 1 < valid.size() &&
         (end < k + 6 || excess(valid[end]) < kFitEndThresholds * threshold) &&
         t_of(valid[end + 1]) - origin <= 2e9) {
    ++end;
  }
  size_t begin = k;
  while (begin > 0 && origin - t_of(valid[begin - 1]) <= 6e9) --begin;
  std::vector<double> fit_t, fit_y;
  for (size_t j = begin; j <= end; ++j) {
    fit_t.push_back((t_of(valid[j]) - origin) / 1e9);
    fit_y.push_back(excess(valid[j]));
  }
  const std::array<double, 7> powers = {1.0, 1.25, 1.5, 1.75, 2.0, 2.5, 3.0};
  std::vector<Hinge> hinges;
  Hinge best;
  const auto evaluate = [&](double t0_s) {
    for (double power : powers) {
      const Hinge hinge = FitHinge(fit_t, fit_y, t0_s, power);
      if (hinge.gain <= 0) continue;
      hinges.push_back(hinge);
      if (hinge.sse < best.sse) best = hinge;
    }
  };
  // coarse: every frame up to the crossing (at most 3 s before it); fine: a tenth of a
  // frame around the best
  for (size_t j = 0; j <= k - begin; ++j) {
    if (fit_t[j] >= -3.0) evaluate(fit_t[j]);
  }
  const double step_s = interval_ns / 1e9 / 10;
  if (std::isfinite(best.sse)) {
    const double coarse_best = best.t0_s;
    for (int i = -20; i <= 20; ++i) {
      const double t0 = coarse_best + i * step_s;
      if (t0 >= fit_t.front() && t0 <= 0) evaluate(t0);
    }
  }

  // how far the curve strays from the hinge near the crossing (noise, or a codec's lag)
  double wobble_px = 0;
  if (std::isfinite(best.sse)) {
    double sum_sq = 0, count = 0;
    for (size_t j = 0; j < fit_t.size(); ++j) {
      if (std::abs(fit_t[j]) > 6 * interval_ns / 1e9) continue;
      const double x = fit_t[j] > best.t0_s ? std::pow(fit_t[j] - best.t0_s, best.power) : 0.0;
      sum_sq += std::pow(fit_y[j] - best.level - best.gain * x, 2);
      count += 1;
    }
    wobble_px = count > 0 ? std::sqrt(sum_sq / count) : 0;
  }
  const double dof = std::max(1.0, static_cast<double>(fit_y.size()) - 4);
  const double variance =
      std::isfinite(best.sse) ? std::max(noise_px * noise_px, best.sse / dof) : noise_px * noise_px;

  // the hinge's crossing, when the hinge follows the curve near the crossing: it strays
  // from the frames there, and from the threshold at the local crossing, by less than half
  // the threshold (or three times the noise)
  double model_ns = local_ns, spread_ns = local_spread_ns;
  bool use_model = false;
  if (std::isfinite(best.sse)) {
    const double crossing_s = best.CrossingS(threshold);
    const double local_s = local_ns / 1e9;
    const double at_local_px =
        best.level +
        best.gain * (local_s > best.t0_s ? std::pow(local_s - best.t0_s, best.power) : 0.0);
    const double tolerance_px = std::max(0.5 * threshold, 3 * noise_px);
    if (wobble_px <= tolerance_px && std::abs(at_local_px - threshold) <= tolerance_px &&
        std::isfinite(crossing_s) && crossing_s >= fit_t.front() && crossing_s <= fit_t.back()) {
      use_model = true;
      model_ns = crossing_s * 1e9;
      const double since_knee_s = crossing_s - best.t0_s;
      if (since_knee_s > 0) {  // the hinge's slope there, px per ns
        slope = best.gain * best.power * std::pow(since_knee_s, best.power - 1) / 1e9;
      }
      // every hinge within two standard deviations of the best: the range of its crossings
      double lo = model_ns, hi = model_ns;
      for (const Hinge& hinge : hinges) {
        if (hinge.sse > best.sse + 4 * variance) continue;
        const double c = hinge.CrossingS(threshold) * 1e9;
        if (!std::isfinite(c)) continue;
        lo = std::min(lo, c);
        hi = std::max(hi, c);
      }
      spread_ns = std::max({model_ns - lo, hi - model_ns, step_s * 1e9});
      if (slope > 0) spread_ns = std::hypot(spread_ns, 2 * rest_error_px / slope);
    } else {
      track.warnings.push_back(
          "the rise does not follow a flat-then-rising curve near the threshold (rms " +
          FormatFixed(wobble_px, 2) + " px): the threshold instant is interpolated locally");
    }
  }
  // the mean lag a lossy codec leaves in slow sub-pixel motion: a sawtooth whose rms is the
  // misfit, so its mean is sqrt(3) times that, at most compression_error_px; it moves the
  // whole rise late and is independent of the fit's spread, so it adds in quadrature
  if (slope > 0) {
    const double codec_lag_px = std::min(o.compression_error_px, std::sqrt(3.0) * wobble_px);
    spread_ns = std::hypot(spread_ns, codec_lag_px / slope);
  }
  // systematic terms: the curve's misfit (not noise: it does not average out) and the scale's
  if (slope > 0) {
    spread_ns += wobble_px / slope;
    if (track.px_per_mm_estimated) spread_ns += kEstimatedScaleFraction * threshold / slope;
  }
  const double crossing_ns = origin + (use_model ? model_ns : local_ns);
  track.above_threshold.t_ns = RoundNs(crossing_ns);
  track.above_threshold.uncertainty_ns = RoundNs(spread_ns + offset_uncertainty_ns);

  // the onset: the best hinge's knee, its spread over the hinges within two deviations,
  // widened by the time the hinge takes to rise by three times the misfit (smaller rises are
  // lost in it: compression keeps a slowly starting foot still)
  TimedEvent onset;
  if (std::isfinite(best.sse)) {
    double lo = best.t0_s, hi = best.t0_s;
    for (const Hinge& hinge : hinges) {
      if (hinge.sse > best.sse + 4 * variance) continue;
      lo = std::min(lo, hinge.t0_s);
      hi = std::max(hi, hinge.t0_s);
    }
    const double hidden_s = std::pow(3 * std::max(noise_px, wobble_px) / best.gain, 1 / best.power);
    onset.t_ns = RoundNs(origin + best.t0_s * 1e9);
    onset.uncertainty_ns =
        RoundNs((std::max({best.t0_s - lo, hi - best.t0_s, step_s}) + hidden_s) * 1e9 +
                offset_uncertainty_ns);
  } else {
    onset = track.above_threshold;
    onset.uncertainty_ns += RoundNs(interval_ns);
    track.warnings.push_back(
        "no knee found in the height curve: the onset is the threshold "
        "instant");
  }

  // the frames either side of each instant
  const auto bracket = [&](TimedEvent& event) {
    event.frame_before = samples.front().frame_index;
    event.frame_after = samples.back().frame_index;
    for (size_t i = 0; i < samples.size(); ++i) {
      if (t_of(i) <= static_cast<double>(event.t_ns)) event.frame_before = samples[i].frame_index;
      if (t_of(i) > static_cast<double>(event.t_ns)) {
        event.frame_after = samples[i].frame_index;
        break;
      }
    }
  };
  bracket(track.above_threshold);
  bracket(onset);
  track.onset = onset;
  return track;
}

}  // namespace liftoff::video
