// Synthetic trials: the scene renderer. scene.h describes the picture and the recipe of a
// frame; this file builds the static scene once and composes each frame from it.
#include "liftoff/synth/scene.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>
#include <string>

#include <opencv2/imgproc.hpp>

#include "liftoff/core/random.h"
#include "liftoff/core/robot.h"
#include "liftoff/core/time.h"

namespace liftoff::synth {
namespace {

constexpr double kPi = std::numbers::pi;

// the view (metres, radians): see scene.h
constexpr double kFeetHalfLengthM = 0.324;  // 0.648 m between front and back feet
constexpr double kFeetHalfWidthM = 0.0755;  // 0.151 m between left and right feet
constexpr double kCameraDistanceM = 0.62;   // from the robot's centre plane
constexpr double kPitchRad = 8.0 * kPi / 180.0;
constexpr double kNearSpanFraction = 0.70;     // of the width, between near feet
constexpr double kNearFootRowFraction = 0.80;  // of the height, near feet's contact row
constexpr double kBedBackM = 1.15;             // depth of the bed's back edge (the wall)

// the foot, its collar and leg, mm in the foot's frame (u right of centre, w up)
constexpr double kFootWidthMm = 40, kFootHeightMm = 30;
constexpr double kFootBottomRadiusMm = 9, kFootTopRadiusMm = 4;
constexpr double kTapeLowMm = 10, kTapeHighMm = 20;
constexpr double kCollarHalfWidthMm = 10, kCollarLowMm = 27, kCollarHighMm = 38;
constexpr double kLegHalfWidthMm = 7;
constexpr double kFootRoiAboveMm = 40;

// shake and noise
constexpr double kShakeBoundPx = 4;
constexpr int kMarginPx = 6;  // canvas border: the shake bound plus room for bilinear
constexpr size_t kNoiseOffsets = 65536;

// seed streams
constexpr uint64_t kTextureStream = 1, kNoiseTableStream = 2, kFrameNoiseStream = 3,
                   kShakeStream = 4;

uint64_t SeedFor(uint64_t seed, uint64_t stream, uint64_t index = 0) {
  SplitMix64 first(seed ^ (stream * 0xD1B54A32D192ED03ull));
  SplitMix64 second(first.Next() ^ (index * 0x8CB92BA72F3D8DD7ull));
  return second.Next();
}

// ---------------------------------------------------------------------------------------
// procedural texture: hashed value noise

double Hash01(int64_t ix, int64_t iy, uint64_t salt) {
  SplitMix64 rng(salt ^ (static_cast<uint64_t>(ix) * 0x9E3779B97F4A7C15ull) ^
                 (static_cast<uint64_t>(iy) * 0xC2B2AE3D27D4EB4Full));
  return rng.Uniform();
}

double ValueNoise(double x, double y, uint64_t salt) {
  const double fx = std::floor(x), fy = std::floor(y);
  const auto ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  double tx = x - fx, ty = y - fy;
  tx = tx * tx * (3 - 2 * tx);
  ty = ty * ty * (3 - 2 * ty);
  const double h00 = Hash01(ix, iy, salt), h10 = Hash01(ix + 1, iy, salt);
  const double h01 = Hash01(ix, iy + 1, salt), h11 = Hash01(ix + 1, iy + 1, salt);
  const double top = h00 + tx * (h10 - h00);
  const double bottom = h01 + tx * (h11 - h01);
  return top + ty * (bottom - top);
}

// fractal sum of octaves, 0..1
double Fbm(double x, double y, uint64_t salt, int octaves) {
  double sum = 0, amplitude = 0.5, norm = 0;
  for (int i = 0; i < octaves; ++i) {
    sum += amplitude * ValueNoise(x, y, salt + static_cast<uint64_t>(i) * 7919);
    norm += amplitude;
    x *= 2.03;
    y *= 2.03;
    amplitude *= 0.5;
  }
  return sum / norm;
}

// fraction of the footprint [x - footprint/2, x + footprint/2] inside [low, high]
double BoxCoverage(double x, double footprint, double low, double high) {
  const double overlap = std::min(x + footprint / 2, high) - std::max(x - footprint / 2, low);
  return std::clamp(overlap / footprint, 0.0, 1.0);
}

// ---------------------------------------------------------------------------------------
// the camera: a pinhole pitched down, in a level frame (x along the robot towards its
// front, y up, z away from the camera)

struct Camera {
  double focal_px = 0, cx_px = 0, cy_px = 0;  // image px, centres at integers
  double height_m = 0;
  double sin_pitch = std::sin(kPitchRad), cos_pitch = std::cos(kPitchRad);

  // image px of a point at x, height y, depth z
  cv::Point2d Project(double x_m, double y_m, double z_m) const {
    const double dy = y_m - height_m;
    const double along = -dy * sin_pitch + z_m * cos_pitch;
    const double up = dy * cos_pitch + z_m * sin_pitch;
    return {cx_px + focal_px * x_m / along, cy_px - focal_px * up / along};
  }
  // depth along the optical axis of a ground point at depth z (for the scale there)
  double AxisDepth(double z_m) const { return height_m * sin_pitch + z_m * cos_pitch; }
  // the ray through an image point, level frame (not normalised)
  cv::Vec3d Ray(double u_px, double v_px) const {
    const double xc = (u_px - cx_px) / focal_px, yc = -(v_px - cy_px) / focal_px;
    return {xc, yc * cos_pitch - sin_pitch, yc * sin_pitch + cos_pitch};
  }
};

// Fixes the camera so the near feet span kNearSpanFraction of the width and stand on
// kNearFootRowFraction of the height.
Camera MakeCamera(int width_px, int height_px) {
  Camera camera;
  camera.cx_px = (width_px - 1) / 2.0;
  camera.cy_px = (height_px - 1) / 2.0;
  const double near_m = kCameraDistanceM - kFeetHalfWidthM;
  const double px_per_m_near = kNearSpanFraction * width_px / (2 * kFeetHalfLengthM);
  const double up_near_m =
      -(kNearFootRowFraction * height_px - camera.cy_px) / px_per_m_near;  // camera frame
  camera.height_m = (near_m * camera.sin_pitch - up_near_m) / camera.cos_pitch;
  camera.focal_px = px_per_m_near * camera.AxisDepth(near_m);
  return camera;
}

// ---------------------------------------------------------------------------------------
// the static background: bed, wall, vignette

struct BedTexture {
  uint64_t salt;
  double tape_near_m, tape_far_m;  // the white tape ruler, depth range
  double seam_z_m, seam_x_m;       // where the plywood sheets meet

  // colour (BGR 0..255) of the bed at (x, z), with the pixel footprint in x and z, m
  cv::Vec3d At(double x_m, double z_m, double footprint_x_m, double footprint_z_m) const {
    const int64_t sheet = (z_m > seam_z_m ? 2 : 0) + (x_m > seam_x_m ? 1 : 0);
    const auto sheet_salt = salt + static_cast<uint64_t>(sheet) * 101;
    const double tint = 0.10 * (Hash01(sheet, 0, salt) - 0.5);

    // rotary-cut veneer: growth rings along x, warped into wide wavy figures; the
    // detail fades where a pixel covers more than a ring (no aliasing far away)
    // flat-sawn figure: the sheet cuts the tree's rings at a height that drifts along x,
    // which draws the rings as nested arches ("cathedrals"), wavy from the warp
    const double ring_per_m = 45 + 25 * Hash01(sheet, 1, salt);
    const double pith_z_m = 0.5 + 0.6 * Hash01(sheet, 4, salt);
    const double cut_m = 0.03 + 0.05 * Fbm(x_m * 0.7, 0.5, sheet_salt + 5, 2) +
                         0.04 * std::sin(x_m * 2.1 + 6 * Hash01(sheet, 5, salt));
    const double radius_m = std::sqrt(cut_m * cut_m + (z_m - pith_z_m) * (z_m - pith_z_m));
    const double phase = radius_m * ring_per_m + 1.2 * Fbm(x_m * 1.6, z_m * 3, sheet_salt, 3) +
                         0.3 * Fbm(x_m * 8, z_m * 40, sheet_salt + 3, 2);
    const double g = 0.5 + 0.5 * std::sin(2 * kPi * phase);
    const double ring_px = std::max(footprint_z_m, 0.3 * footprint_x_m) * ring_per_m;
    const double detail = std::clamp(1.0 - (ring_px - 0.25) / 0.5, 0.0, 1.0);
    const double g2 = g * g, g8 = g2 * g2 * g2 * g2;
    const double bands = detail * 0.22 * (g - 0.5);
    const double lines = 0.16 * (detail * g8 + (1 - detail) * 0.1964);
    const double blotch = 0.14 * (Fbm(x_m * 4, z_m * 6, sheet_salt + 11, 3) - 0.5);
    const double speckle_detail = std::clamp(1.5 - footprint_x_m / 0.0015, 0.0, 1.0);
    const double speckle =
        0.08 * speckle_detail * (ValueNoise(x_m / 0.0011, z_m / 0.0011, salt + 13) - 0.5);
    double shade = (1 + tint) * (1 - bands - lines) * (1 + blotch) * (1 + speckle);

    // the sheets' seams: thin dark gaps
    const double seam = BoxCoverage(z_m - seam_z_m, footprint_z_m, -0.001, 0.001) +
                        BoxCoverage(x_m - seam_x_m, footprint_x_m, -0.001, 0.001);
    shade *= 1 - 0.6 * std::min(1.0, seam);
    cv::Vec3d colour = cv::Vec3d(128, 176, 214) * shade;

    // the tape ruler: off-white tape with ticks every 10 mm, longer every 50 mm
    const double tape = BoxCoverage(z_m, footprint_z_m, tape_near_m, tape_far_m);
    if (tape > 0) {
      const double tick_pos = x_m / 0.01;
      const double nearest = std::round(tick_pos);
      const double tick_x = (tick_pos - nearest) * 0.01;
      const bool long_tick = static_cast<int64_t>(nearest) % 5 == 0;
      const double tick_len_m = long_tick ? 0.014 : 0.007;
      const double tick = BoxCoverage(tick_x, footprint_x_m, -0.0005, 0.0005) *
                          BoxCoverage(z_m, footprint_z_m, tape_far_m - tick_len_m, tape_far_m);
      const cv::Vec3d tape_colour =
          cv::Vec3d(222, 228, 232) * ((1 - 0.82 * tick) * (1 + 0.5 * speckle));
      colour = colour * (1 - tape) + tape_colour * tape;
    }
    return colour;
  }
};

cv::Vec3d WallAt(double x_m, double height_m, uint64_t salt) {
  // dark cloth: soft vertical folds, blotches, darker towards the top
  const double folds =
      0.10 * std::sin(2 * kPi * (x_m / 0.11 + 0.8 * Fbm(x_m * 3, height_m * 1.2, salt + 21, 2)));
  const double blotch = 0.12 * (Fbm(x_m * 4, height_m * 4, salt + 23, 3) - 0.5);
  const double fall = 1.05 - 0.35 * std::clamp(height_m / 0.6, 0.0, 1.0);
  return cv::Vec3d(44, 41, 39) * ((1 + folds) * (1 + blotch) * fall);
}

// Renders the bed and the wall into a float canvas (canvas px = image px + margin).
void RenderBackground(const Camera& camera, int margin_px, uint64_t salt, double tape_near_m,
                      cv::Mat& canvas) {
  const BedTexture bed{salt, tape_near_m, tape_near_m + 0.025,
                       kBedBackM - 0.12 - 0.2 * Hash01(0, 0, salt + 5),
                       -0.6 + 1.2 * Hash01(0, 1, salt + 5)};
  const double wall_row = camera.Project(0, 0, kBedBackM).y;  // bed/wall boundary, image px
  for (int row = 0; row < canvas.rows; ++row) {
    const double v = row - margin_px;
    // depth of the ground along this row, and its footprint
    const auto ground_depth = [&](double v_px) {
      const cv::Vec3d ray = camera.Ray(camera.cx_px, v_px);
      if (ray[1] >= 0) return 1e9;
      return camera.height_m / -ray[1] * ray[2];
    };
    const double bed_fraction = std::clamp(v + 0.5 - wall_row, 0.0, 1.0);
    const double z_m = std::min(ground_depth(v), kBedBackM);
    const double footprint_z_m =
        std::max(1e-5, std::abs(std::min(ground_depth(v + 0.5), kBedBackM) -
                                std::min(ground_depth(v - 0.5), kBedBackM)));
    const cv::Vec3d row_ray = camera.Ray(camera.cx_px, v);
    const double bed_t = z_m / row_ray[2];  // ray length to the bed point (clamped at the wall)
    const double wall_t = kBedBackM / row_ray[2];
    auto* out = canvas.ptr<cv::Vec3f>(row);
    for (int col = 0; col < canvas.cols; ++col) {
      const double xc = (col - margin_px - camera.cx_px) / camera.focal_px;
      cv::Vec3d colour(0, 0, 0);
      if (bed_fraction > 0) {
        const double x_m = bed_t * xc;
        const double footprint_x_m = bed_t / camera.focal_px;
        // light from above the robot, a darker strip where the bed meets the wall
        const double light =
            (1.08 - 0.22 * (x_m * x_m / 0.64)) * (1 - 0.3 * std::exp(-(kBedBackM - z_m) / 0.035));
        colour += bed_fraction * light * bed.At(x_m, z_m, footprint_x_m, footprint_z_m);
      }
      if (bed_fraction < 1) {
        const double x_m = wall_t * xc;
        const double height_m = camera.height_m + wall_t * row_ray[1];
        colour += (1 - bed_fraction) * WallAt(x_m, height_m, salt);
      }
      out[col] = cv::Vec3f(colour);
    }
  }
}

void ApplyVignette(cv::Mat& canvas, int margin_px, const Camera& camera) {
  const double radius2 = camera.cx_px * camera.cx_px + camera.cy_px * camera.cy_px;
  for (int row = 0; row < canvas.rows; ++row) {
    const double dy = row - margin_px - camera.cy_px;
    auto* out = canvas.ptr<cv::Vec3f>(row);
    for (int col = 0; col < canvas.cols; ++col) {
      const double dx = col - margin_px - camera.cx_px;
      out[col] *= static_cast<float>(1.0 - 0.25 * (dx * dx + dy * dy) / radius2);
    }
  }
}

// ---------------------------------------------------------------------------------------
// feet and legs

cv::Vec3d TapeBgr(Foot foot) {
  const std::array<double, 3> bgr = FootTapeBgr(foot);
  return {bgr[0], bgr[1], bgr[2]};
}

struct FootShape {
  double center_x = 0, bottom = 0, px_per_mm = 0;  // canvas px
  cv::Vec3d tape;
};

FootShape ShapeOf(const SceneRenderer::FootPlacement& place, Foot foot) {
  return {place.center_x_px + kMarginPx, place.bottom_px + kMarginPx, place.px_per_mm,
          TapeBgr(foot)};
}

// Whether a canvas point lies on the foot, collar or leg, and its colour there. Rubber,
// collar and leg are neutral greys, so only the tape band carries colour.
bool FootColourAt(const FootShape& shape, double x, double y, cv::Vec3d& colour) {
  const double u = (x - shape.center_x) / shape.px_per_mm;
  const double w = (shape.bottom - y) / shape.px_per_mm;
  const double au = std::abs(u);
  const double half = kFootWidthMm / 2;
  const double across = std::cos(std::min(1.0, au / half) * kPi / 2);

  // the rubber block with rounded corners, and its tape band
  bool in_foot = au <= half && w >= 0 && w <= kFootHeightMm;
  if (in_foot && w < kFootBottomRadiusMm && au > half - kFootBottomRadiusMm) {
    const double du = au - (half - kFootBottomRadiusMm), dw = w - kFootBottomRadiusMm;
    in_foot = du * du + dw * dw <= kFootBottomRadiusMm * kFootBottomRadiusMm;
  }
  if (in_foot && w > kFootHeightMm - kFootTopRadiusMm && au > half - kFootTopRadiusMm) {
    const double du = au - (half - kFootTopRadiusMm), dw = w - (kFootHeightMm - kFootTopRadiusMm);
    in_foot = du * du + dw * dw <= kFootTopRadiusMm * kFootTopRadiusMm;
  }
  if (in_foot) {
    if (w >= kTapeLowMm && w <= kTapeHighMm) {
      colour = shape.tape * ((0.80 + 0.20 * across) *
                             (0.94 + 0.10 * (w - kTapeLowMm) / (kTapeHighMm - kTapeLowMm)));
    } else {
      colour = cv::Vec3d(40, 40, 40) * ((0.70 + 0.50 * w / kFootHeightMm) * (0.75 + 0.25 * across));
    }
    return true;
  }
  // the aluminium collar that holds the foot
  if (au <= kCollarHalfWidthMm && w >= kCollarLowMm && w <= kCollarHighMm) {
    const double c = std::cos(au / kCollarHalfWidthMm * kPi / 2);
    const double shine = std::exp(-std::pow((u / kCollarHalfWidthMm + 0.3) / 0.2, 2));
    colour = cv::Vec3d(118, 118, 118) * (0.5 + 0.5 * c) + cv::Vec3d(60, 60, 60) * shine;
    return true;
  }
  // the leg: a dark rod lit from the upper left
  if (au <= kLegHalfWidthMm && w >= kCollarLowMm) {
    const double c = std::cos(au / kLegHalfWidthMm * kPi / 2);
    const double shine = std::exp(-std::pow((u / kLegHalfWidthMm + 0.35) / 0.18, 2));
    colour = cv::Vec3d(68, 68, 68) * (0.45 + 0.6 * c) + cv::Vec3d(45, 45, 45) * shine;
    return true;
  }
  return false;
}

// Renders a foot's sprite over `region` (canvas px, starting at canvas row 0):
// premultiplied colour and coverage, 4 x 4 samples per pixel. Rows above the collar are
// all leg: one is rendered and copied up. Returns the first row that differs from row 0.
int RenderFootSprite(const FootShape& shape, const cv::Rect& region, cv::Mat& colour,
                     cv::Mat& alpha) {
  const int rows = static_cast<int>(std::floor(shape.bottom + 0.5)) + 1;  // + an empty row
  colour = cv::Mat(rows + 1, region.width, CV_32FC3, cv::Scalar::all(0));
  alpha = cv::Mat(rows + 1, region.width, CV_32FC1, cv::Scalar::all(0));
  const int uniform_rows = std::clamp(
      static_cast<int>(std::floor(shape.bottom - 0.5 - (kCollarHighMm + 1) * shape.px_per_mm)), 0,
      rows);
  constexpr int kSub = 4;
  for (int row = std::max(0, uniform_rows - 1); row < rows; ++row) {
    for (int col = 0; col < region.width; ++col) {
      cv::Vec3d sum(0, 0, 0);
      int inside = 0;
      for (int sy = 0; sy < kSub; ++sy) {
        for (int sx = 0; sx < kSub; ++sx) {
          const double x = region.x + col - 0.5 + (sx + 0.5) / kSub;
          const double y = row - 0.5 + (sy + 0.5) / kSub;
          cv::Vec3d c;
          if (FootColourAt(shape, x, y, c)) {
            sum += cv::Vec3d(std::min(c[0], 255.0), std::min(c[1], 255.0), std::min(c[2], 255.0));
            ++inside;
          }
        }
      }
      colour.at<cv::Vec3f>(row, col) = cv::Vec3f(sum / (kSub * kSub));
      alpha.at<float>(row, col) = static_cast<float>(inside) / (kSub * kSub);
    }
  }
  for (int row = 0; row + 1 < uniform_rows; ++row) {
    colour.row(uniform_rows - 1).copyTo(colour.row(row));
    alpha.row(uniform_rows - 1).copyTo(alpha.row(row));
  }
  return std::max(0, uniform_rows - 1);
}

// The soft shadow under a foot at a height: centre and half-axes (canvas px) and depth.
struct Shadow {
  double center_x, center_y, half_x, half_y, strength;
};

Shadow ShadowAt(const FootShape& shape, double height_m, bool enabled) {
  const double width_px = kFootWidthMm * shape.px_per_mm;
  const double height_mm = height_m * 1000;
  const double size = 1 - 0.3 * (1 - std::exp(-height_mm / 15));
  return {shape.center_x, shape.bottom - 0.03 * width_px, 0.62 * width_px * size,
          0.20 * width_px * size, enabled ? 0.65 * std::exp(-height_mm / 12) : 0.0};
}

// Multiplier of the bed's brightness at a canvas point under `shadow`.
inline float ShadeAt(const Shadow& shadow, double x, double y) {
  const double dx = (x - shadow.center_x) / shadow.half_x;
  const double dy = (y - shadow.center_y) / shadow.half_y;
  const double r2 = dx * dx + dy * dy;
  if (r2 >= 2.56) return 1.0f;
  return static_cast<float>(1 - shadow.strength * std::exp(-2 * r2));
}

cv::Rect ShadowBounds(const Shadow& shadow) {
  const int x0 = static_cast<int>(std::floor(shadow.center_x - 1.6 * shadow.half_x));
  const int y0 = static_cast<int>(std::floor(shadow.center_y - 1.6 * shadow.half_y));
  const int x1 = static_cast<int>(std::ceil(shadow.center_x + 1.6 * shadow.half_x));
  const int y1 = static_cast<int>(std::ceil(shadow.center_y + 1.6 * shadow.half_y));
  return {x0, y0, x1 - x0 + 1, y1 - y0 + 1};
}

// Darkens the bed under a static foot (canvas region clipped to `canvas`).
void ApplyShadow(const Shadow& shadow, cv::Mat& canvas) {
  const cv::Rect box = ShadowBounds(shadow) & cv::Rect(0, 0, canvas.cols, canvas.rows);
  for (int row = box.y; row < box.y + box.height; ++row) {
    auto* out = canvas.ptr<cv::Vec3f>(row);
    for (int col = box.x; col < box.x + box.width; ++col) out[col] *= ShadeAt(shadow, col, row);
  }
}

// Draws a premultiplied sprite at rest into a float canvas.
void DrawSprite(const cv::Mat& colour, const cv::Mat& alpha, const cv::Rect& region,
                cv::Mat& canvas) {
  for (int row = 0; row < std::min(colour.rows, canvas.rows); ++row) {
    auto* out = canvas.ptr<cv::Vec3f>(row) + region.x;
    const auto* c = colour.ptr<cv::Vec3f>(row);
    const auto* a = alpha.ptr<float>(row);
    for (int col = 0; col < region.width; ++col) out[col] = out[col] * (1 - a[col]) + c[col];
  }
}

// ---------------------------------------------------------------------------------------
// the LED

// Disc coverage, 4 x 4 samples per pixel.
float DiscCoverage(double x, double y, double cx, double cy, double radius) {
  constexpr int kSub = 4;
  int inside = 0;
  for (int sy = 0; sy < kSub; ++sy) {
    for (int sx = 0; sx < kSub; ++sx) {
      const double dx = x - 0.5 + (sx + 0.5) / kSub - cx, dy = y - 0.5 + (sy + 0.5) / kSub - cy;
      inside += dx * dx + dy * dy <= radius * radius ? 1 : 0;
    }
  }
  return static_cast<float>(inside) / (kSub * kSub);
}

// Where the feet stand (near, right feet C and A; far, left feet D and B): their shapes on
// the canvas and their placements in the image.
std::array<FootShape, 4> PlaceFeet(const Camera& camera,
                                   std::array<SceneRenderer::FootPlacement, 4>& placements) {
  const int margin = kMarginPx;
  const double near_m = kCameraDistanceM - kFeetHalfWidthM;
  const double far_m = kCameraDistanceM + kFeetHalfWidthM;
  std::array<FootShape, 4> shapes;
  for (Foot foot : kAllFeet) {
    const bool front = foot == Foot::kA || foot == Foot::kB;
    const bool near = foot == Foot::kA || foot == Foot::kC;
    const double depth_m = near ? near_m : far_m;
    const cv::Point2d contact =
        camera.Project(front ? kFeetHalfLengthM : -kFeetHalfLengthM, 0, depth_m);
    FootShape& shape = shapes[static_cast<size_t>(foot)];
    shape.center_x = contact.x + margin;
    shape.bottom = std::floor(contact.y) + 0.5 + margin;  // on a pixel boundary
    shape.px_per_mm = camera.focal_px / camera.AxisDepth(depth_m) / 1000;
    shape.tape = TapeBgr(foot);
    SceneRenderer::FootPlacement& place = placements[static_cast<size_t>(foot)];
    place.center_x_px = shape.center_x - margin;
    place.bottom_px = shape.bottom - margin;
    place.px_per_mm = shape.px_per_mm;
    place.width_px = kFootWidthMm * shape.px_per_mm;
    place.height_px = kFootHeightMm * shape.px_per_mm;
    place.tape_top_px = place.bottom_px - kTapeHighMm * shape.px_per_mm;
    place.tape_bottom_px = place.bottom_px - kTapeLowMm * shape.px_per_mm;
  }
  return shapes;
}

// The LED's board and its dark disc, on the wall: centre (led_x, led_y) and radius in
// canvas px.
void DrawLedBoard(double led_x, double led_y, double radius, cv::Mat& base) {
  const double board_half = std::max(3.2 * radius, radius + 8);
  const cv::Rect box =
      cv::Rect(static_cast<int>(std::floor(led_x - board_half - 2)),
               static_cast<int>(std::floor(led_y - board_half - 2)),
               static_cast<int>(2 * board_half + 5), static_cast<int>(2 * board_half + 5)) &
      cv::Rect(0, 0, base.cols, base.rows);
  for (int row = box.y; row < box.y + box.height; ++row) {
    for (int col = box.x; col < box.x + box.width; ++col) {
      // board coverage: a square, 4 x 4 samples
      int inside = 0;
      for (int s = 0; s < 16; ++s) {
        const double x = col - 0.5 + (s % 4 + 0.5) / 4, y = row - 0.5 + (s / 4 + 0.5) / 4;
        inside += std::abs(x - led_x) <= board_half && std::abs(y - led_y) <= board_half;
      }
      const float board = static_cast<float>(inside) / 16;
      const float bezel = DiscCoverage(col, row, led_x, led_y, radius * 1.35);
      const float disc = DiscCoverage(col, row, led_x, led_y, radius);
      const double dist = std::hypot(col - led_x + 0.3 * radius, row - led_y + 0.3 * radius);
      const double highlight = 40 * std::exp(-dist * dist / (0.1 * radius * radius + 0.5));
      cv::Vec3f& pixel = base.at<cv::Vec3f>(row, col);
      pixel = pixel * (1 - board) + cv::Vec3f(30, 34, 30) * board;
      pixel = pixel * (1 - bezel) + cv::Vec3f(52, 52, 55) * bezel;
      pixel = pixel * (1 - disc) + cv::Vec3f(static_cast<float>(74 + highlight),
                                             static_cast<float>(76 + highlight),
                                             static_cast<float>(80 + highlight)) *
                                       disc;
    }
  }
}

}  // namespace

// ---------------------------------------------------------------------------------------
// building the scene

Result<SceneRenderer> SceneRenderer::Create(const Timeline& timeline) {
  LIFTOFF_RETURN_IF_ERROR(timeline.spec().Validate());
  SceneRenderer renderer;
  try {
    renderer.Build(timeline);
  } catch (const cv::Exception& error) {
    return InvalidArgumentError(std::string("scene: OpenCV failed: ") + error.what());
  }
  return renderer;
}

void SceneRenderer::Build(const Timeline& timeline) {
  timeline_ = timeline;
  const TrialSpec& spec = timeline.spec();
  width_px_ = spec.camera.width_px;
  height_px_ = spec.camera.height_px;
  exposure_ns_ = ExposureNs(spec.camera);
  const int margin = kMarginPx;
  const Camera camera = MakeCamera(width_px_, height_px_);
  const std::array<FootShape, 4> shapes = PlaceFeet(camera, placements_);

  // the bed and the wall, the tape ruler 6 cm in front of the near feet
  cv::Mat base(height_px_ + 2 * margin, width_px_ + 2 * margin, CV_32FC3);
  RenderBackground(camera, margin, SeedFor(spec.seed, kTextureStream),
                   kCameraDistanceM - kFeetHalfWidthM - 0.085, base);
  // the LED: its board, then its light, drawn per frame over led_patch_
  const LedSpec& led = spec.led;
  const double led_x = led.x_frac * width_px_ - 0.5 + margin;
  const double led_y = led.y_frac * height_px_ - 0.5 + margin;
  DrawLedBoard(led_x, led_y, led.radius_px, base);
  ApplyVignette(base, margin, camera);
  BuildLedLight(led, led_x, led_y);
  const double led_roi_half = led.radius_px + kShakeBoundPx + 2;
  led_roi_px_ = ClippedRegion(led_x - margin - led_roi_half, led_y - margin - led_roi_half,
                              led_x - margin + led_roi_half, led_y - margin + led_roi_half);

  // which feet move: the lifting one, and its diagonal partner when it lags
  const Foot lifting = spec.motion.foot;
  std::array<bool, 4> moves{};
  moves[static_cast<size_t>(lifting)] = true;
  if (spec.motion.diagonal_lag_rad > 0) moves[static_cast<size_t>(DiagonalPartner(lifting))] = true;
  const FootPlacement& lift_place = placements_[static_cast<size_t>(lifting)];
  foot_roi_px_ = ClippedRegion(lift_place.center_x_px - lift_place.width_px / 2 - kShakeBoundPx,
                               lift_place.bottom_px - lift_place.height_px -
                                   kFootRoiAboveMm * lift_place.px_per_mm - kShakeBoundPx,
                               lift_place.center_x_px + lift_place.width_px / 2 + kShakeBoundPx,
                               lift_place.bottom_px + kShakeBoundPx);

  // static feet: shadows on the bed, then far feet, then near ones on top
  const bool shadows = spec.nuisance.shadow;
  for (Foot foot : kAllFeet) {
    if (!moves[static_cast<size_t>(foot)])
      ApplyShadow(ShadowAt(shapes[static_cast<size_t>(foot)], 0, shadows), base);
  }
  const std::array<Foot, 4> back_to_front = {Foot::kD, Foot::kB, Foot::kC, Foot::kA};
  const cv::Rect canvas_rect(0, 0, base.cols, base.rows);
  for (Foot foot : back_to_front) {
    const FootShape& shape = shapes[static_cast<size_t>(foot)];
    const double foot_half_px = kFootWidthMm / 2 * shape.px_per_mm;
    const Shadow rest_shadow = ShadowAt(shape, 0, true);
    const cv::Rect shadow_box = ShadowBounds(rest_shadow);
    const int x0 =
        std::min(static_cast<int>(std::floor(shape.center_x - foot_half_px)) - 2, shadow_box.x);
    const int x1 = std::max(static_cast<int>(std::ceil(shape.center_x + foot_half_px)) + 2,
                            shadow_box.x + shadow_box.width);
    const int y1 =
        std::max(static_cast<int>(std::ceil(shape.bottom)) + 2, shadow_box.y + shadow_box.height);
    const cv::Rect region = cv::Rect(x0, 0, x1 - x0, y1) & canvas_rect;
    cv::Mat colour, alpha;
    const int first_varying_row = RenderFootSprite(shape, region, colour, alpha);
    if (!moves[static_cast<size_t>(foot)]) {
      DrawSprite(colour, alpha, region, base);
      continue;
    }
    moving_.push_back(MovingFoot{foot, region, cv::Mat(), std::move(colour), std::move(alpha),
                                 first_varying_row});
  }
  for (MovingFoot& moving : moving_) base(moving.region).copyTo(moving.background);

  // the static canvas: the moving feet at rest, composed as every frame composes them
  base.convertTo(static_canvas_, CV_8UC3);
  for (const MovingFoot& moving : moving_) {
    ComposeMovingFoot(moving, std::vector<double>{0.0}, true, static_canvas_);
  }

  BuildNoiseTable(spec);
  shake_rng_ = SplitMix64(SeedFor(spec.seed, kShakeStream));
  shake_px_.assign(1, cv::Point2d(0, 0));
}

void SceneRenderer::BuildLedLight(const LedSpec& led, double led_x, double led_y) {
  const double radius = led.radius_px;
  const double bloom_sigma = 0.5 * led.bloom * radius;
  const int patch_half = static_cast<int>(std::ceil(radius + 3 * bloom_sigma + 2));
  led_patch_ = cv::Rect(static_cast<int>(std::floor(led_x)) - patch_half,
                        static_cast<int>(std::floor(led_y)) - patch_half, 2 * patch_half + 2,
                        2 * patch_half + 2) &
               cv::Rect(0, 0, width_px_ + 2 * kMarginPx, height_px_ + 2 * kMarginPx);
  led_disc_alpha_ = cv::Mat(led_patch_.size(), CV_32FC1);
  led_emission_ = cv::Mat(led_patch_.size(), CV_32FC3);
  const cv::Vec3d led_bgr(led.blue, led.green, led.red);
  const double white_core = 180 * std::max(0.0, led.intensity - 1);
  for (int row = 0; row < led_patch_.height; ++row) {
    for (int col = 0; col < led_patch_.width; ++col) {
      const double x = led_patch_.x + col, y = led_patch_.y + row;
      const float disc = DiscCoverage(x, y, led_x, led_y, radius);
      const double dist2 = (x - led_x) * (x - led_x) + (y - led_y) * (y - led_y);
      const double halo =
          led.bloom > 0 ? 0.8 * std::exp(-dist2 / (2 * bloom_sigma * bloom_sigma)) : 0;
      const cv::Vec3d emission =
          static_cast<double>(disc) * (led.intensity * led_bgr + cv::Vec3d::all(white_core)) +
          halo * led.intensity * led_bgr;
      led_disc_alpha_.at<float>(row, col) = disc;
      led_emission_.at<cv::Vec3f>(row, col) = cv::Vec3f(emission);
    }
  }
}

void SceneRenderer::BuildNoiseTable(const TrialSpec& spec) {
  // Gaussian grey levels, split into positive and negative parts
  if (spec.nuisance.noise_sigma <= 0) return;
  const size_t count =
      static_cast<size_t>(width_px_) * static_cast<size_t>(height_px_) * 3 + kNoiseOffsets;
  noise_positive_.assign(count, 0);
  noise_negative_.assign(count, 0);
  SplitMix64 rng(SeedFor(spec.seed, kNoiseTableStream));
  for (size_t i = 0; i < count; i += 2) {
    const double u1 = 1.0 - rng.Uniform(), u2 = rng.Uniform();
    const double r = std::sqrt(-2.0 * std::log(u1)) * spec.nuisance.noise_sigma;
    const std::array<double, 2> values = {r * std::cos(2 * kPi * u2), r * std::sin(2 * kPi * u2)};
    for (size_t k = 0; k < 2 && i + k < count; ++k) {
      const long level = std::clamp(std::lround(values[k]), -255L, 255L);
      noise_positive_[i + k] = static_cast<uint8_t>(std::max(0L, level));
      noise_negative_[i + k] = static_cast<uint8_t>(std::max(0L, -level));
    }
  }
}

RegionPx SceneRenderer::ClippedRegion(double x0, double y0, double x1, double y1) const {
  const int left = std::clamp(static_cast<int>(std::floor(x0)), 0, width_px_ - 1);
  const int top = std::clamp(static_cast<int>(std::floor(y0)), 0, height_px_ - 1);
  const int right = std::clamp(static_cast<int>(std::ceil(x1)), left, width_px_ - 1);
  const int bottom = std::clamp(static_cast<int>(std::ceil(y1)), top, height_px_ - 1);
  return {left, top, right - left + 1, bottom - top + 1};
}

// ---------------------------------------------------------------------------------------
// per frame

void SceneRenderer::ComposeMovingFoot(const MovingFoot& moving,
                                      const std::vector<double>& heights_m, bool force,
                                      cv::Mat& canvas) const {
  const bool moved =
      std::any_of(heights_m.begin(), heights_m.end(), [](double h) { return h > 0; });
  if (!moved && !force) return;  // the static canvas holds the foot at rest
  const FootShape shape = ShapeOf(placements_[static_cast<size_t>(moving.foot)], moving.foot);
  const bool shadows = timeline_.spec().nuisance.shadow;
  const double max_lift_px =
      *std::max_element(heights_m.begin(), heights_m.end()) * 1000 * shape.px_per_mm;

  // only rows that can differ from rest: from the collar's top lifted to the region's end
  const cv::Rect& region = moving.region;
  const int row_begin =
      force ? 0
            : std::clamp(moving.first_varying_row - static_cast<int>(std::ceil(max_lift_px)) - 2, 0,
                         region.height);
  const int rows = region.height - row_begin, cols = region.width;
  std::vector<cv::Vec3f> sum(static_cast<size_t>(rows) * static_cast<size_t>(cols),
                             cv::Vec3f(0, 0, 0));
  const int sprite_rows = moving.sprite_alpha.rows;

  for (double height_m : heights_m) {
    // the sprite lifted by a subpixel amount: linear interpolation between two rows
    const double lift_px = height_m * 1000 * shape.px_per_mm;
    const int whole = static_cast<int>(std::floor(lift_px));
    const auto part = static_cast<float>(lift_px - whole);
    const Shadow shadow = ShadowAt(shape, height_m, shadows);
    const cv::Rect shadow_box = ShadowBounds(shadow);
    for (int r = 0; r < rows; ++r) {
      const int row = row_begin + r;  // canvas row (the region starts at row 0)
      const int q0 = std::min(row + whole, sprite_rows - 1);
      const int q1 = std::min(row + whole + 1, sprite_rows - 1);  // the last sprite row is empty
      const auto* c0 = moving.sprite_colour.ptr<cv::Vec3f>(q0);
      const auto* c1 = moving.sprite_colour.ptr<cv::Vec3f>(q1);
      const auto* a0 = moving.sprite_alpha.ptr<float>(q0);
      const auto* a1 = moving.sprite_alpha.ptr<float>(q1);
      const auto* bg = moving.background.ptr<cv::Vec3f>(row);
      cv::Vec3f* out = sum.data() + static_cast<size_t>(r) * static_cast<size_t>(cols);
      const bool shadow_row =
          shadow.strength > 0 && row >= shadow_box.y && row < shadow_box.y + shadow_box.height;
      for (int col = 0; col < cols; ++col) {
        const float alpha = a0[col] + part * (a1[col] - a0[col]);
        const cv::Vec3f colour = c0[col] + part * (c1[col] - c0[col]);
        const float shade = shadow_row ? ShadeAt(shadow, region.x + col, row) : 1.0f;
        out[col] += bg[col] * (shade * (1 - alpha)) + colour;
      }
    }
  }

  // the average over the sub-samples, into the canvas
  const float scale = 1.0f / static_cast<float>(heights_m.size());
  for (int r = 0; r < rows; ++r) {
    auto* out = canvas.ptr<cv::Vec3b>(row_begin + r) + region.x;
    const cv::Vec3f* in = sum.data() + static_cast<size_t>(r) * static_cast<size_t>(cols);
    for (int col = 0; col < cols; ++col) {
      const cv::Vec3f v = in[col] * scale;
      out[col] = cv::Vec3b(cv::saturate_cast<uchar>(v[0]), cv::saturate_cast<uchar>(v[1]),
                           cv::saturate_cast<uchar>(v[2]));
    }
  }
}

void SceneRenderer::ComposeLed(double fraction, cv::Mat& canvas) const {
  // on = the disc's light over the scene, clipped at 255; the frame sees off + f (on - off)
  const auto f = static_cast<float>(fraction);
  for (int row = 0; row < led_patch_.height; ++row) {
    auto* pixel = canvas.ptr<cv::Vec3b>(led_patch_.y + row) + led_patch_.x;
    const auto* alpha = led_disc_alpha_.ptr<float>(row);
    const auto* emission = led_emission_.ptr<cv::Vec3f>(row);
    for (int col = 0; col < led_patch_.width; ++col) {
      cv::Vec3b& p = pixel[col];
      for (int k = 0; k < 3; ++k) {
        const float off = p[k];
        const float on = std::min(255.0f, off * (1 - alpha[col]) + emission[col][k]);
        p[k] = cv::saturate_cast<uchar>(off + f * (on - off));
      }
    }
  }
}

double SceneRenderer::LedOnFraction(int64_t t_video_ns) const {
  return timeline_.LedOnFractionOfExposure(t_video_ns);
}

cv::Point2d SceneRenderer::ShakeOffsetPx(int64_t frame_index) {
  const double step_px = timeline_.spec().nuisance.shake_px;
  if (step_px <= 0 || frame_index <= 0) return {0, 0};
  // a random walk reflected at +-kShakeBoundPx, extended as far as asked
  const auto reflect = [](double x) {
    while (std::abs(x) > kShakeBoundPx) x = (x > 0 ? 2 : -2) * kShakeBoundPx - x;
    return x;
  };
  while (static_cast<int64_t>(shake_px_.size()) <= frame_index) {
    const cv::Point2d last = shake_px_.back();
    const double dx = step_px * shake_rng_.Gaussian(), dy = step_px * shake_rng_.Gaussian();
    shake_px_.emplace_back(reflect(last.x + dx), reflect(last.y + dy));
  }
  return shake_px_[static_cast<size_t>(frame_index)];
}

cv::Mat SceneRenderer::RenderFrame(int64_t frame_index, int64_t t_video_ns) {
  const TrialSpec& spec = timeline_.spec();

  // 1. the static scene
  static_canvas_.copyTo(canvas_);

  // 2. the moving feet at the midpoints of the exposure's equal parts (the exposure is
  //    centred on the frame's timestamp)
  const int64_t exposure_start_ns = ExposureStartNs(spec.camera, t_video_ns);
  const int samples = spec.nuisance.motion_blur_samples;
  std::vector<double> heights_m(static_cast<size_t>(samples));
  for (const MovingFoot& moving : moving_) {
    for (int i = 0; i < samples; ++i) {
      const int64_t t_ns = exposure_start_ns + (2 * i + 1) * exposure_ns_ / (2 * samples);
      heights_m[static_cast<size_t>(i)] = timeline_.FootHeightMAt(moving.foot, t_ns);
    }
    ComposeMovingFoot(moving, heights_m, false, canvas_);
  }

  // 3. flicker: the lamp's brightness 1 + a sin(2 pi f t), averaged over the exposure
  const double amplitude = spec.nuisance.flicker_amplitude;
  if (amplitude > 0) {
    const double omega = 2 * kPi * spec.nuisance.flicker_hz;
    const double t0_s = SecondsFromNs(exposure_start_ns);
    const double t1_s = SecondsFromNs(exposure_start_ns + exposure_ns_);
    const double mean_sin =
        (std::cos(omega * t0_s) - std::cos(omega * t1_s)) / (omega * (t1_s - t0_s));
    canvas_.convertTo(canvas_, -1, 1 + amplitude * mean_sin);
  }

  // 4. the LED, self-lit, by the exact fraction of the exposure it was on
  const double fraction = LedOnFraction(t_video_ns);
  if (fraction > 0) ComposeLed(fraction, canvas_);

  // 5. camera shake: the picture moved by a subpixel offset, bilinear as two separable
  //    blends of shifted views (much faster than a general warp)
  cv::Mat frame;
  const cv::Point2d shake = ShakeOffsetPx(frame_index);
  const double source_x = kMarginPx - shake.x, source_y = kMarginPx - shake.y;
  const int x0 = static_cast<int>(std::floor(source_x)),
            y0 = static_cast<int>(std::floor(source_y));
  const double fx = source_x - x0, fy = source_y - y0;
  const cv::Rect view(x0, y0, width_px_, height_px_);
  if (fx == 0 && fy == 0) {
    canvas_(view).copyTo(frame);
  } else {
    const cv::Rect tall(x0, y0, width_px_, height_px_ + 1);
    cv::addWeighted(canvas_(tall), 1 - fx, canvas_(tall + cv::Point(1, 0)), fx, 0, shifted_);
    cv::addWeighted(shifted_.rowRange(0, height_px_), 1 - fy, shifted_.rowRange(1, height_px_ + 1),
                    fy, 0, frame);
  }

  // 6. sensor noise: the table read from a per-frame offset, with a per-frame sign
  if (!noise_positive_.empty()) {
    SplitMix64 rng(SeedFor(spec.seed, kFrameNoiseStream, static_cast<uint64_t>(frame_index)));
    const size_t offset = static_cast<size_t>(rng.Next() % kNoiseOffsets);
    const bool flip = (rng.Next() & 1) != 0;
    const cv::Mat up(
        height_px_, width_px_, CV_8UC3,
        const_cast<uint8_t*>((flip ? noise_negative_ : noise_positive_).data() + offset));
    const cv::Mat down(
        height_px_, width_px_, CV_8UC3,
        const_cast<uint8_t*>((flip ? noise_positive_ : noise_negative_).data() + offset));
    cv::add(frame, up, frame);
    cv::subtract(frame, down, frame);
  }
  return frame;
}

double SceneRenderer::px_per_mm() const {
  return placements_[static_cast<size_t>(timeline_.spec().motion.foot)].px_per_mm;
}

double SceneRenderer::foot_rest_bottom_px() const {
  return placements_[static_cast<size_t>(timeline_.spec().motion.foot)].bottom_px;
}

double SceneRenderer::FootBottomPxAt(int64_t t_video_ns) const {
  const double height_mm = timeline_.FootHeightMAt(timeline_.spec().motion.foot, t_video_ns) * 1000;
  return foot_rest_bottom_px() - height_mm * px_per_mm();
}

}  // namespace liftoff::synth
