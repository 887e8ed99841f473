// Sub-pixel registration of a small image patch (private to the video module).
//
// A template patch, taken from a reference image, is found again in another image near a
// guessed position: the translation d and a brightness change (gain g, offset o) that make
//   current(x + d) ~ (1 + g) * template(x) + o     for every pixel x of the patch,
// all channels at once. Gauss-Newton with the template's own gradients (the inverse
// compositional form: the normal matrix is fixed per template, so an iteration costs one
// bilinear resampling of the patch), started from the guess. The gain and offset absorb
// flicker, exposure and codec brightness changes, which would otherwise shift an edge.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace liftoff::video::internal {

/// A patch to find: its pixels and gradients, float, channels interleaved.
struct PatchTemplate {
  /// Top-left corner in the reference image, px (pixel centres at integers).
  cv::Point2d origin_px;
  /// Side length (square patches), width and height, px; channels per pixel.
  int size_px = 0;
  int width_px = 0;
  int height_px = 0;
  int channels = 0;
  /// width * height * channels values each: intensities, their x and y derivatives, and
  /// their weights (empty: all 1).
  std::vector<float> values, gradient_x, gradient_y, weights;
  /// Normal matrix of (dx, dy, gain, offset), fixed per template, and its inverse.
  cv::Matx44d normal, normal_inverse;
  /// Sum of squared y derivatives, per value: how well the patch pins vertical motion.
  double texture_y = 0.0;
  double texture_x = 0.0;
  /// Whether the normal matrix is well conditioned (the patch has texture to register).
  bool usable = false;
};

/// Takes the patch of `image` (CV_32FC1 or CV_32FC3) at `origin_px` (integer corner) of
/// side `size_px`. The patch and a one-pixel border must lie inside the image.
PatchTemplate MakePatchTemplate(const cv::Mat& image, cv::Point origin_px, int size_px);

/// Takes the region `rect` of `image` (CV_32FC1 or CV_32FC3), each pixel weighted by
/// `weights` (CV_32FC1 of rect's size, >= 0; empty: all 1): a zero weight leaves a pixel
/// out (e.g. what moves inside a region of static ground). rect and a one-pixel border must
/// lie inside the image.
PatchTemplate MakeWeightedTemplate(const cv::Mat& image, const cv::Rect& rect,
                                   const cv::Mat& weights);

/// Where the template was found.
struct PatchMatch {
  /// Top-left corner of the patch in the current image, px.
  cv::Point2d origin_px;
  double gain = 0.0;
  double offset = 0.0;
  /// Root mean square residual after the fit, intensity units.
  double residual_rms = 0.0;
  /// Gauss-Newton iterations run; false when the patch left the image or diverged.
  int iterations = 0;
  bool ok = false;
};

/// Registers `patch` in `image` (same type as the template's) starting at `guess_px`
/// (top-left corner). A square patch that leaves the image is not ok; a weighted region's
/// pixels that leave it are left out. Stops when a step is below `tolerance_px` or after
/// `max_iterations`.
PatchMatch RegisterPatch(const PatchTemplate& patch, const cv::Mat& image, cv::Point2d guess_px,
                         int max_iterations = 8, double tolerance_px = 0.005);

}  // namespace liftoff::video::internal
