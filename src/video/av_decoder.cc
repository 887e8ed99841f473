#include "av_decoder.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/display.h>
#include <libavutil/imgutils.h>
#include <libavutil/pixdesc.h>
#include <libswscale/swscale.h>
}
#include <opencv2/core.hpp>

namespace liftoff::video::internal {
namespace {

// OpenCV's FFmpeg backend uses at most this many decoder threads
constexpr unsigned kMaxThreads = 16;
// converted regions start and end on whole 16-pixel columns (swscale's vector paths)
constexpr int kColumnAlignPx = 16;
// swscale contexts kept for regions of different sizes (the LED's, the foot's, ...)
constexpr size_t kMostPartContexts = 8;

// swscale's vector paths want 16-byte aligned output rows (OpenCV gives it 32)
constexpr int kRowAlignBytes = 32;

int AlignDown(int value, int step) { return value / step * step; }
int AlignUp(int value, int step) { return (value + step - 1) / step * step; }

// Whether swscale may write `width_px` BGR pixels in rows starting at `data`, `step` bytes
// apart, exactly: aligned rows, and a width of whole 16-pixel blocks (its vector paths
// write whole blocks, past the end of a shorter row).
bool WritableInPlace(const uint8_t* data, size_t step, int width_px) {
  return reinterpret_cast<uintptr_t>(data) % 16 == 0 && step % 16 == 0 &&
         width_px % kColumnAlignPx == 0;
}

// `size` BGR pixels in `buffer`: rows 32-byte aligned, each with room for a whole last
// block, and a spare row (swscale may write a block past a row's end)
cv::Mat AlignedBgr(cv::Size size, cv::Mat& buffer) {
  const int row_bytes = AlignUp(3 * AlignUp(size.width, kColumnAlignPx), kRowAlignBytes);
  buffer.create(size.height + 1, row_bytes, CV_8UC1);
  return cv::Mat(size, CV_8UC3, buffer.data, static_cast<size_t>(row_bytes));
}

// the four characters of a codec tag; empty when not printable
std::string TagText(uint32_t tag) {
  std::string text;
  for (int i = 0; i < 4; ++i) {
    const auto c = static_cast<char>((tag >> (8 * i)) & 0xFFu);
    if (c == '\0') break;
    if (c < ' ' || c > '~') return {};
    text.push_back(c);
  }
  return text;
}

// OpenCV's CAP_PROP_FOURCC: the stream's tag, else the codec's name when it has four
// letters, else the tag AVI or QuickTime would give the codec
std::string FourccOf(const AVCodecParameters& parameters) {
  if (parameters.codec_tag != 0) return TagText(parameters.codec_tag);
  const std::string name = avcodec_get_name(parameters.codec_id);
  if (name.size() == 4) return name;
  const AVCodecTag* const tables[] = {avformat_get_riff_video_tags(),
                                      avformat_get_mov_video_tags(), nullptr};
  return TagText(av_codec_get_tag(tables, parameters.codec_id));
}

// OpenCV's rotation: the display matrix's angle, counter-clockwise turned clockwise
int RotationOf(const AVStream& stream) {
  const uint8_t* matrix = av_stream_get_side_data(&stream, AV_PKT_DATA_DISPLAYMATRIX, nullptr);
  if (matrix == nullptr) return 0;
  const double angle = av_display_rotation_get(reinterpret_cast<const int32_t*>(matrix));
  if (!std::isfinite(angle)) return 0;
  int degrees = -static_cast<int>(std::lround(angle));
  degrees = ((degrees % 360) + 360) % 360;
  return degrees == 90 || degrees == 180 || degrees == 270 ? degrees : 0;
}

// whether a region of the format's picture is found by offsetting each plane: planar
// formats (one component per plane, or Y and interleaved chroma) and grey; not packed
// formats, palettes or bit streams
bool RegionsAddressable(const AVPixFmtDescriptor& format) {
  if ((format.flags & (AV_PIX_FMT_FLAG_PAL | AV_PIX_FMT_FLAG_BITSTREAM)) != 0) return false;
  return (format.flags & AV_PIX_FMT_FLAG_PLANAR) != 0 || format.nb_components == 1;
}

}  // namespace

struct AvDecoder::Impl {
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  int stream_index = -1;
  double ms_per_tick = 0.0;
  int64_t start_ticks = 0;
  bool draining = false;
  bool ended = false;
  StreamFacts facts;

  // swscale contexts: the whole picture's, and one per region size (the LED's and the
  // foot's regions differ in size; one context made again for every region of every frame
  // stood out in a profile)
  struct PartContext {
    cv::Size size_px;
    SwsContext* context = nullptr;
  };
  SwsContext* whole = nullptr;
  std::vector<PartContext> parts;
  // regions are converted alone until a comparison with a whole conversion disagrees
  bool regions_checked = false;
  bool regions_exact = true;
  cv::Mat whole_buffer, part_buffer, check_scratch;

  ~Impl() {
    sws_freeContext(whole);
    for (PartContext& part : parts) sws_freeContext(part.context);
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    if (format != nullptr) avformat_close_input(&format);
  }

  Status OpenStream(const std::string& path, int threads);
  void ReadFacts();
  cv::Size Extent() const;
  void ConvertWhole(cv::Mat& bgr);
  void ConvertRegion(const cv::Rect& region, cv::Mat& bgr);
  cv::Rect Widened(const cv::Rect& region) const;
  bool RegionsMatchWhole(const std::vector<cv::Rect>& regions, const cv::Mat& bgr);
};

Status AvDecoder::Impl::OpenStream(const std::string& path, int threads) {
  if (avformat_open_input(&format, path.c_str(), nullptr, nullptr) < 0) {
    return ParseError("FFmpeg cannot open it");
  }
  if (avformat_find_stream_info(format, nullptr) < 0) {
    return ParseError("FFmpeg finds no stream information");
  }
  for (unsigned i = 0; i < format->nb_streams; ++i) {
    if (format->streams[i]->codecpar->codec_type == AVMEDIA_TYPE_VIDEO) {
      stream_index = static_cast<int>(i);
      break;
    }
  }
  if (stream_index < 0) return ParseError("no video stream");
  const AVStream* stream = format->streams[stream_index];
  const AVCodec* decoder = avcodec_find_decoder(stream->codecpar->codec_id);
  if (decoder == nullptr) {
    return ParseError(std::string("no decoder for ") +
                      avcodec_get_name(stream->codecpar->codec_id));
  }
  codec = avcodec_alloc_context3(decoder);
  packet = av_packet_alloc();
  frame = av_frame_alloc();
  if (codec == nullptr || packet == nullptr || frame == nullptr) {
    return ParseError("out of memory for a decoder");
  }
  if (avcodec_parameters_to_context(codec, stream->codecpar) < 0) {
    return ParseError("the stream's parameters are unusable");
  }
  codec->pkt_timebase = stream->time_base;
  codec->thread_count = static_cast<int>(std::clamp(
      threads > 0 ? static_cast<unsigned>(threads) : std::thread::hardware_concurrency(), 1u,
      kMaxThreads));
  if (avcodec_open2(codec, decoder, nullptr) < 0) {
    return ParseError(std::string("the ") + decoder->name + " decoder refused the stream");
  }
  ms_per_tick = av_q2d(stream->time_base) * 1000.0;
  start_ticks = stream->start_time == AV_NOPTS_VALUE ? 0 : stream->start_time;
  ReadFacts();
  return Status::Ok();
}

// what OpenCV's backend reports for CAP_PROP_FPS, CAP_PROP_FRAME_COUNT and CAP_PROP_FOURCC
void AvDecoder::Impl::ReadFacts() {
  AVStream* stream = format->streams[stream_index];
  facts.fps = av_q2d(av_guess_frame_rate(format, stream, nullptr));
  if (!(facts.fps > 0.0) || !std::isfinite(facts.fps)) facts.fps = 0.0;
  int64_t frames = stream->nb_frames;
  if (frames <= 0) {
    double seconds = static_cast<double>(format->duration) / AV_TIME_BASE;
    if (format->duration == AV_NOPTS_VALUE || seconds < 1e-6) {
      seconds = stream->duration == AV_NOPTS_VALUE
                    ? 0.0
                    : static_cast<double>(stream->duration) * av_q2d(stream->time_base);
    }
    const double listed = std::floor(seconds * facts.fps + 0.5);
    frames = std::isfinite(listed) && listed > 0 && listed < 1e15 ? static_cast<int64_t>(listed)
                                                                   : 0;
  }
  facts.frames = frames;
  facts.fourcc = FourccOf(*stream->codecpar);
  facts.rotation_deg = RotationOf(*stream);
  const bool turned = facts.rotation_deg == 90 || facts.rotation_deg == 270;
  facts.width_px = turned ? stream->codecpar->height : stream->codecpar->width;
  facts.height_px = turned ? stream->codecpar->width : stream->codecpar->height;
}

Result<std::unique_ptr<AvDecoder>> AvDecoder::Open(const std::string& path, int threads) {
  auto impl = std::make_unique<Impl>();
  LIFTOFF_RETURN_IF_ERROR(impl->OpenStream(path, threads));
  return std::unique_ptr<AvDecoder>(new AvDecoder(std::move(impl)));
}

AvDecoder::AvDecoder(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
AvDecoder::~AvDecoder() = default;

const StreamFacts& AvDecoder::facts() const { return impl_->facts; }

bool AvDecoder::Next() {
  Impl& s = *impl_;
  while (!s.ended) {
    const int received = avcodec_receive_frame(s.codec, s.frame);
    if (received == 0) return true;
    if (received == AVERROR_EOF || s.draining) {
      s.ended = true;
      break;
    }
    // the decoder wants input: the next packet of our stream, or the end
    if (av_read_frame(s.format, s.packet) < 0) {
      s.draining = true;
      avcodec_send_packet(s.codec, nullptr);
      continue;
    }
    if (s.packet->stream_index == s.stream_index) avcodec_send_packet(s.codec, s.packet);
    av_packet_unref(s.packet);
  }
  return false;
}

double AvDecoder::position_ms() const {
  const AVFrame& frame = *impl_->frame;
  int64_t ticks = frame.best_effort_timestamp;
  if (ticks == AV_NOPTS_VALUE) ticks = frame.pts;
  if (ticks == AV_NOPTS_VALUE) ticks = frame.pkt_dts;
  if (ticks == AV_NOPTS_VALUE) return std::numeric_limits<double>::quiet_NaN();
  return static_cast<double>(ticks - impl_->start_ticks) * impl_->ms_per_tick;
}

// The picture's extent in the decoder's buffers: the coded size, which pads the visible
// one to whole macroblocks. Like OpenCV, conversions run over whole 16-pixel blocks there
// (swscale's vector paths leave a partial last block wrong).
cv::Size AvDecoder::Impl::Extent() const {
  return {std::max(frame->width, codec->coded_width), std::max(frame->height, codec->coded_height)};
}

// the stored picture, whole, into `bgr` (turned upright)
void AvDecoder::Impl::ConvertWhole(cv::Mat& bgr) {
  const cv::Size extent = Extent();
  const cv::Rect visible(0, 0, frame->width, frame->height);
  whole = sws_getCachedContext(whole, extent.width, extent.height,
                               static_cast<AVPixelFormat>(frame->format), extent.width,
                               extent.height, AV_PIX_FMT_BGR24, SWS_BICUBIC, nullptr, nullptr,
                               nullptr);
  bgr.create(facts.height_px, facts.width_px, CV_8UC3);
  const bool direct = facts.rotation_deg == 0 && extent == visible.size() &&
                      WritableInPlace(bgr.data, bgr.step[0], extent.width);
  const cv::Mat target = direct ? bgr : AlignedBgr(extent, whole_buffer);
  uint8_t* planes[4] = {target.data, nullptr, nullptr, nullptr};
  int strides[4] = {static_cast<int>(target.step[0]), 0, 0, 0};
  sws_scale(whole, frame->data, frame->linesize, 0, extent.height, planes, strides);
  if (direct) return;
  const cv::Mat upright = target(visible);
  if (facts.rotation_deg == 0) upright.copyTo(bgr);
  if (facts.rotation_deg == 90) cv::rotate(upright, bgr, cv::ROTATE_90_CLOCKWISE);
  if (facts.rotation_deg == 180) cv::rotate(upright, bgr, cv::ROTATE_180);
  if (facts.rotation_deg == 270) cv::rotate(upright, bgr, cv::ROTATE_90_COUNTERCLOCKWISE);
}

// `region` clipped to the picture and widened to whole 16-pixel columns and chroma
// samples (reaching into the coded extent at the right and bottom edges)
cv::Rect AvDecoder::Impl::Widened(const cv::Rect& region) const {
  const AVPixFmtDescriptor* format_info =
      av_pix_fmt_desc_get(static_cast<AVPixelFormat>(frame->format));
  const int chroma_w = 1 << format_info->log2_chroma_w;
  const int chroma_h = 1 << format_info->log2_chroma_h;
  const int step_x = std::max(kColumnAlignPx, chroma_w);
  const cv::Rect clipped = region & cv::Rect(0, 0, frame->width, frame->height);
  if (clipped.empty()) return {};
  const cv::Size extent = Extent();
  const int x0 = AlignDown(clipped.x, step_x);
  const int y0 = AlignDown(clipped.y, chroma_h);
  const int x1 = std::min(extent.width, AlignUp(clipped.br().x, step_x));
  const int y1 = std::min(extent.height, AlignUp(clipped.br().y, chroma_h));
  return {x0, y0, x1 - x0, y1 - y0};
}

// one region (already widened) of the stored picture into the same place of `bgr`
void AvDecoder::Impl::ConvertRegion(const cv::Rect& region, cv::Mat& bgr) {
  const auto pixel_format = static_cast<AVPixelFormat>(frame->format);
  const AVPixFmtDescriptor* format_info = av_pix_fmt_desc_get(pixel_format);
  auto at = std::find_if(parts.begin(), parts.end(),
                         [&](const PartContext& part) { return part.size_px == region.size(); });
  if (at == parts.end() && parts.size() < kMostPartContexts) {
    at = parts.insert(parts.end(), PartContext{region.size(), nullptr});
  }
  if (at == parts.end()) at = parts.end() - 1;  // made again for this size
  at->size_px = region.size();
  at->context = sws_getCachedContext(at->context, region.width, region.height, pixel_format,
                                     region.width, region.height, AV_PIX_FMT_BGR24, SWS_BICUBIC,
                                     nullptr, nullptr, nullptr);
  SwsContext* part = at->context;
  int max_step[4] = {};
  av_image_fill_max_pixsteps(max_step, nullptr, format_info);
  const uint8_t* source[4] = {};
  for (int plane = 0; plane < 4 && frame->data[plane] != nullptr; ++plane) {
    const bool chroma = plane == 1 || plane == 2;
    const int x = chroma ? region.x >> format_info->log2_chroma_w : region.x;
    const int y = chroma ? region.y >> format_info->log2_chroma_h : region.y;
    source[plane] = frame->data[plane] + static_cast<ptrdiff_t>(y) * frame->linesize[plane] +
                    static_cast<ptrdiff_t>(x) * max_step[plane];
  }
  // a region reaching into the padding, or that swscale cannot write in place, is
  // converted aside and its visible part copied
  const cv::Rect visible = region & cv::Rect(0, 0, bgr.cols, bgr.rows);
  const bool direct =
      visible == region &&
      WritableInPlace(bgr.ptr<uint8_t>(region.y) + 3 * region.x, bgr.step[0], region.width);
  const cv::Mat target = direct ? bgr(region) : AlignedBgr(region.size(), part_buffer);
  uint8_t* planes[4] = {target.data, nullptr, nullptr, nullptr};
  int strides[4] = {static_cast<int>(target.step[0]), 0, 0, 0};
  sws_scale(part, source, frame->linesize, 0, region.height, planes, strides);
  if (!direct) target(cv::Rect(cv::Point(0, 0), visible.size())).copyTo(bgr(visible));
}

// converts the regions of the current frame alone and whole, and compares
bool AvDecoder::Impl::RegionsMatchWhole(const std::vector<cv::Rect>& regions,
                                        const cv::Mat& bgr) {
  ConvertWhole(check_scratch);
  for (const cv::Rect& region : regions) {
    const cv::Rect inside = region & cv::Rect(0, 0, bgr.cols, bgr.rows);
    if (inside.empty()) continue;
    if (cv::norm(bgr(inside), check_scratch(inside), cv::NORM_INF) != 0.0) return false;
  }
  return true;
}

void AvDecoder::ToBgr(const std::vector<cv::Rect>& regions_px, cv::Mat& bgr) {
  Impl& s = *impl_;
  const AVPixFmtDescriptor* format_info =
      av_pix_fmt_desc_get(static_cast<AVPixelFormat>(s.frame->format));
  if (regions_px.empty() || s.facts.rotation_deg != 0 || !s.regions_exact ||
      format_info == nullptr || !RegionsAddressable(*format_info)) {
    s.ConvertWhole(bgr);
    return;
  }
  if (bgr.rows != s.frame->height || bgr.cols != s.frame->width || bgr.type() != CV_8UC3) {
    bgr = cv::Mat::zeros(s.frame->height, s.frame->width, CV_8UC3);
  }
  for (const cv::Rect& region : regions_px) {
    const cv::Rect widened = s.Widened(region);
    if (!widened.empty()) s.ConvertRegion(widened, bgr);
  }
  if (!s.regions_checked) {
    // swscale's converters are exact per pixel for the usual formats; a format whose
    // conversion filters across a region's edge is found out here and converted whole
    s.regions_checked = true;
    s.regions_exact = s.RegionsMatchWhole(regions_px, bgr);
    if (!s.regions_exact) s.check_scratch.copyTo(bgr);
  }
}

}  // namespace liftoff::video::internal
