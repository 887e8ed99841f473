// One decoded video frame and its timing: the unit every video detector consumes.
#pragma once

#include <cstdint>

#include <opencv2/core.hpp>

namespace liftoff::video {

/// A decoded frame, in decode (= presentation) order.
struct Frame {
  /// 0-based position among the decoded frames (not the container's frame number: a
  /// dropped frame leaves no gap in indices, only in t_ns).
  int64_t index = 0;
  /// Presentation time, video clock, ns from the stream's start (the first frame of a
  /// camera file is at or near 0). Strictly increasing across frames.
  int64_t t_ns = 0;
  /// True when t_ns was not read from the file but repaired: a frame without a time, or
  /// whose time does not increase, is given the previous time plus the usual interval.
  bool t_repaired = false;
  /// The picture, CV_8UC3 BGR. Valid until the reader decodes the next frame: detectors
  /// that keep pixels must copy them.
  cv::Mat bgr;
  /// True when the frame was coded on its own (a key frame: every frame of an intra-only
  /// codec such as MJPEG or FFV1, and frames not read from a file): it shows the scene as it
  /// is. False for predicted frames of H.264 and the like, which may hold slowly moving
  /// parts still and let them catch up later.
  bool keyframe = true;
};

}  // namespace liftoff::video
