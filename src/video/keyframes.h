// Which frames of a file are key (intra-coded) frames (private to the video module).
//
// A lossy codec with temporal prediction (H.264, HEVC) holds slowly moving parts of the
// picture still between key frames and lets them catch up later; a key frame is coded on
// its own and shows the scene as it is. OpenCV does not say which decoded frame was a key
// frame, so the file's packets are read once more without decoding (milliseconds for a
// clip) and their presentation times kept, on the clock OpenCV reports (CAP_PROP_POS_MSEC:
// the stream's start time subtracted).
#pragma once

#include <cstdint>
#include <filesystem>
#include <vector>

#include "liftoff/core/status.h"

namespace liftoff::video::internal {

/// Presentation times of the video stream's key-frame packets, ns, sorted. kParse when
/// FFmpeg cannot open the file or finds no video stream.
Result<std::vector<int64_t>> ReadKeyframeTimesNs(const std::filesystem::path& path);

/// Whether `t_ns` is within `tolerance_ns` of a time in `sorted_times_ns`.
bool NearAny(const std::vector<int64_t>& sorted_times_ns, int64_t t_ns, int64_t tolerance_ns);

}  // namespace liftoff::video::internal
