#include "area_resize.h"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace liftoff::video::internal {

AreaResizer::AreaResizer(cv::Size source, double scale) : source_(source) {
  assert(scale > 0 && scale <= 1 && source.width > 0 && source.height > 0);
  // rounded half to even, as cv::resize does (cvRound)
  output_ = cv::Size(std::max(1, static_cast<int>(std::lrint(source.width * scale))),
                     std::max(1, static_cast<int>(std::lrint(source.height * scale))));
  x_ = MakeAxis(source.width, output_.width, scale);
  y_ = MakeAxis(source.height, output_.height, scale);
}

// Output pixel i covers [i / scale, (i + 1) / scale) of the source, clipped to it; each
// source pixel k in it weighs its overlap with that interval over the interval's length.
AreaResizer::Axis AreaResizer::MakeAxis(int source_px, int output_px, double scale) {
  Axis axis;
  const double step = 1.0 / scale;
  for (int i = 0; i < output_px; ++i) {
    axis.begin.push_back(static_cast<int>(axis.taps.size()));
    const double from = i * step;
    const double to = std::min((i + 1) * step, static_cast<double>(source_px));
    const double length = to - from;
    for (int k = static_cast<int>(std::floor(from)); k < source_px && k < to; ++k) {
      const double overlap = std::min<double>(k + 1, to) - std::max<double>(k, from);
      if (overlap > 1e-9) axis.taps.push_back({k, static_cast<float>(overlap / length)});
    }
  }
  axis.begin.push_back(static_cast<int>(axis.taps.size()));
  return axis;
}

void AreaResizer::Apply(const cv::Mat& bgr, cv::Mat& out) const {
  assert(bgr.type() == CV_8UC3 && bgr.size() == source_);
  out.create(output_, CV_32FC3);
  // rows first: each output row is a weighted sum of source rows, over the full width
  std::vector<float> row(static_cast<size_t>(source_.width) * 3);
  for (int oy = 0; oy < output_.height; ++oy) {
    std::fill(row.begin(), row.end(), 0.f);
    for (int t = y_.begin[static_cast<size_t>(oy)]; t < y_.begin[static_cast<size_t>(oy) + 1];
         ++t) {
      const Tap& tap = y_.taps[static_cast<size_t>(t)];
      const uint8_t* source = bgr.ptr<uint8_t>(tap.source);
      for (size_t v = 0; v < row.size(); ++v) row[v] += tap.weight * static_cast<float>(source[v]);
    }
    // then columns
    float* target = out.ptr<float>(oy);
    for (int ox = 0; ox < output_.width; ++ox) {
      float b = 0.f, g = 0.f, r = 0.f;
      for (int t = x_.begin[static_cast<size_t>(ox)]; t < x_.begin[static_cast<size_t>(ox) + 1];
           ++t) {
        const Tap& tap = x_.taps[static_cast<size_t>(t)];
        const float* pixel = &row[static_cast<size_t>(tap.source) * 3];
        b += tap.weight * pixel[0];
        g += tap.weight * pixel[1];
        r += tap.weight * pixel[2];
      }
      // to whole levels, half to even, as cv::resize gives an 8-bit image's at a
      // non-integer scale (the tracker was tuned on those)
      // (cvRound: inline, where std::nearbyint is a library call per channel)
      target[3 * ox] = static_cast<float>(cvRound(b));
      target[3 * ox + 1] = static_cast<float>(cvRound(g));
      target[3 * ox + 2] = static_cast<float>(cvRound(r));
    }
  }
}

}  // namespace liftoff::video::internal
