// Key-frame times (src/video/keyframes.h) of clips written by synth's VideoWriter, whose
// GOP is one key frame per nominal second (x264 and FFV1, which resets its context model
// at each key frame); intra-only MJPEG makes every frame a key frame.
#include "keyframes.h"

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "liftoff/synth/spec.h"
#include "liftoff/synth/video_writer.h"
#include "support/test_support.h"

namespace liftoff::video::internal {
namespace {

using ::liftoff::testing::ScratchDir;
using ::testing::ElementsAre;

constexpr int kWidth = 64;
constexpr int kHeight = 48;
constexpr double kFps = 10.0;

// Seeded random pixels sliding a pixel right and half a pixel down per frame: predicting a
// frame from the last is far cheaper than coding it alone, so x264 never sees a scene cut
// (a smooth gradient is cheap enough to code alone that it inserts extra key frames).
cv::Mat Frame(int index) {
  static const cv::Mat texture = [] {
    cv::Mat pixels(kHeight + 32, kWidth + 64, CV_8UC3);
    cv::RNG generator(5);
    generator.fill(pixels, cv::RNG::UNIFORM, 0, 256);
    return pixels;
  }();
  return texture(cv::Rect(index, index / 2, kWidth, kHeight)).clone();
}

// Writes `frames` frames at 1 / kFps s each and returns the path.
std::filesystem::path WriteClip(const ScratchDir& scratch, synth::VideoCodec codec, int frames) {
  synth::VideoWriterOptions options;
  options.codec = codec;
  options.width_px = kWidth;
  options.height_px = kHeight;
  options.nominal_fps = kFps;
  options.quality = codec == synth::VideoCodec::kMjpeg ? 4 : 18;
  const std::filesystem::path path =
      scratch / ("clip" + std::string(synth::VideoCodecExtension(codec)));
  auto writer = synth::VideoWriter::Open(path, options);
  EXPECT_TRUE(writer.ok()) << writer.status().ToString();
  if (!writer.ok()) return path;
  for (int i = 0; i < frames; ++i) {
    const int64_t t_ns = static_cast<int64_t>(i) * 100'000'000;  // 1 / kFps
    EXPECT_TRUE((*writer)->Write(Frame(i), t_ns).ok());
  }
  EXPECT_TRUE((*writer)->Close().ok());
  return path;
}

TEST(ReadKeyframeTimesNs, H264AndFfv1ClipsHaveAKeyFrameEveryNominalSecond) {
  // 25 frames at 10 Hz, GOP 10: key frames 0, 10 and 20, at 0, 1 and 2 s (H.264 with
  // B-frames: packets in decode order, times from the presentation stamps)
  for (const synth::VideoCodec codec : {synth::VideoCodec::kH264, synth::VideoCodec::kFfv1}) {
    const ScratchDir scratch;
    const std::filesystem::path path = WriteClip(scratch, codec, 25);
    const Result<std::vector<int64_t>> times = ReadKeyframeTimesNs(path);
    ASSERT_TRUE(times.ok()) << times.status().ToString();
    EXPECT_THAT(*times, ElementsAre(0, 1'000'000'000, 2'000'000'000))
        << synth::VideoCodecName(codec);
  }
}

TEST(ReadKeyframeTimesNs, MjpegClipHasEveryFrameKey) {
  const ScratchDir scratch;
  constexpr int kFrames = 12;
  const std::filesystem::path path = WriteClip(scratch, synth::VideoCodec::kMjpeg, kFrames);
  const Result<std::vector<int64_t>> times = ReadKeyframeTimesNs(path);
  ASSERT_TRUE(times.ok()) << times.status().ToString();
  std::vector<int64_t> expected;
  for (int i = 0; i < kFrames; ++i) expected.push_back(static_cast<int64_t>(i) * 100'000'000);
  EXPECT_EQ(*times, expected);
}

TEST(ReadKeyframeTimesNs, MissingFileIsAParseError) {
  const ScratchDir scratch;
  const Result<std::vector<int64_t>> times = ReadKeyframeTimesNs(scratch / "absent.mp4");
  ASSERT_FALSE(times.ok());
  EXPECT_EQ(times.status().code(), StatusCode::kParse);
  EXPECT_THAT(times.status().message(), ::testing::HasSubstr("absent.mp4"));
}

TEST(ReadKeyframeTimesNs, TextFileIsAParseError) {
  const ScratchDir scratch;
  const std::filesystem::path path = scratch / "not_a_video.mp4";
  ASSERT_TRUE(synth::WriteNotAVideo(path).ok());
  const Result<std::vector<int64_t>> times = ReadKeyframeTimesNs(path);
  ASSERT_FALSE(times.ok());
  EXPECT_EQ(times.status().code(), StatusCode::kParse);
}

TEST(NearAny, EmptyListIsNeverNear) { EXPECT_FALSE(NearAny({}, 0, 1'000'000)); }

TEST(NearAny, ToleranceIsInclusiveOnBothSides) {
  const std::vector<int64_t> times = {1'000, 5'000, 9'000};
  EXPECT_TRUE(NearAny(times, 5'000, 0));
  EXPECT_TRUE(NearAny(times, 5'100, 100));
  EXPECT_TRUE(NearAny(times, 4'900, 100));
  EXPECT_FALSE(NearAny(times, 5'101, 100));
  EXPECT_FALSE(NearAny(times, 4'899, 100));
  // between two times, outside both tolerances; before the first and after the last
  EXPECT_FALSE(NearAny(times, 3'000, 1'000));
  EXPECT_TRUE(NearAny(times, 3'000, 2'000));
  EXPECT_FALSE(NearAny(times, 0, 999));
  EXPECT_TRUE(NearAny(times, 0, 1'000));
  EXPECT_FALSE(NearAny(times, 9'501, 500));
  EXPECT_TRUE(NearAny(times, 9'500, 500));
}

}  // namespace
}  // namespace liftoff::video::internal
