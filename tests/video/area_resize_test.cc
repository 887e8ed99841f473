// Area downscaling (src/video/area_resize.h) against OpenCV's cv::resize with INTER_AREA,
// the rule it reproduces: on random 8-bit images, at the foot tracker's kind of scales
// (non-integer, a region of 67-400 px to about 64) and at simple ones, through a view into
// a larger image as the tracker passes it; both round to whole levels, so they agree but
// for half-way cases. And analytic cases: a constant image stays constant; a staircase's
// means are its exact integrals, to the rounding.
#include "area_resize.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

namespace liftoff::video::internal {
namespace {

struct Agreement {
  double max_difference = 0;  // grey levels
  double fraction_equal = 0;  // of all values
};

Agreement CompareWithOpenCv(const cv::Mat& bgr, double scale) {
  const AreaResizer resizer(bgr.size(), scale);
  cv::Mat ours, theirs, theirs_float;
  resizer.Apply(bgr, ours);
  cv::resize(bgr, theirs, cv::Size(), scale, scale, cv::INTER_AREA);
  theirs.convertTo(theirs_float, CV_32FC3);
  EXPECT_EQ(ours.size(), theirs.size()) << "scale " << scale;
  if (ours.size() != theirs.size()) return {1e9, 0};
  cv::Mat difference = cv::abs(ours - theirs_float);
  const double values = static_cast<double>(difference.total() * 3);
  return {cv::norm(difference, cv::NORM_INF),
          1.0 - cv::countNonZero(difference.reshape(1) > 1e-3) / values};
}

// Both round to whole levels; where the exact mean is a half-way case, float sums in a
// different order may round the other way. At integer factors (1/2, 1/4) OpenCV takes an
// integer path that rounds half up, and a 2x2 mean is a half-way case for 1 value in 4.
TEST(AreaResizer, AgreesWithOpenCvsInterArea) {
  cv::RNG rng(20261125);
  const cv::Size sizes[] = {{182, 182}, {91, 130}, {400, 260}, {67, 67}, {257, 73}};
  for (const cv::Size size : sizes) {
    cv::Mat frame(size.height + 20, size.width + 30, CV_8UC3);
    rng.fill(frame, cv::RNG::UNIFORM, 0, 256);
    const cv::Mat view = frame(cv::Rect(17, 9, size.width, size.height));
    for (const double scale : {64.0 / std::min(size.width, size.height), 0.5, 0.25, 0.9}) {
      if (scale > 1) continue;
      const Agreement agreement = CompareWithOpenCv(view, scale);
      EXPECT_LE(agreement.max_difference, 1.0) << size.width << "x" << size.height << " at " << scale;
      const bool integer_factor = scale == 0.5 || scale == 0.25;
      EXPECT_GE(agreement.fraction_equal, integer_factor ? 0.85 : 0.995)
          << size.width << "x" << size.height << " at " << scale;
    }
  }
}

TEST(AreaResizer, KeepsAConstantAndALinearRamp) {
  cv::Mat constant(150, 210, CV_8UC3, cv::Scalar(7, 99, 201));
  const AreaResizer resizer(constant.size(), 0.37);
  cv::Mat out;
  resizer.Apply(constant, out);
  EXPECT_EQ(out.size(), cv::Size(78, 56));  // round(210 * 0.37), round(150 * 0.37)
  cv::Mat expected(out.size(), CV_32FC3, cv::Scalar(7, 99, 201));
  EXPECT_LE(cv::norm(out, expected, cv::NORM_INF), 1e-3);

  // value = source column, a staircase floor(x): output pixel i is its mean over
  // [a, b) = [i / s, (i + 1) / s) (b clipped to the width), (F(b) - F(a)) / (b - a) with
  // F(x) = integral of floor from 0 to x = n (n - 1) / 2 + n (x - n), n = floor(x)
  cv::Mat ramp(40, 200, CV_8UC3);
  for (int x = 0; x < ramp.cols; ++x) ramp.col(x).setTo(cv::Scalar::all(x));
  const double scale = 0.3;
  const AreaResizer ramp_resizer(ramp.size(), scale);
  ramp_resizer.Apply(ramp, out);
  ASSERT_EQ(out.cols, 60);
  const auto integral = [](double x) {
    const double n = std::floor(x);
    return n * (n - 1) / 2 + n * (x - n);
  };
  for (int i = 0; i < out.cols; ++i) {
    const double a = i / scale, b = std::min((i + 1) / scale, 200.0);
    // (rounded to a whole level)
    EXPECT_NEAR(out.at<cv::Vec3f>(5, i)[1], (integral(b) - integral(a)) / (b - a), 0.5 + 1e-3)
        << "column " << i;
  }
}

}  // namespace
}  // namespace liftoff::video::internal
