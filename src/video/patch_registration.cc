#include "patch_registration.h"

#include <cmath>

namespace liftoff::video::internal {
namespace {

// Bilinear sample of every channel at (x, y); false outside [0, cols - 1] x [0, rows - 1].
inline bool Sample(const cv::Mat& image, double x, double y, int channels, float* out) {
  if (!(x >= 0 && y >= 0 && x <= image.cols - 1 && y <= image.rows - 1)) return false;
  const int x0 = std::min(static_cast<int>(x), image.cols - 2);
  const int y0 = std::min(static_cast<int>(y), image.rows - 2);
  const float fx = static_cast<float>(x - x0), fy = static_cast<float>(y - y0);
  const float* row0 = image.ptr<float>(y0) + x0 * channels;
  const float* row1 = image.ptr<float>(y0 + 1) + x0 * channels;
  for (int c = 0; c < channels; ++c) {
    const float top = row0[c] + fx * (row0[c + channels] - row0[c]);
    const float bottom = row1[c] + fx * (row1[c + channels] - row1[c]);
    out[c] = top + fy * (bottom - top);
  }
  return true;
}

// Whether every sample of the patch at `origin` has its four neighbours in the image.
bool Inside(const PatchTemplate& patch, const cv::Mat& image, cv::Point2d origin) {
  if (!(origin.x >= 0 && origin.y >= 0)) return false;
  const double x0 = std::floor(origin.x), y0 = std::floor(origin.y);
  return x0 + patch.width_px <= image.cols - 1 && y0 + patch.height_px <= image.rows - 1;
}

// One Gauss-Newton pass's sums, the patch wholly inside: every sample has the same
// sub-pixel offset, so the bilinear weights are computed once.
void AccumulateInside(const PatchTemplate& patch, const cv::Mat& image, const PatchMatch& match,
                      cv::Vec4d& projection, double& sum_sq, double& weight_sum) {
  const int channels = patch.channels;
  const int x0 = static_cast<int>(std::floor(match.origin_px.x));
  const int y0 = static_cast<int>(std::floor(match.origin_px.y));
  const float fx = static_cast<float>(match.origin_px.x - x0);
  const float fy = static_cast<float>(match.origin_px.y - y0);
  const float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
  const float gain = static_cast<float>(1 + match.gain), offset = static_cast<float>(match.offset);
  const bool weighted = !patch.weights.empty();
  double p0 = 0, p1 = 0, p2 = 0, p3 = 0;
  size_t k = 0;
  for (int y = 0; y < patch.height_px; ++y) {
    const float* r0 = image.ptr<float>(y0 + y) + x0 * channels;
    const float* r1 = image.ptr<float>(y0 + y + 1) + x0 * channels;
    const int count = patch.width_px * channels;
    for (int i = 0; i < count; ++i, ++k) {
      const float sample =
          w00 * r0[i] + w01 * r0[i + channels] + w10 * r1[i] + w11 * r1[i + channels];
      const float value = patch.values[k];
      const float w = weighted ? patch.weights[k] : 1.0f;
      const float residual = sample - (gain * value + offset);
      const float wr = w * residual;
      sum_sq += static_cast<double>(wr * residual);
      weight_sum += static_cast<double>(w);
      p0 += static_cast<double>(patch.gradient_x[k] * wr);
      p1 += static_cast<double>(patch.gradient_y[k] * wr);
      p2 -= static_cast<double>(value * wr);
      p3 -= static_cast<double>(wr);
    }
  }
  projection = cv::Vec4d(p0, p1, p2, p3);
}

// The same sums for a weighted region partly outside the image: what left it is left out.
void AccumulateClipped(const PatchTemplate& patch, const cv::Mat& image, const PatchMatch& match,
                       cv::Vec4d& projection, double& sum_sq,
                       double& weight_sum) {
  const int channels = patch.channels;
  cv::Vec4f sample;  // CV_32FC1 or CV_32FC3 (MakeWeightedTemplate)
  size_t k = 0;
  for (int y = 0; y < patch.height_px; ++y) {
    for (int x = 0; x < patch.width_px; ++x) {
      if (!Sample(image, match.origin_px.x + x, match.origin_px.y + y, channels, sample.val)) {
        k += static_cast<size_t>(channels);
        continue;
      }
      for (int c = 0; c < channels; ++c, ++k) {
        const double value = static_cast<double>(patch.values[k]);
        const double model = (1 + match.gain) * value + match.offset;
        const double residual = static_cast<double>(sample[c]) - model;
        const double w = static_cast<double>(patch.weights[k]);
        sum_sq += w * residual * residual;
        weight_sum += w;
        projection += cv::Vec4d(static_cast<double>(patch.gradient_x[k]),
                                static_cast<double>(patch.gradient_y[k]), -value, -1) *
                      (w * residual);
      }
    }
  }
}

}  // namespace

PatchTemplate MakePatchTemplate(const cv::Mat& image, cv::Point origin_px, int size_px) {
  return MakeWeightedTemplate(image, cv::Rect(origin_px, cv::Size(size_px, size_px)), cv::Mat());
}

PatchTemplate MakeWeightedTemplate(const cv::Mat& image, const cv::Rect& rect,
                                   const cv::Mat& weights) {
  PatchTemplate patch;
  patch.origin_px = cv::Point2d(rect.x, rect.y);
  patch.size_px = rect.width;
  patch.width_px = rect.width;
  patch.height_px = rect.height;
  patch.channels = image.channels();
  const int channels = patch.channels;
  const size_t count = static_cast<size_t>(rect.width * rect.height * channels);
  patch.values.resize(count);
  patch.gradient_x.resize(count);
  patch.gradient_y.resize(count);
  if (!weights.empty()) patch.weights.resize(count);
  cv::Matx44d normal = cv::Matx44d::zeros();
  double weight_sum = 0;
  size_t k = 0;
  for (int y = 0; y < rect.height; ++y) {
    const float* above = image.ptr<float>(rect.y + y - 1) + rect.x * channels;
    const float* row = image.ptr<float>(rect.y + y) + rect.x * channels;
    const float* below = image.ptr<float>(rect.y + y + 1) + rect.x * channels;
    for (int x = 0; x < rect.width; ++x) {
      const double w = weights.empty() ? 1.0 : static_cast<double>(weights.at<float>(y, x));
      for (int c = 0; c < channels; ++c, ++k) {
        const int i = x * channels + c;
        const double value = static_cast<double>(row[i]);
        const double gx = 0.5 * static_cast<double>(row[i + channels] - row[i - channels]);
        const double gy = 0.5 * static_cast<double>(below[i] - above[i]);
        patch.values[k] = static_cast<float>(value);
        patch.gradient_x[k] = static_cast<float>(gx);
        patch.gradient_y[k] = static_cast<float>(gy);
        if (!weights.empty()) patch.weights[k] = static_cast<float>(w);
        const cv::Vec4d j(gx, gy, -value, -1.0);
        normal += w * (j * j.t());
        weight_sum += w;
      }
    }
  }
  patch.normal = normal;
  patch.texture_x = normal(0, 0) / std::max(weight_sum, 1.0);
  patch.texture_y = normal(1, 1) / std::max(weight_sum, 1.0);
  // the translation must be pinned apart from brightness: its block well conditioned
  patch.normal_inverse = normal.inv(cv::DECOMP_SVD);
  const cv::Matx22d translation(normal(0, 0), normal(0, 1), normal(1, 0), normal(1, 1));
  const double trace = translation(0, 0) + translation(1, 1);
  const double det = cv::determinant(translation);
  const double disc = std::sqrt(std::max(0.0, trace * trace / 4 - det));
  const double smallest = trace / 2 - disc;
  const double condition = smallest / std::max(1e-12, trace / 2 + disc);
  patch.usable = smallest > 0 && condition > 1e-4 && std::isfinite(patch.normal_inverse(0, 0));
  return patch;
}

PatchMatch RegisterPatch(const PatchTemplate& patch, const cv::Mat& image, cv::Point2d guess_px,
                         int max_iterations, double tolerance_px) {
  PatchMatch match;
  match.origin_px = guess_px;
  for (int iteration = 1; iteration <= max_iterations; ++iteration) {
    // residual of the current estimate and its projection on the template's Jacobian
    cv::Vec4d projection(0, 0, 0, 0);
    double sum_sq = 0, weight_sum = 0;
    if (Inside(patch, image, match.origin_px)) {
      AccumulateInside(patch, image, match, projection, sum_sq, weight_sum);
    } else if (patch.weights.empty()) {
      match.iterations = iteration;  // a patch that left the image is lost
      return match;
    } else {
      AccumulateClipped(patch, image, match, projection, sum_sq, weight_sum);
    }
    match.residual_rms = std::sqrt(sum_sq / std::max(weight_sum, 1e-12));
    match.iterations = iteration;
    // image(x + d) - (1 + g) t(x) - o ~ grad t . step - t dg - do
    const cv::Vec4d step = patch.normal_inverse * projection;
    if (!std::isfinite(step[0]) || !std::isfinite(step[1])) return match;
    match.origin_px.x -= step[0];
    match.origin_px.y -= step[1];
    match.gain -= step[2];
    match.offset -= step[3];
    if (std::hypot(step[0], step[1]) < tolerance_px) break;
  }
  match.ok = std::isfinite(match.origin_px.x) && std::isfinite(match.origin_px.y);
  return match;
}

}  // namespace liftoff::video::internal
