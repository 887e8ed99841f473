#include "liftoff/synth/video_writer.h"

#include <algorithm>
#include <cmath>
#include <mutex>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/error.h>
#include <libavutil/imgutils.h>
#include <libavutil/log.h>
#include <libavutil/mathematics.h>
#include <libavutil/opt.h>
#include <libswscale/swscale.h>
}

#include "liftoff/core/file.h"
#include "liftoff/core/json.h"
#include "liftoff/core/time.h"

namespace liftoff::synth {
namespace {

constexpr AVRational kNanosecondTimeBase{1, 1'000'000'000};

std::string AvErrorText(int error) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(error, text, sizeof(text));
  return text;
}

// What each codec needs from FFmpeg.
struct CodecChoice {
  const char* encoder;
  const char* muxer;
  AVPixelFormat pixel_format;
};

CodecChoice ChoiceFor(VideoCodec codec) {
  switch (codec) {
    case VideoCodec::kH264: return {"libx264", "mp4", AV_PIX_FMT_YUV420P};
    case VideoCodec::kMjpeg: return {"mjpeg", "avi", AV_PIX_FMT_YUVJ420P};
    case VideoCodec::kFfv1: return {"ffv1", "matroska", AV_PIX_FMT_BGR0};
  }
  return {"", "", AV_PIX_FMT_NONE};
}

// The time base the container will keep, so the encoder counts in it directly and the
// only rounding is the one StoredPtsNs() reports.
AVRational ContainerTimeBase(const VideoWriterOptions& options) {
  switch (options.codec) {
    case VideoCodec::kH264: return {1, static_cast<int>(options.time_base_den)};
    case VideoCodec::kMjpeg: return av_inv_q(av_d2q(options.nominal_fps, 1'000'000));
    case VideoCodec::kFfv1: return {1, 1000};
  }
  return {1, 1000};
}

void QuietenFfmpegOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    if (av_log_get_level() > AV_LOG_WARNING) av_log_set_level(AV_LOG_WARNING);
  });
}

std::filesystem::path PartialPath(const std::filesystem::path& path) {
  std::filesystem::path partial = path;
  partial += ".partial";
  return partial;
}

}  // namespace

Status VideoWriterOptions::Validate() const {
  // "<field>: expected <range>[ <why>], got <value>" when out of range
  const auto check = [](std::string_view field, double value, const NumberRange& range,
                        std::string_view why = "") -> Status {
    if (InNumberRange(value, range)) return Status::Ok();
    return InvalidArgumentError(std::string(field) + ": expected " +
                                DescribeNumberRange(range, true) + std::string(why) + ", got " +
                                FormatNumber(value));
  };
  const bool chroma_halved = codec != VideoCodec::kFfv1;
  for (const auto& [name, value] :
       {std::pair{"width_px", width_px}, std::pair{"height_px", height_px}}) {
    LIFTOFF_RETURN_IF_ERROR(check(name, value, {.min = 16, .max = 4096}, " px"));
    if (chroma_halved && value % 2 != 0) {
      return InvalidArgumentError(std::string(name) + ": expected an even size for " +
                                  std::string(VideoCodecName(codec)) + " (4:2:0 chroma), got " +
                                  std::to_string(value));
    }
  }
  if (constexpr NumberRange kFps{.min = 1, .max = 1000}; !InNumberRange(nominal_fps, kFps)) {
    return InvalidArgumentError("nominal_fps: expected " + DescribeNumberRange(kFps) + " Hz, got " +
                                FormatNumber(nominal_fps));
  }
  if (codec == VideoCodec::kH264) {
    LIFTOFF_RETURN_IF_ERROR(check("quality", quality, {.min = 0, .max = 51}, " (CRF for h264)"));
  } else if (codec == VideoCodec::kMjpeg) {
    LIFTOFF_RETURN_IF_ERROR(check("quality", quality, {.min = 2, .max = 31}, " (q:v for mjpeg)"));
  }
  LIFTOFF_RETURN_IF_ERROR(check("keyframe_interval_frames", keyframe_interval_frames,
                                {.min = 0, .max = 10'000}, " frames (0: one a nominal second)"));
  return check("time_base_den", static_cast<double>(time_base_den),
               {.min = 10'000, .max = 1'000'000'000}, " ticks per second");
}

struct VideoWriter::Impl {
  std::filesystem::path path;
  std::filesystem::path partial_path;
  VideoWriterOptions options;
  AVFormatContext* format = nullptr;
  AVCodecContext* encoder = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  SwsContext* converter = nullptr;
  cv::Mat padded;  // a picture of odd row length, copied for swscale (see Write)
  bool created = false;  // `partial_path` is ours
  bool closed = false;
  bool in_place = false;  // renamed onto `path`
  Status error;           // the first failure; sticky
  int64_t frames = 0;
  int64_t last_pts_ns = -1;
  int64_t last_tick = -1;

  ~Impl() {
    sws_freeContext(converter);
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&encoder);
    if (format != nullptr) {
      if (format->pb != nullptr) avio_closep(&format->pb);
      avformat_free_context(format);
    }
    if (created && !in_place) {
      std::error_code ignored;
      std::filesystem::remove(partial_path, ignored);
    }
  }

  std::string Where() const { return DisplayPath(path); }

  Status Fail(StatusCode code, const std::string& what) {
    if (error.ok()) error = Status(code, Where() + ": " + what);
    return error;
  }
  Status FailAv(const std::string& what, int av_error) {
    return Fail(StatusCode::kIo, what + ": " + AvErrorText(av_error));
  }

  int64_t TickFromNs(int64_t pts_ns) const {
    return av_rescale_q(pts_ns, kNanosecondTimeBase, encoder->time_base);
  }

  // Moves every packet the encoder has ready into the file.
  Status DrainPackets() {
    while (true) {
      const int received = avcodec_receive_packet(encoder, packet);
      if (received == AVERROR(EAGAIN) || received == AVERROR_EOF) return Status::Ok();
      if (received < 0) return FailAv("encoding failed", received);
      if (packet->duration == 0) {
        packet->duration = av_rescale_q(1, av_inv_q(encoder->framerate), encoder->time_base);
      }
      av_packet_rescale_ts(packet, encoder->time_base, stream->time_base);
      packet->stream_index = stream->index;
      const int written = av_interleaved_write_frame(format, packet);
      if (written < 0) return FailAv("writing a frame failed", written);
    }
  }

  // --- opening, in order: contexts, encoder, file, colour conversion ---

  // FFmpeg's encoder, muxer, frame and packet for `choice`
  Status AllocateContexts(const CodecChoice& choice, const AVCodec*& codec) {
    codec = avcodec_find_encoder_by_name(choice.encoder);
    if (codec == nullptr) {
      return UnsupportedError(Where() + ": this FFmpeg has no " + choice.encoder + " encoder");
    }
    const int created_format =
        avformat_alloc_output_context2(&format, nullptr, choice.muxer, partial_path.c_str());
    if (created_format < 0 || format == nullptr) {
      return UnsupportedError(Where() + ": this FFmpeg has no " + choice.muxer +
                              " muxer: " + AvErrorText(created_format));
    }
    encoder = avcodec_alloc_context3(codec);
    frame = av_frame_alloc();
    packet = av_packet_alloc();
    if (encoder == nullptr || frame == nullptr || packet == nullptr) {
      return IoError(Where() + ": out of memory");
    }
    return Status::Ok();
  }

  // the encoder's settings, common then per codec, and the encoder opened
  Status OpenEncoder(const AVCodec* codec, const CodecChoice& choice) {
    encoder->width = options.width_px;
    encoder->height = options.height_px;
    encoder->pix_fmt = choice.pixel_format;
    encoder->time_base = ContainerTimeBase(options);
    encoder->framerate = av_d2q(options.nominal_fps, 1'000'000);
    encoder->gop_size = options.keyframe_interval_frames > 0
                            ? options.keyframe_interval_frames
                            : std::max(1, static_cast<int>(std::lround(options.nominal_fps)));
    encoder->sample_aspect_ratio = {1, 1};
    // bit-exact: no random segment id, no version strings; the same frames give the same bytes
    format->flags |= AVFMT_FLAG_BITEXACT;
    encoder->flags |= AV_CODEC_FLAG_BITEXACT;
    if ((format->oformat->flags & AVFMT_GLOBALHEADER) != 0) {
      encoder->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
    }
    SetCodecSettings();
    if (const int opened = avcodec_open2(encoder, codec, nullptr); opened < 0) {
      return UnsupportedError(Where() + ": cannot open the " + choice.encoder +
                              " encoder: " + AvErrorText(opened));
    }
    return Status::Ok();
  }

  void SetCodecSettings() {
    switch (options.codec) {
      case VideoCodec::kH264:
        // b-adapt=0: every run of non-key frames uses both B-frames, whatever the content
        encoder->max_b_frames = 2;
        encoder->thread_count = 2;  // fixed, so the bytes do not depend on the machine
        av_opt_set(encoder->priv_data, "preset", "veryfast", 0);
        av_opt_set(encoder->priv_data, "crf", std::to_string(options.quality).c_str(), 0);
        av_opt_set(encoder->priv_data, "x264-params", "b-adapt=0", 0);
        break;
      case VideoCodec::kMjpeg:
        encoder->color_range = AVCOL_RANGE_JPEG;
        encoder->flags |= AV_CODEC_FLAG_QSCALE;
        encoder->global_quality = FF_QP2LAMBDA * options.quality;
        break;
      case VideoCodec::kFfv1:
        // version 3 with 4 slices encodes the slices in parallel; slices, not threads,
        // decide the bytes, so the output stays the same on any machine
        encoder->thread_count = 2;
        encoder->thread_type = FF_THREAD_SLICE;
        av_opt_set_int(encoder->priv_data, "slices", 4, 0);
        av_opt_set_int(encoder->priv_data, "slicecrc", 1, 0);
        encoder->level = 3;
        break;
    }
  }

  // the stream, the .partial file and the container's header
  Status OpenFile() {
    stream = avformat_new_stream(format, nullptr);
    if (stream == nullptr) return IoError(Where() + ": out of memory");
    avcodec_parameters_from_context(stream->codecpar, encoder);
    stream->time_base = encoder->time_base;
    stream->avg_frame_rate = encoder->framerate;
    if (const Status folder = CreateParentFolder(path); !folder.ok()) {
      return IoError(Where() + ": cannot create the file: " + folder.message());
    }
    if (const int opened = avio_open(&format->pb, partial_path.c_str(), AVIO_FLAG_WRITE);
        opened < 0) {
      return IoError(Where() + ": cannot create the file: " + AvErrorText(opened));
    }
    created = true;
    AVDictionary* muxer_options = nullptr;
    if (options.codec == VideoCodec::kH264)
      av_dict_set(&muxer_options, "movflags", "+faststart", 0);
    const int header = avformat_write_header(format, &muxer_options);
    av_dict_free(&muxer_options);
    if (header < 0) {
      return IoError(Where() + ": cannot write the header: " + AvErrorText(header));
    }
    // the muxer may have changed the stream's time base; packets are rescaled to it
    // and StoredPtsNs() follows both roundings
    return Status::Ok();
  }

  // frame buffer and colour conversion
  Status PrepareConversion() {
    frame->format = encoder->pix_fmt;
    frame->width = encoder->width;
    frame->height = encoder->height;
    if (const int allocated = av_frame_get_buffer(frame, 0); allocated < 0) {
      return IoError(Where() + ": cannot allocate a frame: " + AvErrorText(allocated));
    }
    // yuvj420p is yuv420p at full range; naming it that way keeps swscale from warning
    const AVPixelFormat convert_to =
        encoder->pix_fmt == AV_PIX_FMT_YUVJ420P ? AV_PIX_FMT_YUV420P : encoder->pix_fmt;
    converter = sws_getContext(options.width_px, options.height_px, AV_PIX_FMT_BGR24,
                               options.width_px, options.height_px, convert_to,
                               SWS_BICUBIC | SWS_ACCURATE_RND, nullptr, nullptr, nullptr);
    if (converter == nullptr) {
      return UnsupportedError(Where() + ": no colour conversion from BGR to " +
                              av_get_pix_fmt_name(convert_to));
    }
    if (options.codec != VideoCodec::kFfv1) {
      const int full_range = options.codec == VideoCodec::kMjpeg ? 1 : 0;
      const int* bt601 = sws_getCoefficients(SWS_CS_ITU601);
      sws_setColorspaceDetails(converter, bt601, 1, bt601, full_range, 0, 1 << 16, 1 << 16);
    }
    return Status::Ok();
  }
};

VideoWriter::VideoWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

// Without Close() the file is unfinished: Impl's destructor deletes the .partial file.
VideoWriter::~VideoWriter() = default;

Result<std::unique_ptr<VideoWriter>> VideoWriter::Open(const std::filesystem::path& path,
                                                       const VideoWriterOptions& options) {
  LIFTOFF_RETURN_IF_ERROR(options.Validate().WithContext(DisplayPath(path)));
  const std::string_view extension = VideoCodecExtension(options.codec);
  if (path.extension() != extension) {
    return InvalidArgumentError(DisplayPath(path) + ": " +
                                std::string(VideoCodecName(options.codec)) + " video goes in a " +
                                std::string(extension) + " file");
  }
  QuietenFfmpegOnce();
  auto impl = std::make_unique<Impl>();
  impl->path = path;
  impl->partial_path = PartialPath(path);
  impl->options = options;
  const CodecChoice choice = ChoiceFor(options.codec);
  const AVCodec* codec = nullptr;
  LIFTOFF_RETURN_IF_ERROR(impl->AllocateContexts(choice, codec));
  LIFTOFF_RETURN_IF_ERROR(impl->OpenEncoder(codec, choice));
  LIFTOFF_RETURN_IF_ERROR(impl->OpenFile());
  LIFTOFF_RETURN_IF_ERROR(impl->PrepareConversion());
  return std::unique_ptr<VideoWriter>(new VideoWriter(std::move(impl)));
}

Status VideoWriter::Write(const cv::Mat& bgr, int64_t pts_ns) {
  Impl& impl = *impl_;
  assert(!impl.closed && "Write() after Close()");
  if (!impl.error.ok()) return impl.error;
  // the frame's name, built only for an error
  const auto frame_name = [&impl] { return "frame " + std::to_string(impl.frames); };

  // checks the image and the timestamp
  if (bgr.type() != CV_8UC3 || bgr.cols != impl.options.width_px ||
      bgr.rows != impl.options.height_px) {
    return InvalidArgumentError(
        impl.Where() + ": " + frame_name() + ": expected an 8-bit BGR image of " +
        std::to_string(impl.options.width_px) + "x" + std::to_string(impl.options.height_px) +
        " px, got " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows) + " px with " +
        std::to_string(bgr.channels()) + " channel(s) of " + std::to_string(bgr.elemSize1() * 8) +
        " bits");
  }
  if (pts_ns < 0 || pts_ns <= impl.last_pts_ns) {
    return InvalidArgumentError(
        impl.Where() + ": " + frame_name() + ": timestamp " + FormatSeconds(pts_ns, 9) +
        " s: expected " +
        (impl.last_pts_ns < 0
             ? std::string(">= 0")
             : "after the previous frame's " + FormatSeconds(impl.last_pts_ns, 9) + " s"));
  }
  // readers (OpenCV's CAP_PROP_POS_MSEC, AVI) count time from the first frame
  if (impl.frames == 0 && StoredPtsNs(pts_ns) != 0) {
    return InvalidArgumentError(impl.Where() + ": frame 0: timestamp " + FormatSeconds(pts_ns, 9) +
                                " s: expected the first frame at 0 (readers count time from it)");
  }
  const int64_t tick = impl.TickFromNs(pts_ns);
  if (tick <= impl.last_tick) {
    return InvalidArgumentError(impl.Where() + ": " + frame_name() + ": timestamp " +
                                FormatSeconds(pts_ns, 9) + " s is stored at " +
                                FormatSeconds(StoredPtsNs(pts_ns), 9) +
                                " s, no later than the previous frame's (the container keeps " +
                                std::to_string(impl.encoder->time_base.num) + "/" +
                                std::to_string(impl.encoder->time_base.den) + " s ticks)");
  }

  // converts to the encoder's pixels
  if (const int writable = av_frame_make_writable(impl.frame); writable < 0) {
    return impl.FailAv("cannot reuse the frame buffer", writable);
  }
  // swscale's vector paths read rows in whole 16-byte blocks, past the end of a row whose
  // length is not a multiple of 16: such a picture is read from a copy with a spare row
  cv::Mat source = bgr;
  if ((3 * bgr.cols) % 16 != 0) {
    impl.padded.create(bgr.rows + 1, bgr.cols, CV_8UC3);
    source = impl.padded(cv::Rect(0, 0, bgr.cols, bgr.rows));
    bgr.copyTo(source);
  }
  const uint8_t* source_planes[1] = {source.data};
  const int source_strides[1] = {static_cast<int>(source.step[0])};
  sws_scale(impl.converter, source_planes, source_strides, 0, bgr.rows, impl.frame->data,
            impl.frame->linesize);
  impl.frame->pts = tick;
  impl.frame->quality = impl.encoder->global_quality;

  // encodes and writes what is ready
  if (const int sent = avcodec_send_frame(impl.encoder, impl.frame); sent < 0) {
    return impl.FailAv("encoding " + frame_name() + " failed", sent);
  }
  LIFTOFF_RETURN_IF_ERROR(impl.DrainPackets());
  impl.last_pts_ns = pts_ns;
  impl.last_tick = tick;
  ++impl.frames;
  return Status::Ok();
}

Status VideoWriter::Close() {
  Impl& impl = *impl_;
  if (impl.closed) return impl.error;
  impl.closed = true;
  // flushes the frames the encoder still holds (B-frames, lookahead)
  if (impl.error.ok()) {
    const int sent = avcodec_send_frame(impl.encoder, nullptr);
    if (sent < 0) {
      (void)impl.FailAv("flushing the encoder failed", sent);
    } else {
      (void)impl.DrainPackets();
    }
  }
  // trailer (index, moov up front) and the file into place
  if (impl.error.ok()) {
    if (const int trailer = av_write_trailer(impl.format); trailer < 0) {
      (void)impl.FailAv("writing the trailer failed", trailer);
    }
  }
  if (const int closed = avio_closep(&impl.format->pb); closed < 0) {
    (void)impl.FailAv("closing the file failed", closed);
  }
  if (!impl.error.ok()) return impl.error;
  impl.error = RenameIntoPlace(impl.partial_path, impl.path);
  impl.in_place = impl.error.ok();
  return impl.error;
}

int64_t VideoWriter::StoredPtsNs(int64_t pts_ns) const {
  const Impl& impl = *impl_;
  const int64_t stream_tick =
      av_rescale_q(impl.TickFromNs(pts_ns), impl.encoder->time_base, impl.stream->time_base);
  return av_rescale_q(stream_tick, impl.stream->time_base, kNanosecondTimeBase);
}

int64_t VideoWriter::frames_written() const { return impl_->frames; }

const std::filesystem::path& VideoWriter::path() const { return impl_->path; }

Status WriteTruncatedCopy(const std::filesystem::path& source,
                          const std::filesystem::path& destination, double keep_fraction) {
  if (!(keep_fraction > 0.0 && keep_fraction < 1.0)) {
    return InvalidArgumentError(DisplayPath(destination) +
                                ": keep_fraction: expected 0 < fraction < 1, got " +
                                std::to_string(keep_fraction));
  }
  LIFTOFF_ASSIGN_OR_RETURN(const std::string bytes, ReadWholeFile(source));
  const auto kept = static_cast<size_t>(static_cast<double>(bytes.size()) * keep_fraction);
  return WriteFileAtomically(destination, std::string_view(bytes).substr(0, kept));
}

Status WriteNotAVideo(const std::filesystem::path& path) {
  std::string text;
  for (int line = 0; line < 64; ++line) {
    text += "liftoff synthetic invalid input: this file is named like a video but holds text.\n";
  }
  return WriteFileAtomically(path, text);
}

}  // namespace liftoff::synth
