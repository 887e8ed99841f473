// The direct FFmpeg decoder against OpenCV's FFmpeg backend (the reference it replaces):
// the same pictures, times, rate, frame count and FourCC; and regions converted alone
// equal to the same regions of a whole conversion, in every codec synth writes and at
// sizes that are not multiples of the alignment.
#include "av_decoder.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include "liftoff/synth/video_writer.h"
#include "support/test_support.h"

namespace liftoff::video::internal {
namespace {

namespace fs = std::filesystem;
using liftoff::testing::ScratchDir;

// A textured, moving picture with sharp colour edges (chroma changes at every region edge).
cv::Mat Picture(int width_px, int height_px, int k) {
  cv::Mat bgr(height_px, width_px, CV_8UC3);
  cv::RNG rng(static_cast<uint64_t>(1000 + k));
  rng.fill(bgr, cv::RNG::UNIFORM, cv::Scalar::all(0), cv::Scalar::all(256));
  cv::GaussianBlur(bgr, bgr, cv::Size(3, 3), 0.7);
  for (int i = 0; i < 12; ++i) {
    const cv::Point corner((37 * i + 5 * k) % width_px, (23 * i + 3 * k) % height_px);
    cv::rectangle(bgr, cv::Rect(corner, cv::Size(19, 11)),
                  cv::Scalar(40 * (i % 7), 255 - 20 * i, 30 * (i % 5)), cv::FILLED);
  }
  return bgr;
}

fs::path WriteClip(const fs::path& folder, synth::VideoCodec codec, int width_px,
                   int height_px, int frames) {
  synth::VideoWriterOptions options;
  options.codec = codec;
  options.width_px = width_px;
  options.height_px = height_px;
  options.nominal_fps = 30.0;
  const fs::path path = folder / ("clip-" + std::to_string(width_px) + "x" +
                                  std::to_string(height_px) +
                                  std::string(synth::VideoCodecExtension(codec)));
  auto writer = synth::VideoWriter::Open(path, options);
  EXPECT_TRUE(writer.ok()) << writer.status().ToString();
  if (!writer.ok()) return path;
  for (int k = 0; k < frames; ++k) {
    const Status written =
        (*writer)->Write(Picture(width_px, height_px, k), static_cast<int64_t>(k) * 33'333'333);
    EXPECT_TRUE(written.ok()) << written.ToString();
  }
  EXPECT_TRUE((*writer)->Close().ok());
  return path;
}

struct Case {
  synth::VideoCodec codec;
  int width_px, height_px;
};

class AvDecoderClips : public ::testing::TestWithParam<Case> {
 protected:
  static void SetUpTestSuite() { scratch_ = std::make_unique<ScratchDir>(); }
  static void TearDownTestSuite() { scratch_.reset(); }
  fs::path Clip() const {
    const Case& c = GetParam();
    return WriteClip(scratch_->path(), c.codec, c.width_px, c.height_px, kFrames);
  }
  static constexpr int kFrames = 12;

 private:
  static inline std::unique_ptr<ScratchDir> scratch_;
};

TEST_P(AvDecoderClips, PicturesTimesAndFactsEqualOpenCvs) {
  const fs::path path = Clip();
  auto decoder = AvDecoder::Open(path.string());
  ASSERT_TRUE(decoder.ok()) << decoder.status().ToString();
  cv::VideoCapture capture(path.string(), cv::CAP_FFMPEG);
  ASSERT_TRUE(capture.isOpened());
  const StreamFacts& facts = (*decoder)->facts();
  EXPECT_EQ(facts.width_px, GetParam().width_px);
  EXPECT_EQ(facts.height_px, GetParam().height_px);
  EXPECT_DOUBLE_EQ(facts.fps, capture.get(cv::CAP_PROP_FPS));
  EXPECT_EQ(facts.frames, std::llround(capture.get(cv::CAP_PROP_FRAME_COUNT)));
  const auto code = static_cast<uint32_t>(capture.get(cv::CAP_PROP_FOURCC));
  EXPECT_EQ(facts.fourcc, std::string({static_cast<char>(code & 0xFF),
                                       static_cast<char>((code >> 8) & 0xFF),
                                       static_cast<char>((code >> 16) & 0xFF),
                                       static_cast<char>((code >> 24) & 0xFF)})
                              .substr(0, facts.fourcc.size()));
  cv::Mat ours, theirs;
  int frames = 0;
  while (capture.read(theirs)) {
    ASSERT_TRUE((*decoder)->Next()) << "frame " << frames;
    (*decoder)->ToBgr({}, ours);
    EXPECT_EQ(cv::norm(ours, theirs, cv::NORM_INF), 0.0) << "frame " << frames;
    const double their_ms = capture.get(cv::CAP_PROP_POS_MSEC);
    // OpenCV reads 0 ms for the B-frames drained at the end; ours are the real times
    if (frames == 0 || their_ms > 0) {
      EXPECT_NEAR((*decoder)->position_ms(), their_ms, 1e-6) << "frame " << frames;
    } else {
      EXPECT_NEAR((*decoder)->position_ms(), frames * 33.333333, 0.01) << "frame " << frames;
    }
    ++frames;
  }
  EXPECT_FALSE((*decoder)->Next());
  EXPECT_EQ(frames, kFrames);
}

TEST_P(AvDecoderClips, RegionsAloneEqualAWholeConversion) {
  const fs::path path = Clip();
  auto decoder = AvDecoder::Open(path.string());
  ASSERT_TRUE(decoder.ok()) << decoder.status().ToString();
  const int width = GetParam().width_px, height = GetParam().height_px;
  // odd origins and sizes, one touching the right and bottom edges, one partly outside
  const std::vector<cv::Rect> regions = {{3, 5, 41, 17},
                                         {width - 29, height - 13, 29, 13},
                                         {width / 2 + 1, 1, 7, height / 2 + 1},
                                         {-10, height / 3, 30, 9}};
  cv::Mat parts, whole;
  for (int k = 0; k < kFrames; ++k) {
    ASSERT_TRUE((*decoder)->Next());
    (*decoder)->ToBgr(regions, parts);
    (*decoder)->ToBgr({}, whole);
    ASSERT_EQ(parts.size(), whole.size());
    for (const cv::Rect& region : regions) {
      const cv::Rect inside = region & cv::Rect(0, 0, width, height);
      EXPECT_EQ(cv::norm(parts(inside), whole(inside), cv::NORM_INF), 0.0)
          << "frame " << k << ", region " << inside;
    }
    if (k == 0 && GetParam().codec != synth::VideoCodec::kFfv1) {
      // planar YUV (H.264, MJPEG): the regions alone were converted, so a new buffer stays
      // black far from all of them (FFV1's packed BGR is converted whole)
      EXPECT_EQ(parts.at<cv::Vec3b>(height - 1, width / 4), cv::Vec3b(0, 0, 0));
    }
  }
}

// More region sizes than the decoder keeps swscale contexts for (8): the ones past them
// share a context made again for each, and still convert exactly.
TEST_P(AvDecoderClips, ManyRegionSizesEqualAWholeConversion) {
  auto decoder = AvDecoder::Open(Clip().string());
  ASSERT_TRUE(decoder.ok()) << decoder.status().ToString();
  std::vector<cv::Rect> regions;
  for (int i = 0; i < 12; ++i) regions.emplace_back(3 + 17 * i, 2 + 9 * i, 9 + 3 * i, 5 + 2 * i);
  cv::Mat parts, whole;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE((*decoder)->Next());
    (*decoder)->ToBgr(regions, parts);
    (*decoder)->ToBgr({}, whole);
    for (const cv::Rect& region : regions) {
      const cv::Rect inside = region & cv::Rect(0, 0, whole.cols, whole.rows);
      EXPECT_EQ(cv::norm(parts(inside), whole(inside), cv::NORM_INF), 0.0)
          << "frame " << k << ", region " << inside;
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Codecs, AvDecoderClips,
                         ::testing::Values(Case{synth::VideoCodec::kH264, 320, 240},
                                           Case{synth::VideoCodec::kH264, 326, 198},
                                           Case{synth::VideoCodec::kMjpeg, 320, 240},
                                           Case{synth::VideoCodec::kMjpeg, 322, 202},
                                           Case{synth::VideoCodec::kFfv1, 320, 240},
                                           Case{synth::VideoCodec::kFfv1, 318, 206}));

TEST(AvDecoder, WhatIsNotAVideoIsAParseError) {
  ScratchDir scratch;
  const fs::path text = scratch.path() / "notes.mp4";
  std::ofstream(text) << "not a video at all\n";
  auto decoder = AvDecoder::Open(text.string());
  ASSERT_FALSE(decoder.ok());
  EXPECT_EQ(decoder.status().code(), StatusCode::kParse);
}

}  // namespace
}  // namespace liftoff::video::internal
