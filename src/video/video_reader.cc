#include "liftoff/video/video_reader.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <cctype>
#include <cmath>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <deque>
#include <fstream>
#include <mutex>
#include <string_view>
#include <system_error>
#include <utility>

extern "C" {
#include <libavutil/log.h>
}

#include "liftoff/core/file.h"
#include "liftoff/core/text.h"
#include "liftoff/core/time.h"
#include "av_decoder.h"
#include "keyframes.h"
#include "video_util.h"

namespace liftoff::video {
namespace {

namespace fs = std::filesystem;

// What FFmpeg logged on one thread while it decoded for a reader.
struct DecoderLog {
  int64_t errors = 0;
  std::string first_error;
};

// FFmpeg prints demuxer and decoder complaints about damaged files straight to stderr,
// many per file. liftoff reports damage through its own errors, so while any reader is
// decoding, FFmpeg's messages are caught instead of printed: those logged on the
// reader's thread (the demuxer's) are counted and the first kept for the message; those
// of the decoder's worker threads are dropped. Otherwise messages go to FFmpeg's own
// printer as before. OpenCV (whose writer liftoff uses) resets FFmpeg's level at every
// open, not its printer, so the printer is the place to filter.
using AvLogCallback = void (*)(void*, int, const char*, va_list);
std::atomic<int> g_readers_inside{0};
thread_local DecoderLog* t_decoder_log = nullptr;
AvLogCallback g_default_printer = nullptr;

void FilterDecoderLog(void* context, int level, const char* format, va_list arguments) {
  if (g_readers_inside.load(std::memory_order_relaxed) == 0) {
    if (g_default_printer != nullptr) g_default_printer(context, level, format, arguments);
    return;
  }
  DecoderLog* log = t_decoder_log;
  if (log == nullptr || level > AV_LOG_ERROR) return;
  ++log->errors;
  if (log->first_error.empty()) {
    std::array<char, 256> text{};
    va_list copy;
    va_copy(copy, arguments);
    std::vsnprintf(text.data(), text.size(), format, copy);
    va_end(copy);
    log->first_error = text.data();
    while (!log->first_error.empty() &&
           (log->first_error.back() == '\n' || log->first_error.back() == ' ')) {
      log->first_error.pop_back();
    }
  }
}

// Installs the filter once per process.
void InstallDecoderLogFilter() {
  static const bool installed = [] {
    g_default_printer = &av_log_default_callback;
    av_log_set_callback(&FilterDecoderLog);
    return true;
  }();
  static_cast<void>(installed);
}

// While alive, FFmpeg's messages on this thread go to `log`.
class CatchDecoderLog {
 public:
  explicit CatchDecoderLog(DecoderLog& log) : previous_(t_decoder_log) {
    InstallDecoderLogFilter();
    t_decoder_log = &log;
    g_readers_inside.fetch_add(1, std::memory_order_relaxed);
  }
  ~CatchDecoderLog() {
    g_readers_inside.fetch_sub(1, std::memory_order_relaxed);
    t_decoder_log = previous_;
  }
  CatchDecoderLog(const CatchDecoderLog&) = delete;
  CatchDecoderLog& operator=(const CatchDecoderLog&) = delete;

 private:
  DecoderLog* previous_;
};

// codecs that keep every pixel: FFV1, HuffYUV, UtVideo, PNG, raw pictures (unknown: lossy)
bool IsLosslessCodec(std::string fourcc) {
  while (!fourcc.empty() && fourcc.back() == ' ') fourcc.pop_back();
  for (char& c : fourcc) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  for (std::string_view lossless : {"FFV1", "HFYU", "FFVH", "ULRG", "ULRA", "ULY0", "ULY2", "ULY4",
                                    "ULH0", "ULH2", "PNG", "MPNG", "RAW", "I420"}) {
    if (fourcc == lossless) return true;
  }
  return false;
}

// A file's first bytes, for recognising what it is by its signature.
class FileHead {
 public:
  explicit FileHead(const fs::path& path) {
    std::ifstream file(path, std::ios::binary);
    file.read(bytes_.data(), static_cast<std::streamsize>(bytes_.size()));
    size_ = static_cast<size_t>(file.gcount());
  }
  // whether `text` stands at `offset`
  bool Has(size_t offset, std::string_view text) const {
    return size_ >= offset + text.size() &&
           std::memcmp(bytes_.data() + offset, text.data(), text.size()) == 0;
  }

 private:
  std::array<char, 12> bytes_{};
  size_t size_ = 0;
};

// Whether the file starts like a container liftoff expects a camera video in: an MP4 /
// QuickTime box, Matroska's EBML magic or a RIFF AVI header.
bool LooksLikeVideoContainer(const fs::path& path) {
  const FileHead head(path);
  const auto has = [&](size_t offset, std::string_view text) { return head.Has(offset, text); };
  for (const char* box : {"ftyp", "moov", "mdat", "free", "skip", "wide"}) {
    if (has(4, box)) return true;
  }
  if (has(0, "\x1A\x45\xDF\xA3")) return true;
  return has(0, "RIFF") && (has(8, "AVI ") || has(8, "AVIX"));
}

// The kind of still picture the file starts like ("PNG", "JPEG", ...), or empty.
std::string_view StillImageKind(const fs::path& path) {
  const FileHead head(path);
  const auto has = [&](size_t offset, std::string_view text) { return head.Has(offset, text); };
  if (has(0, "\x89PNG\r\n\x1a\n")) return "PNG";
  if (has(0, "\xff\xd8\xff")) return "JPEG";
  if (has(0, "GIF87a") || has(0, "GIF89a")) return "GIF";
  if (has(0, "BM")) return "BMP";
  if (has(0, "II*") || has(0, std::string_view("MM\0*", 4))) return "TIFF";
  if (has(0, "RIFF") && has(8, "WEBP")) return "WebP";
  return {};
}

// The median of every interval of a clip in fixed memory: intervals are counted in bins
// 2^(1/256) wide (0.27 %) from 2^13 ns (8 us) to 2^37 ns (137 s); the median is the mean
// of the intervals in the median's bin, exact for a constant frame rate.
class IntervalHistogram {
 public:
  void Add(int64_t interval_ns) {
    const size_t bin = BinOf(interval_ns);
    ++counts_[bin];
    sums_ns_[bin] += interval_ns;
    ++total_;
  }
  int64_t Median() const {
    if (total_ == 0) return 0;
    const int64_t wanted = (total_ + 1) / 2;
    int64_t seen = 0;
    for (size_t bin = 0; bin < kBins; ++bin) {
      seen += counts_[bin];
      if (seen >= wanted) return sums_ns_[bin] / counts_[bin];
    }
    return 0;
  }

 private:
  static constexpr int kLowExponent = 13, kHighExponent = 37, kBinsPerOctave = 256;
  static constexpr size_t kBins = (kHighExponent - kLowExponent) * kBinsPerOctave;
  static size_t BinOf(int64_t interval_ns) {
    const double position =
        (std::log2(static_cast<double>(std::max<int64_t>(interval_ns, 1))) - kLowExponent) *
        kBinsPerOctave;
    return static_cast<size_t>(std::clamp(position, 0.0, static_cast<double>(kBins - 1)));
  }
  std::vector<int64_t> counts_ = std::vector<int64_t>(kBins, 0);
  std::vector<int64_t> sums_ns_ = std::vector<int64_t>(kBins, 0);
  int64_t total_ = 0;
};

// One frame's interval to its predecessor, waiting to be judged against the intervals
// around it.
struct IntervalEntry {
  int64_t frame_index = 0;
  int64_t t_ns = 0;
  int64_t interval_ns = 0;
  bool repaired = false;
  bool judged = false;
};

}  // namespace

Status VideoReader::Options::Validate() const {
  if (!(irregular_tolerance_frac > 0.0 && irregular_tolerance_frac < 1.0)) {
    return InvalidArgumentError("irregular_tolerance_frac: expected 0 < x < 1, got " +
                                std::to_string(irregular_tolerance_frac));
  }
  if (median_window_frames < 3) {
    return InvalidArgumentError("median_window_frames: expected >= 3, got " +
                                std::to_string(median_window_frames));
  }
  if (max_listed < 0) {
    return InvalidArgumentError("max_listed: expected >= 0, got " + std::to_string(max_listed));
  }
  if (decoder_threads < 0 || decoder_threads > 64) {
    return InvalidArgumentError("decoder_threads: expected an integer in [0, 64], got " +
                                std::to_string(decoder_threads));
  }
  return Status::Ok();
}

std::string FrameTimingReport::Brief() const {
  std::string text = Plural(frames, "frame");
  if (fps > 0) text += " at " + FormatFixed(fps, 2) + " fps";
  if (median_interval_ns > 0) {
    text += ", " + FormatFixed(static_cast<double>(median_interval_ns) * 1e-6, 3) +
            " ms median interval";
  }
  text += ", " + std::to_string(dropped_frames) + " dropped, " + std::to_string(repaired_frames) +
          " repaired, " + std::to_string(irregular_frames) + " irregular";
  if (decoder_errors > 0) text += ", " + Plural(decoder_errors, "decoder error");
  return text;
}

struct VideoReader::Impl {
  fs::path path;
  std::string name;  // the file as messages show it
  Options options;
  std::unique_ptr<internal::AvDecoder> decoder;
  int width_px = 0, height_px = 0;
  // the regions of each frame converted to BGR (empty: the whole picture)
  std::vector<cv::Rect> regions_px;

  // frame 0, decoded by Open to tell a video from a damaged file
  cv::Mat first_bgr;
  double first_ms = 0.0;
  bool first_pending = true;
  bool ended = false;
  // the key frames' presentation times, ns (empty when unknown)
  std::vector<int64_t> keyframe_times_ns;

  int64_t next_index = 0;
  int64_t last_ns = 0;  // the last time handed out (read or repaired)

  // the last median_window_frames intervals: each is judged against their median when it
  // is at the window's centre, and a repair extrapolates by it
  std::deque<IntervalEntry> window;
  IntervalHistogram histogram;
  FrameTimingReport report;
  DecoderLog decoder_log;

  // "; FFmpeg: moov atom not found" when FFmpeg complained, else empty
  std::string FfmpegSays() const {
    return decoder_log.first_error.empty() ? std::string() : "; FFmpeg: " + decoder_log.first_error;
  }

  int64_t WindowMedianNs() const {
    std::vector<int64_t> read;
    for (const IntervalEntry& entry : window) {
      if (!entry.repaired) read.push_back(entry.interval_ns);
    }
    return MedianOf(std::move(read));
  }

  void Judge(IntervalEntry& entry, int64_t median_ns) {
    entry.judged = true;
    TimingIrregularity irregularity;
    irregularity.frame_index = entry.frame_index;
    irregularity.t_ns = entry.t_ns;
    irregularity.interval_ns = entry.interval_ns;
    if (entry.repaired) {
      irregularity.kind = TimingIrregularity::Kind::kRepaired;
    } else {
      if (median_ns <= 0) return;
      const double ratio = static_cast<double>(entry.interval_ns) / static_cast<double>(median_ns);
      const double multiple = std::round(ratio);
      const double tolerance = options.irregular_tolerance_frac;
      if (multiple >= 2.0 && std::abs(ratio - multiple) <= tolerance) {
        irregularity.kind = TimingIrregularity::Kind::kDropped;
        irregularity.missing_frames = static_cast<int64_t>(multiple) - 1;
        report.dropped_frames += irregularity.missing_frames;
      } else if (std::abs(ratio - 1.0) > tolerance) {
        irregularity.kind = TimingIrregularity::Kind::kIrregular;
        ++report.irregular_frames;
      } else {
        return;
      }
    }
    if (static_cast<int64_t>(report.irregularities.size()) < options.max_listed) {
      report.irregularities.push_back(irregularity);
    }
  }

  // judges the interval at the window's centre once the window is full (at the first
  // fill, every interval before the centre too)
  void JudgeCentre() {
    const auto size = static_cast<size_t>(options.median_window_frames);
    if (window.size() < size) return;
    const int64_t median_ns = WindowMedianNs();
    for (size_t i = 0; i <= size / 2; ++i) {
      if (!window[i].judged) Judge(window[i], median_ns);
    }
  }

  void Record(int64_t index, int64_t t_ns, bool repaired) {
    if (index == 0) {
      report.first_ns = t_ns;
    } else {
      IntervalEntry entry;
      entry.frame_index = index;
      entry.t_ns = t_ns;
      entry.interval_ns = t_ns - last_ns;
      entry.repaired = repaired;
      if (!repaired) histogram.Add(entry.interval_ns);
      window.push_back(entry);
      if (window.size() > static_cast<size_t>(options.median_window_frames)) window.pop_front();
      JudgeCentre();
    }
    if (repaired) ++report.repaired_frames;
    report.frames = index + 1;
    report.last_ns = t_ns;
    last_ns = t_ns;
  }

  // at the end: the intervals not yet judged, against the last window
  void FinishReport() {
    const int64_t median_ns = WindowMedianNs();
    for (IntervalEntry& entry : window) {
      if (!entry.judged) Judge(entry, median_ns);
    }
    report.median_interval_ns = histogram.Median();
    const int64_t span_ns = report.last_ns - report.first_ns;
    report.fps = report.frames > 1 && span_ns > 0
                     ? static_cast<double>(report.frames - 1 + report.dropped_frames) /
                           SecondsFromNs(span_ns)
                     : 0.0;
    report.decoder_errors = decoder_log.errors;
    report.first_decoder_error = decoder_log.first_error;
  }

  // the frame's time: what the decoder says when it increases, else extrapolated
  int64_t TimeOf(int64_t index, double position_ms, bool& repaired) {
    repaired = false;
    const double read_ns = std::isfinite(position_ms) ? std::round(position_ms * 1e6) : 0.0;
    const auto t_ns = static_cast<int64_t>(read_ns);
    if (index == 0 || t_ns > last_ns) return t_ns;
    repaired = true;
    int64_t step_ns = WindowMedianNs();
    if (step_ns <= 0) {
      // no interval read yet: the container's rate is the only guess left
      step_ns = report.container_fps > 0 ? NsFromSeconds(1.0 / report.container_fps)
                                         : kNanosecondsPerSecond / 30;
    }
    return last_ns + std::max<int64_t>(step_ns, 1);
  }

  // the stream ended: damaged when it stopped short of what the container lists, in
  // frames and in time (a variable-rate file lists fewer frames than its nominal rate
  // implies, an AVI with dropped slots more than it holds; neither is short in both): by
  // a tenth, or by two frames when FFmpeg also complained
  Status CheckEnd() const {
    const double listed = static_cast<double>(report.container_frames);
    if (listed <= 0 || report.container_fps <= 0) return Status::Ok();
    const double listed_s = listed / report.container_fps;
    const double decoded_s = SecondsFromNs(report.last_ns - report.first_ns) +
                             (report.frames > 0 ? 1.0 / report.container_fps : 0.0);
    const double missing_frames = listed - static_cast<double>(report.frames);
    const double missing_s = listed_s - decoded_s;
    const double tolerance = decoder_log.errors > 0 ? 1.5 : std::max(1.5, 0.1 * listed);
    const bool short_in_frames = missing_frames > tolerance;
    const bool short_in_time = missing_s > tolerance / report.container_fps;
    if (!(short_in_frames && short_in_time)) return Status::Ok();
    return ParseError(name + ": truncated or damaged: decoding stopped after frame " +
                      std::to_string(report.frames - 1) + " (" +
                      FormatFixed(SecondsFromNs(report.last_ns), 3) + " s) of the " +
                      std::to_string(report.container_frames) + " frames (" +
                      FormatFixed(listed_s, 3) + " s) the container lists" + FfmpegSays());
  }
};

Result<VideoReader> VideoReader::Open(const fs::path& path, const Options& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate().WithContext("video reader options"));
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->name = DisplayPath(path);
  impl->options = options;

  std::error_code error;
  const fs::file_status status = fs::status(path, error);
  if (fs::is_directory(status)) return ParseError(impl->name + ": not a video (a folder)");
  LIFTOFF_RETURN_IF_ERROR(CheckRegularFile(path));
  // FFmpeg opens a still picture as a one-frame clip, whatever the file's name
  if (const std::string_view image = StillImageKind(path); !image.empty()) {
    return ParseError(impl->name + ": not a video (a " + std::string(image) + " picture)");
  }

  const bool container = LooksLikeVideoContainer(path);
  const auto damaged = [&](const std::string& why) {
    return container ? ParseError(impl->name + ": truncated or damaged: " + why)
                     : ParseError(impl->name + ": not a video (" + why + ")");
  };

  {
    CatchDecoderLog catching(impl->decoder_log);
    Result<std::unique_ptr<internal::AvDecoder>> decoder =
        internal::AvDecoder::Open(path.string(), options.decoder_threads);
    if (!decoder.ok()) {
      return damaged("no decoder could open it (" + decoder.status().message() + ")" +
                     impl->FfmpegSays());
    }
    impl->decoder = std::move(decoder).value();
    const internal::StreamFacts& facts = impl->decoder->facts();
    impl->report.container_fps = facts.fps;
    impl->report.codec_fourcc = facts.fourcc;
    impl->report.lossless_codec = IsLosslessCodec(impl->report.codec_fourcc);
    impl->report.container_frames = facts.frames;
    if (!impl->decoder->Next()) {
      return damaged("no frame could be decoded" + impl->FfmpegSays());
    }
    impl->decoder->ToBgr({}, impl->first_bgr);
    impl->first_ms = impl->decoder->position_ms();
  }
  if (impl->first_bgr.empty()) return damaged("no frame could be decoded" + impl->FfmpegSays());
  impl->width_px = impl->first_bgr.cols;
  impl->height_px = impl->first_bgr.rows;
  {
    DecoderLog ignored;  // a damaged file's complaints were counted once already
    CatchDecoderLog catching(ignored);
    Result<std::vector<int64_t>> keyframes = internal::ReadKeyframeTimesNs(path);
    if (keyframes.ok() && !keyframes->empty()) {
      impl->keyframe_times_ns = std::move(*keyframes);
      impl->report.keyframes_known = true;
    }
  }
  return VideoReader(std::move(impl));
}

VideoReader::VideoReader(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
VideoReader::VideoReader(VideoReader&&) noexcept = default;
VideoReader& VideoReader::operator=(VideoReader&&) noexcept = default;
VideoReader::~VideoReader() = default;

Result<bool> VideoReader::Next(Frame& frame) {
  Impl& impl = *impl_;
  if (impl.ended) return false;
  double position_ms = 0.0;
  if (impl.first_pending) {
    impl.first_pending = false;
    frame.bgr = std::move(impl.first_bgr);
    position_ms = impl.first_ms;
  } else {
    bool decoded = false;
    {
      CatchDecoderLog catching(impl.decoder_log);
      decoded = impl.decoder->Next();
      if (decoded) {
        impl.decoder->ToBgr(impl.regions_px, frame.bgr);
        position_ms = impl.decoder->position_ms();
      }
    }
    if (!decoded) {
      impl.ended = true;
      impl.decoder.reset();
      impl.FinishReport();
      LIFTOFF_RETURN_IF_ERROR(impl.CheckEnd());
      return false;
    }
    if (frame.bgr.cols != impl.width_px || frame.bgr.rows != impl.height_px) {
      impl.ended = true;
      impl.FinishReport();
      return UnsupportedError(impl.name + ": frame " + std::to_string(impl.next_index) +
                              " changes the picture size to " + std::to_string(frame.bgr.cols) +
                              "x" + std::to_string(frame.bgr.rows));
    }
  }
  bool repaired = false;
  frame.index = impl.next_index++;
  frame.t_ns = impl.TimeOf(frame.index, position_ms, repaired);
  frame.t_repaired = repaired;
  // a key frame by its time (within a tenth of a millisecond: the decoder's times are the
  // same packets' times in ms); unknown: every frame is one
  frame.keyframe = !impl.report.keyframes_known ||
                   (!repaired && internal::NearAny(impl.keyframe_times_ns, frame.t_ns, 100000));
  if (frame.keyframe) ++impl.report.keyframes;
  impl.Record(frame.index, frame.t_ns, repaired);
  return true;
}

void VideoReader::ConvertOnly(std::vector<cv::Rect> regions_px) {
  impl_->regions_px = std::move(regions_px);
}

int VideoReader::width_px() const { return impl_->width_px; }
int VideoReader::height_px() const { return impl_->height_px; }
const fs::path& VideoReader::path() const { return impl_->path; }
const FrameTimingReport& VideoReader::timing() const { return impl_->report; }

}  // namespace liftoff::video
