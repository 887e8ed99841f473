#include "keyframes.h"

#include <algorithm>
#include <cmath>
#include <string>

extern "C" {
#include <libavformat/avformat.h>
}

namespace liftoff::video::internal {
namespace {

// Closes the demuxer on every path.
struct FormatContext {
  AVFormatContext* context = nullptr;
  ~FormatContext() {
    if (context != nullptr) avformat_close_input(&context);
  }
};

struct Packet {
  AVPacket* packet = av_packet_alloc();
  ~Packet() { av_packet_free(&packet); }
};

}  // namespace

Result<std::vector<int64_t>> ReadKeyframeTimesNs(const std::filesystem::path& path) {
  FormatContext format;
  if (avformat_open_input(&format.context, path.c_str(), nullptr, nullptr) < 0) {
    return ParseError(path.string() + ": FFmpeg cannot open it to read its key frames");
  }
  if (avformat_find_stream_info(format.context, nullptr) < 0) {
    return ParseError(path.string() + ": FFmpeg finds no stream information");
  }
  const int stream_index =
      av_find_best_stream(format.context, AVMEDIA_TYPE_VIDEO, -1, -1, nullptr, 0);
  if (stream_index < 0) return ParseError(path.string() + ": no video stream");
  const AVStream* stream = format.context->streams[stream_index];
  const double seconds_per_tick = av_q2d(stream->time_base);
  const int64_t start = stream->start_time == AV_NOPTS_VALUE ? 0 : stream->start_time;

  std::vector<int64_t> times_ns;
  Packet packet;
  if (packet.packet == nullptr) return ParseError("out of memory for a packet");
  while (av_read_frame(format.context, packet.packet) >= 0) {
    const bool key = (packet.packet->flags & AV_PKT_FLAG_KEY) != 0;
    const int64_t pts = packet.packet->pts != AV_NOPTS_VALUE ? packet.packet->pts
                                                             : packet.packet->dts;
    if (packet.packet->stream_index == stream_index && key && pts != AV_NOPTS_VALUE) {
      times_ns.push_back(static_cast<int64_t>(
          std::llround(static_cast<double>(pts - start) * seconds_per_tick * 1e9)));
    }
    av_packet_unref(packet.packet);
  }
  std::sort(times_ns.begin(), times_ns.end());
  return times_ns;
}

bool NearAny(const std::vector<int64_t>& sorted_times_ns, int64_t t_ns, int64_t tolerance_ns) {
  const auto above = std::lower_bound(sorted_times_ns.begin(), sorted_times_ns.end(),
                                      t_ns - tolerance_ns);
  return above != sorted_times_ns.end() && *above <= t_ns + tolerance_ns;
}

}  // namespace liftoff::video::internal
