// Frame timing against the synthetic generator's exact frame times (FFV1, MJPEG, H.264 with
// its B-frame quirk), drops and irregular intervals against the truth's intervals, and
// every error a user can cause (missing, not a video, truncated or damaged).
#include "liftoff/video/video_reader.h"

#include <cmath>
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <gmock/gmock.h>
extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
}
#include <gtest/gtest.h>

#include "liftoff/core/calibration.h"
#include "liftoff/synth/spec.h"
#include "liftoff/synth/trial_writer.h"
#include "liftoff/synth/video_writer.h"
#include "support/test_support.h"

namespace liftoff::video {
namespace {

namespace fs = std::filesystem;
using ::liftoff::testing::ScratchDir;
using ::liftoff::testing::SourceDir;
using ::liftoff::testing::WriteFile;
using ::testing::HasSubstr;

// A short small clip: 320 x 240 at 30 fps, the LED on at 0.4 s, the foot at rest.
synth::TrialSpec SmallClip(const std::string& id, synth::VideoCodec codec) {
  synth::TrialSpec spec;
  spec.id = id;
  spec.seed = 7;
  spec.duration_s = 1.5;
  spec.camera.width_px = 320;
  spec.camera.height_px = 240;
  spec.camera.fps = 30.0;
  spec.camera.exposure_s = 1.0 / 60.0;
  spec.camera.codec = codec;
  spec.camera.quality = codec == synth::VideoCodec::kMjpeg ? 5 : 20;
  spec.led.on_video_s = 0.4;
  spec.motion.bend_start_s = 0.0;
  spec.motion.bend_end_s = 0.2;
  spec.motion.ramp_start_s = 0.3;
  spec.motion.ramp_rate_rad_per_s = 0.2;
  return spec;
}

// Every frame of a file (the first error, if any).
struct ReadAll {
  Status status;
  std::vector<int64_t> t_ns;
  std::vector<bool> repaired;
  FrameTimingReport timing;
};
ReadAll ReadFrames(const fs::path& path) {
  ReadAll all;
  auto reader = VideoReader::Open(path);
  if (!reader.ok()) {
    all.status = reader.status();
    return all;
  }
  Frame frame;
  for (;;) {
    auto more = reader->Next(frame);
    if (!more.ok()) {
      all.status = more.status();
      break;
    }
    if (!*more) break;
    EXPECT_EQ(frame.index, static_cast<int64_t>(all.t_ns.size()));
    EXPECT_EQ(frame.bgr.cols, 320);
    EXPECT_EQ(frame.bgr.type(), CV_8UC3);
    all.t_ns.push_back(frame.t_ns);
    all.repaired.push_back(frame.t_repaired);
  }
  all.timing = reader->timing();
  return all;
}

// Clips rendered once for the whole suite.
class VideoReaderClips : public ::testing::Test {
 protected:
  struct Clip {
    fs::path path;
    synth::GroundTruth truth;
    double fps = 30.0;
  };

  static void SetUpTestSuite() {
    scratch_ = std::make_unique<ScratchDir>();
    auto calibration = LoadCalibration(SourceDir() / "calib" / "laika-2018.json");
    ASSERT_TRUE(calibration.ok()) << calibration.status().ToString();
    const auto add = [&](const synth::TrialSpec& spec) {
      auto written = synth::WriteTrial(spec, *calibration, scratch_->path());
      ASSERT_TRUE(written.ok()) << written.status().ToString();
      clips_[spec.id] = Clip{written->video_path, written->truth, spec.camera.fps};
    };
    // lossless, variable rate: jitter and drops, stored to the millisecond
    synth::TrialSpec ffv1 = SmallClip("ffv1-vfr", synth::VideoCodec::kFfv1);
    ffv1.camera.timestamp_jitter_s = 0.2 / 30.0;
    ffv1.camera.drop_probability = 0.1;
    add(ffv1);
    // AVI slots: drops survive, jitter does not
    synth::TrialSpec mjpeg = SmallClip("mjpeg-drops", synth::VideoCodec::kMjpeg);
    mjpeg.camera.drop_probability = 0.2;
    add(mjpeg);
    add(SmallClip("mjpeg", synth::VideoCodec::kMjpeg));
    // B-frames held back and drained at the end
    add(SmallClip("h264", synth::VideoCodec::kH264));
    synth::TrialSpec h264_vfr = SmallClip("h264-vfr", synth::VideoCodec::kH264);
    h264_vfr.camera.timestamp_jitter_s = 0.1 / 30.0;
    h264_vfr.camera.drop_probability = 0.1;
    add(h264_vfr);
  }
  static void TearDownTestSuite() {
    clips_.clear();
    scratch_.reset();
  }
  static const Clip& Get(const std::string& id) { return clips_.at(id); }
  static const ScratchDir& Scratch() { return *scratch_; }

 private:
  static inline std::unique_ptr<ScratchDir> scratch_;
  static inline std::map<std::string, Clip> clips_;
};

// Missing frames per interval by the nominal rate, from the truth.
int64_t TruthDrops(const std::vector<int64_t>& t_ns, double fps) {
  const double period_ns = 1e9 / fps;
  int64_t drops = 0;
  for (size_t i = 1; i < t_ns.size(); ++i) {
    drops += std::llround(static_cast<double>(t_ns[i] - t_ns[i - 1]) / period_ns) - 1;
  }
  return drops;
}

TEST_F(VideoReaderClips, Ffv1TimestampsEqualTheTruthExactly) {
  const Clip& clip = Get("ffv1-vfr");
  const ReadAll all = ReadFrames(clip.path);
  ASSERT_TRUE(all.status.ok()) << all.status.ToString();
  EXPECT_EQ(all.t_ns, clip.truth.frame_times_ns);
  EXPECT_EQ(all.timing.repaired_frames, 0);
  EXPECT_EQ(all.timing.frames, static_cast<int64_t>(clip.truth.frame_times_ns.size()));
  EXPECT_EQ(all.timing.first_ns, clip.truth.frame_times_ns.front());
  EXPECT_EQ(all.timing.last_ns, clip.truth.frame_times_ns.back());
}

TEST_F(VideoReaderClips, MjpegTimestampsAndDroppedFramesEqualTheTruth) {
  const Clip& clip = Get("mjpeg-drops");
  const ReadAll all = ReadFrames(clip.path);
  ASSERT_TRUE(all.status.ok()) << all.status.ToString();
  EXPECT_EQ(all.t_ns, clip.truth.frame_times_ns);
  const int64_t drops = TruthDrops(clip.truth.frame_times_ns, clip.fps);
  ASSERT_GT(drops, 3) << "the clip should have dropped frames";
  EXPECT_EQ(all.timing.dropped_frames, drops);
  EXPECT_EQ(all.timing.irregular_frames, 0);
  // each listed drop is where the truth has a gap of that many slots
  int64_t listed = 0;
  for (const TimingIrregularity& item : all.timing.irregularities) {
    ASSERT_EQ(item.kind, TimingIrregularity::Kind::kDropped);
    const auto i = static_cast<size_t>(item.frame_index);
    const double slots =
        static_cast<double>(clip.truth.frame_times_ns[i] - clip.truth.frame_times_ns[i - 1]) *
        clip.fps * 1e-9;
    EXPECT_EQ(item.missing_frames, std::llround(slots) - 1) << "frame " << i;
    listed += item.missing_frames;
  }
  EXPECT_EQ(listed, drops);
  // the container's count includes the empty slots; it is reported, not used
  EXPECT_EQ(all.timing.container_frames, all.timing.frames + drops);
  EXPECT_NEAR(static_cast<double>(all.timing.median_interval_ns), 1e9 / 30.0, 1e3);
  EXPECT_THAT(all.timing.Brief(), HasSubstr(std::to_string(drops) + " dropped"));
}

TEST_F(VideoReaderClips, H264TimesEqualTheTruthExactlyBFramesDrainedAtTheEndIncluded) {
  // (OpenCV 4.6's backend read 0 ms for the last two frames of this clip; decoded
  // directly, they carry their own times)
  for (const std::string id : {"h264", "h264-vfr"}) {
    const Clip& clip = Get(id);
    const ReadAll all = ReadFrames(clip.path);
    ASSERT_TRUE(all.status.ok()) << all.status.ToString();
    const std::vector<int64_t>& truth = clip.truth.frame_times_ns;
    ASSERT_EQ(all.t_ns.size(), truth.size()) << id;
    for (size_t i = 0; i < truth.size(); ++i) {
      EXPECT_EQ(all.t_ns[i], truth[i]) << id << " frame " << i;
      EXPECT_FALSE(all.repaired[i]) << id << " frame " << i;
    }
    EXPECT_EQ(all.timing.repaired_frames, 0) << id;
  }
}

// Copies `source`'s video packets into a Matroska file, packet `repeat` stamped with the
// previous packet's time: a file whose times do not increase (Matroska allows equal ones).
void RemuxWithRepeatedTime(const fs::path& source, const fs::path& target, int repeat) {
  AVFormatContext* input = nullptr;
  ASSERT_GE(avformat_open_input(&input, source.c_str(), nullptr, nullptr), 0);
  ASSERT_GE(avformat_find_stream_info(input, nullptr), 0);
  AVFormatContext* output = nullptr;
  ASSERT_GE(avformat_alloc_output_context2(&output, nullptr, "matroska", target.c_str()), 0);
  AVStream* in_stream = input->streams[0];
  AVStream* out_stream = avformat_new_stream(output, nullptr);
  ASSERT_NE(out_stream, nullptr);
  ASSERT_GE(avcodec_parameters_copy(out_stream->codecpar, in_stream->codecpar), 0);
  out_stream->codecpar->codec_tag = 0;
  out_stream->time_base = AVRational{1, 1000};
  ASSERT_GE(avio_open(&output->pb, target.c_str(), AVIO_FLAG_WRITE), 0);
  ASSERT_GE(avformat_write_header(output, nullptr), 0);
  AVPacket* packet = av_packet_alloc();
  int64_t previous = 0;
  for (int index = 0; av_read_frame(input, packet) >= 0; ++index) {
    av_packet_rescale_ts(packet, in_stream->time_base, out_stream->time_base);
    if (index == repeat) packet->pts = previous;
    packet->dts = packet->pts;
    previous = packet->pts;
    packet->stream_index = 0;
    ASSERT_GE(av_write_frame(output, packet), 0) << "packet " << index;
    av_packet_unref(packet);
  }
  av_packet_free(&packet);
  av_write_trailer(output);
  avio_closep(&output->pb);
  avformat_free_context(output);
  avformat_close_input(&input);
}

TEST_F(VideoReaderClips, ATimeThatDoesNotIncreaseIsRepairedFromTheMedianIntervalAndMarked) {
  const Clip& clip = Get("mjpeg");
  const fs::path repeated = Scratch() / "repeated-time.mkv";
  constexpr int kRepeat = 7;
  RemuxWithRepeatedTime(clip.path, repeated, kRepeat);
  const ReadAll all = ReadFrames(repeated);
  ASSERT_TRUE(all.status.ok()) << all.status.ToString();
  const std::vector<int64_t>& truth = clip.truth.frame_times_ns;
  ASSERT_EQ(all.t_ns.size(), truth.size());
  for (size_t i = 0; i < truth.size(); ++i) {
    EXPECT_EQ(all.repaired[i], i == kRepeat) << "frame " << i;
    // Matroska stores milliseconds; the repair extrapolates by the median interval
    EXPECT_NEAR(static_cast<double>(all.t_ns[i]), static_cast<double>(truth[i]), 1e6)
        << "frame " << i;
  }
  EXPECT_EQ(all.timing.repaired_frames, 1);
  ASSERT_FALSE(all.timing.irregularities.empty());
  EXPECT_EQ(all.timing.irregularities.front().kind, TimingIrregularity::Kind::kRepaired);
  EXPECT_EQ(all.timing.irregularities.front().frame_index, kRepeat);
  EXPECT_THAT(all.timing.Brief(), HasSubstr("1 repaired"));
}

TEST_F(VideoReaderClips, JitteredIntervalsAreReportedIrregular) {
  const Clip& clip = Get("ffv1-vfr");
  const ReadAll all = ReadFrames(clip.path);
  ASSERT_TRUE(all.status.ok()) << all.status.ToString();
  const std::vector<int64_t>& truth = clip.truth.frame_times_ns;
  const double period_ns = 1e9 / clip.fps;
  // the truth's intervals in nominal periods; the reader's tolerance is 0.25 of its
  // median (about the nominal period): flagged ones are off by more than 0.2, and every
  // interval off by more than 0.3 from a whole number of periods is flagged
  std::map<int64_t, TimingIrregularity::Kind> flagged;
  for (const TimingIrregularity& item : all.timing.irregularities) {
    flagged[item.frame_index] = item.kind;
  }
  int64_t clearly_off = 0;
  for (size_t i = 1; i < truth.size(); ++i) {
    const double periods = static_cast<double>(truth[i] - truth[i - 1]) / period_ns;
    const double off_whole = std::abs(periods - std::round(periods));
    const bool off_one = std::abs(periods - 1.0) > 0.3;
    const auto found = flagged.find(static_cast<int64_t>(i));
    if (off_one && (std::round(periods) < 2 || off_whole > 0.3)) {
      ++clearly_off;
      EXPECT_TRUE(found != flagged.end()) << "interval " << periods << " periods at frame " << i;
    }
    if (found != flagged.end() && found->second == TimingIrregularity::Kind::kIrregular) {
      EXPECT_GT(std::abs(periods - 1.0), 0.2) << "frame " << i;
    }
    if (found != flagged.end() && found->second == TimingIrregularity::Kind::kDropped) {
      EXPECT_GE(std::round(periods), 2.0) << "frame " << i;
      EXPECT_LT(off_whole, 0.3) << "frame " << i;
    }
  }
  EXPECT_GT(clearly_off, 2) << "the clip should have irregular intervals";
  EXPECT_GT(all.timing.irregular_frames, 0);
  // the usual interval is the nominal one (FFV1 stores milliseconds)
  EXPECT_NEAR(static_cast<double>(all.timing.median_interval_ns), period_ns, 0.05 * period_ns);
}

TEST_F(VideoReaderClips, ContainerRateIsReportedButNotUsed) {
  const ReadAll all = ReadFrames(Get("h264").path);
  ASSERT_TRUE(all.status.ok());
  EXPECT_NEAR(all.timing.container_fps, 30.0, 0.01);
  EXPECT_EQ(all.timing.container_frames, all.timing.frames);
}

TEST(VideoReader, MissingFileIsNotFoundNamingTheFile) {
  ScratchDir scratch;
  auto reader = VideoReader::Open(scratch / "no-such-clip.mp4");
  ASSERT_FALSE(reader.ok());
  EXPECT_EQ(reader.status().code(), StatusCode::kNotFound);
  EXPECT_THAT(reader.status().message(), HasSubstr("no-such-clip.mp4"));
}

TEST(VideoReader, TextFileIsNotAVideo) {
  ScratchDir scratch;
  const fs::path named_like_a_video = scratch / "text.mp4";
  ASSERT_TRUE(synth::WriteNotAVideo(named_like_a_video).ok());
  WriteFile(scratch / "notes.txt", "just some notes\n");
  for (const fs::path& path : {named_like_a_video, scratch / "notes.txt"}) {
    ::testing::internal::CaptureStderr();
    auto reader = VideoReader::Open(path);
    const std::string printed = ::testing::internal::GetCapturedStderr();
    ASSERT_FALSE(reader.ok()) << path;
    EXPECT_EQ(reader.status().code(), StatusCode::kParse);
    EXPECT_THAT(reader.status().message(), HasSubstr("not a video"));
    EXPECT_THAT(reader.status().message(), HasSubstr(path.filename().string()));
    EXPECT_EQ(printed, "") << "FFmpeg's complaints are caught, not printed";
  }
}

TEST(VideoReader, FolderIsNotAVideo) {
  ScratchDir scratch;
  auto reader = VideoReader::Open(scratch.path());
  ASSERT_FALSE(reader.ok());
  EXPECT_EQ(reader.status().code(), StatusCode::kParse);
}

TEST_F(VideoReaderClips, TruncatedFilesAreTruncatedOrDamagedInEveryContainer) {
  // cut after 3 % (H.264: the index is up front but the frames are gone; the others lose
  // their header or index), half, and 90 % of their bytes
  for (const std::string id : {"h264", "mjpeg-drops", "ffv1-vfr"}) {
    for (const double keep : {0.03, 0.5, 0.9}) {
      const fs::path whole = Get(id).path;
      const fs::path cut = Scratch() / ("cut-" + std::to_string(static_cast<int>(keep * 100)) +
                                        "-" + whole.filename().string());
      ASSERT_TRUE(synth::WriteTruncatedCopy(whole, cut, keep).ok());
      ::testing::internal::CaptureStderr();
      const ReadAll all = ReadFrames(cut);
      const std::string printed = ::testing::internal::GetCapturedStderr();
      EXPECT_EQ(all.status.code(), StatusCode::kParse) << cut << ": " << all.status.ToString();
      EXPECT_THAT(all.status.message(), HasSubstr("truncated or damaged")) << cut;
      EXPECT_THAT(all.status.message(), HasSubstr(cut.filename().string()));
      EXPECT_EQ(printed, "") << cut;
      // the frames returned before the damage was found carry the truth's times
      for (size_t i = 0; i + 2 < all.t_ns.size() && id != "h264"; ++i) {
        EXPECT_EQ(all.t_ns[i], Get(id).truth.frame_times_ns[i]) << cut << " frame " << i;
      }
    }
  }
}

TEST(VideoReader, OptionsOutOfRangeAreNamed) {
  VideoReader::Options options;
  options.irregular_tolerance_frac = 1.5;
  EXPECT_THAT(options.Validate().message(), HasSubstr("irregular_tolerance_frac"));
  options = {};
  options.median_window_frames = 2;
  EXPECT_THAT(options.Validate().message(), HasSubstr("median_window_frames"));
  options = {};
  options.max_listed = -1;
  EXPECT_THAT(options.Validate().message(), HasSubstr("max_listed"));
  EXPECT_TRUE(VideoReader::Options{}.Validate().ok());
  ScratchDir scratch;
  auto reader = VideoReader::Open(scratch / "x.mp4", options);
  EXPECT_EQ(reader.status().code(), StatusCode::kInvalidArgument);
}

TEST(FrameTimingReport, BriefSaysFramesRateAndCounts) {
  FrameTimingReport report;
  report.frames = 1432;
  report.fps = 60.0;
  report.median_interval_ns = 16'666'667;
  report.dropped_frames = 3;
  report.repaired_frames = 2;
  EXPECT_EQ(report.Brief(),
            "1432 frames at 60.00 fps, 16.667 ms median interval, 3 dropped, 2 repaired, 0 "
            "irregular");
}

}  // namespace
}  // namespace liftoff::video
