// Downscaling by pixel-area averaging with the weights computed once (private to the video
// module).
//
// cv::resize with cv::INTER_AREA rebuilds its tables of weights at every call; for the foot
// tracker's small work image (a region of a few hundred pixels scaled to 64, every frame)
// the tables cost more than the sums. AreaResizer builds them once for one source size and
// scale: output pixel i covers the source interval [i / scale, (i + 1) / scale) (clipped to
// the source) and is the mean of the source pixels weighted by their overlap with it,
// separably in x and y, rounded to a whole level: cv::INTER_AREA's rule and result on an
// 8-bit image (but for half-way cases), as float.
#pragma once

#include <vector>

#include <opencv2/core.hpp>

namespace liftoff::video::internal {

class AreaResizer {
 public:
  AreaResizer() = default;
  /// `source`: the input's size, px; `scale`: output px per input px, in (0, 1]. The output
  /// is source * scale rounded half to even (as cv::resize with fx = fy = scale), at least
  /// 1 px.
  AreaResizer(cv::Size source, double scale);

  cv::Size output_size() const { return output_; }

  /// `bgr`: CV_8UC3 of the source size (a view into a larger image is fine); `out`:
  /// CV_32FC3 of output_size() (allocated when it is not).
  void Apply(const cv::Mat& bgr, cv::Mat& out) const;

 private:
  struct Tap {
    int source = 0;      // source column or row
    float weight = 0.f;  // its share of the output pixel
  };
  // taps of every output column (row): [begin[i], begin[i + 1]) in taps
  struct Axis {
    std::vector<int> begin;
    std::vector<Tap> taps;
  };
  static Axis MakeAxis(int source_px, int output_px, double scale);

  cv::Size source_, output_;
  Axis x_, y_;
};

}  // namespace liftoff::video::internal
