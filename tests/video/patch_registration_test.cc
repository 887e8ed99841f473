// Patch registration (src/video/patch_registration.h) against images built analytically:
// a smooth texture f and its copy shifted by a known sub-pixel amount s, g(x) = f(x - s),
// so the template taken at corner c in f lies at c + s in g. OpenCV's ECC registration
// (cv::findTransformECC, translation only) is the independent reference on the same pair.
// At a sub-pixel position the registration samples g bilinearly, which averages
// neighbours and so damps the texture's contrast by up to a few per cent: the gain absorbs
// that (it comes out slightly below zero) and the translation does not move.
#include "patch_registration.h"

#include <cmath>
#include <cstdio>
#include <numbers>
#include <ostream>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/video/tracking.hpp>

namespace liftoff::video::internal {
namespace {

constexpr int kImageSize = 96;
constexpr int kPatchSize = 24;
const cv::Point kCorner(36, 36);

// A smooth texture: sinusoids of 11 to 23 px in x, y and along both diagonals, with
// different phases per channel, around a mean of 100.
float Texture(double x, double y, int channel) {
  constexpr double kTwoPi = 2 * std::numbers::pi;
  const double phase = 0.9 * channel;
  const double value = 100 + 30 * std::sin(kTwoPi * x / 17 + 0.3 + phase) +
                       25 * std::sin(kTwoPi * y / 13 + 1.1 - phase) +
                       20 * std::sin(kTwoPi * (x + y) / 23 + 2 * phase) +
                       15 * std::cos(kTwoPi * (x - y) / 11 + 0.5);
  return static_cast<float>(value);
}

// f(x - shift) * (1 + gain) + offset at every pixel, `channels` channels (1 or 3).
cv::Mat ShiftedTexture(cv::Point2d shift, int channels, double gain = 0.0, double offset = 0.0) {
  cv::Mat image(kImageSize, kImageSize, CV_32FC(channels));
  for (int y = 0; y < kImageSize; ++y) {
    float* row = image.ptr<float>(y);
    for (int x = 0; x < kImageSize; ++x) {
      for (int c = 0; c < channels; ++c) {
        const double value = Texture(x - shift.x, y - shift.y, c);
        row[x * channels + c] = static_cast<float>((1 + gain) * value + offset);
      }
    }
  }
  return image;
}

struct ShiftCase {
  cv::Point2d shift;
  int channels;
};

class RegisterPatchShift : public ::testing::TestWithParam<ShiftCase> {};

TEST_P(RegisterPatchShift, RecoversSubPixelTranslationToAHundredthOfAPixel) {
  const auto [shift, channels] = GetParam();
  const cv::Mat reference = ShiftedTexture({0, 0}, channels);
  const cv::Mat current = ShiftedTexture(shift, channels);
  const PatchTemplate patch = MakePatchTemplate(reference, kCorner, kPatchSize);
  ASSERT_TRUE(patch.usable);
  const PatchMatch match = RegisterPatch(patch, current, cv::Point2d(kCorner), 20, 1e-4);
  ASSERT_TRUE(match.ok);
  const cv::Point2d error = match.origin_px - (cv::Point2d(kCorner) + shift);
  std::printf("shift (%.2f, %.2f) x%d: error (%+.5f, %+.5f) px, %d iterations\n", shift.x,
              shift.y, channels, error.x, error.y, match.iterations);
  EXPECT_NEAR(error.x, 0.0, 0.01);
  EXPECT_NEAR(error.y, 0.0, 0.01);
  // bilinear sampling only damps contrast: 1 + gain a little below 1
  EXPECT_LE(match.gain, 1e-6);
  EXPECT_GT(match.gain, -0.05);
  // the defaults the tracker uses (8 iterations, 0.005 px) get as close
  const PatchMatch quick = RegisterPatch(patch, current, cv::Point2d(kCorner));
  ASSERT_TRUE(quick.ok);
  EXPECT_NEAR(quick.origin_px.x, kCorner.x + shift.x, 0.01);
  EXPECT_NEAR(quick.origin_px.y, kCorner.y + shift.y, 0.01);
}

void PrintTo(const ShiftCase& shift_case, std::ostream* out) {
  *out << "shift (" << shift_case.shift.x << ", " << shift_case.shift.y << ") x"
       << shift_case.channels;
}

INSTANTIATE_TEST_SUITE_P(Shifts, RegisterPatchShift,
                         ::testing::Values(ShiftCase{{0.3, -0.45}, 3}, ShiftCase{{-0.8, 1.25}, 3},
                                           ShiftCase{{1.6, 0.7}, 3}, ShiftCase{{0.3, -0.45}, 1},
                                           ShiftCase{{-1.35, -0.2}, 1}));

TEST(RegisterPatch, RecoversGainAndOffsetExactlyAtAWholePixelShift) {
  // current = 1.2 f(x - s) + 10: the model's 1 + gain = 1.2, offset = 10; no interpolation
  const cv::Point2d shift(2, -1);
  for (const int channels : {1, 3}) {
    const cv::Mat reference = ShiftedTexture({0, 0}, channels);
    const cv::Mat current = ShiftedTexture(shift, channels, 0.2, 10.0);
    const PatchTemplate patch = MakePatchTemplate(reference, kCorner, kPatchSize);
    const PatchMatch match = RegisterPatch(patch, current, cv::Point2d(kCorner), 20, 1e-4);
    ASSERT_TRUE(match.ok);
    const cv::Point2d error = match.origin_px - (cv::Point2d(kCorner) + shift);
    std::printf("whole-pixel shift, x%d: error (%+.1e, %+.1e) px, gain %.6f, offset %.5f\n",
                channels, error.x, error.y, match.gain, match.offset);
    EXPECT_NEAR(error.x, 0.0, 1e-3);
    EXPECT_NEAR(error.y, 0.0, 1e-3);
    EXPECT_NEAR(match.gain, 0.2, 1e-4);
    EXPECT_NEAR(match.offset, 10.0, 1e-2);
    EXPECT_LT(match.residual_rms, 0.01);
  }
}

TEST(RegisterPatch, GainAndOffsetLeaveASubPixelTranslationAlone) {
  // 1.2 g + 10 is an affine copy of g, bilinear samples included: the same translation,
  // and gain and offset those found on g itself mapped through it
  const cv::Point2d shift(0.55, -0.3);
  for (const int channels : {1, 3}) {
    const cv::Mat reference = ShiftedTexture({0, 0}, channels);
    const PatchTemplate patch = MakePatchTemplate(reference, kCorner, kPatchSize);
    const PatchMatch plain = RegisterPatch(patch, ShiftedTexture(shift, channels),
                                           cv::Point2d(kCorner), 20, 1e-4);
    const PatchMatch match = RegisterPatch(patch, ShiftedTexture(shift, channels, 0.2, 10.0),
                                           cv::Point2d(kCorner), 20, 1e-4);
    ASSERT_TRUE(plain.ok);
    ASSERT_TRUE(match.ok);
    const cv::Point2d error = match.origin_px - (cv::Point2d(kCorner) + shift);
    std::printf("gain 1.2, offset 10, x%d: error (%+.5f, %+.5f) px, gain %.5f (1.2 x plain: "
                "%.5f), offset %.4f (10 + 1.2 x plain: %.4f)\n",
                channels, error.x, error.y, match.gain, 1.2 * (1 + plain.gain) - 1, match.offset,
                10 + 1.2 * plain.offset);
    EXPECT_NEAR(error.x, 0.0, 0.01);
    EXPECT_NEAR(error.y, 0.0, 0.01);
    EXPECT_NEAR(match.origin_px.x, plain.origin_px.x, 1e-3);
    EXPECT_NEAR(match.origin_px.y, plain.origin_px.y, 1e-3);
    EXPECT_NEAR(1 + match.gain, 1.2 * (1 + plain.gain), 1e-3);
    EXPECT_NEAR(match.offset, 10 + 1.2 * plain.offset, 0.1);
  }
}

TEST(RegisterPatch, AgreesWithOpenCvEccOnTranslation) {
  for (const double gain : {0.0, 0.2}) {
    const cv::Point2d shift(-0.65, 0.4);
    const cv::Mat reference = ShiftedTexture({0, 0}, 1);
    const cv::Mat current = ShiftedTexture(shift, 1, gain, 10.0 * gain);
    const PatchTemplate patch = MakePatchTemplate(reference, kCorner, kPatchSize);
    const PatchMatch match = RegisterPatch(patch, current, cv::Point2d(kCorner), 20, 1e-4);
    ASSERT_TRUE(match.ok);
    // ECC maps template coordinates into the input image: its translation is the corner
    cv::Mat warp = (cv::Mat_<float>(2, 3) << 1, 0, kCorner.x, 0, 1, kCorner.y);
    const cv::Mat template_image =
        reference(cv::Rect(kCorner, cv::Size(kPatchSize, kPatchSize))).clone();
    cv::findTransformECC(template_image, current, warp, cv::MOTION_TRANSLATION,
                         cv::TermCriteria(cv::TermCriteria::COUNT + cv::TermCriteria::EPS, 100,
                                          1e-7),
                         cv::noArray(), 1);
    const cv::Point2d ecc(warp.at<float>(0, 2), warp.at<float>(1, 2));
    std::printf("gain %.1f: ours - ECC (%+.5f, %+.5f) px, ECC - truth (%+.5f, %+.5f) px\n", gain,
                match.origin_px.x - ecc.x, match.origin_px.y - ecc.y,
                ecc.x - kCorner.x - shift.x, ecc.y - kCorner.y - shift.y);
    // ECC resamples with cv::warpAffine, whose bilinear weights are quantised to 1/32 px
    EXPECT_NEAR(match.origin_px.x, ecc.x, 1.0 / 32);
    EXPECT_NEAR(match.origin_px.y, ecc.y, 1.0 / 32);
  }
}

TEST(MakePatchTemplate, FlatPatchIsNotUsable) {
  const cv::Mat flat(kImageSize, kImageSize, CV_32FC3, cv::Scalar(80, 90, 100));
  EXPECT_FALSE(MakePatchTemplate(flat, kCorner, kPatchSize).usable);
}

TEST(MakePatchTemplate, StripesThatPinOnlyOneAxisAreNotUsable) {
  // vertical stripes: x is pinned, y slides freely
  cv::Mat stripes(kImageSize, kImageSize, CV_32FC1);
  for (int y = 0; y < kImageSize; ++y) {
    for (int x = 0; x < kImageSize; ++x) stripes.at<float>(y, x) = Texture(x, 0, 0);
  }
  const PatchTemplate patch = MakePatchTemplate(stripes, kCorner, kPatchSize);
  EXPECT_GT(patch.texture_x, 1.0);
  EXPECT_EQ(patch.texture_y, 0.0);
  EXPECT_FALSE(patch.usable);
}

TEST(RegisterPatch, GuessThatLeavesTheImageIsNotOk) {
  const cv::Mat image = ShiftedTexture({0, 0}, 3);
  const PatchTemplate patch = MakePatchTemplate(image, kCorner, kPatchSize);
  ASSERT_TRUE(patch.usable);
  // the patch would reach column 80 + 23 > 95
  EXPECT_FALSE(RegisterPatch(patch, image, {80.0, 36.0}).ok);
  EXPECT_FALSE(RegisterPatch(patch, image, {-0.5, 36.0}).ok);
  // the same image guessed right: found where it is
  const PatchMatch inside = RegisterPatch(patch, image, cv::Point2d(kCorner));
  EXPECT_TRUE(inside.ok);
  EXPECT_NEAR(inside.origin_px.x, kCorner.x, 1e-6);
  EXPECT_NEAR(inside.origin_px.y, kCorner.y, 1e-6);
}

}  // namespace
}  // namespace liftoff::video::internal
