#include "liftoff/stats/statistics.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <boost/math/distributions/students_t.hpp>

namespace liftoff::stats {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string Format(double value) {
  char buffer[32];
  std::snprintf(buffer, sizeof buffer, "%.4g", value);
  return buffer;
}

}  // namespace

std::string Summary::Brief() const {
  if (n == 0) return "n 0";
  std::string text = "n " + std::to_string(n) + ", mean " + Format(mean);
  if (n > 1) text += ", sd " + Format(stddev);
  text += ", median " + Format(median);
  if (n > 1) {
    char level[16];
    std::snprintf(level, sizeof level, "%g", confidence * 100.0);
    text += ", " + std::string(level) + " % CI [" + Format(ci_low) + ", " + Format(ci_high) + "]";
  }
  text += ", range [" + Format(min) + ", " + Format(max) + "]";
  return text;
}

double StudentTQuantile(double probability, double degrees_of_freedom) {
  // boost throws on a bad domain; answer NaN instead
  if (!(probability > 0.0 && probability < 1.0) || !(degrees_of_freedom > 0.0) ||
      std::isinf(degrees_of_freedom)) {
    return kNaN;
  }
  const boost::math::students_t distribution(degrees_of_freedom);
  return boost::math::quantile(distribution, probability);
}

Summary Summarize(std::span<const double> values, double confidence) {
  Summary summary;
  summary.confidence = confidence;

  // keep the finite values, sorted for the range and the median
  std::vector<double> sorted;
  sorted.reserve(values.size());
  for (double value : values) {
    if (std::isfinite(value)) sorted.push_back(value);
  }
  std::sort(sorted.begin(), sorted.end());
  const size_t count = sorted.size();
  summary.n = static_cast<int64_t>(count);
  if (count == 0) return summary;

  summary.min = sorted.front();
  summary.max = sorted.back();
  summary.median =
      count % 2 == 1 ? sorted[count / 2] : 0.5 * (sorted[count / 2 - 1] + sorted[count / 2]);
  double sum = 0.0;
  for (double value : sorted) sum += value;
  summary.mean = sum / static_cast<double>(count);
  if (count == 1) return summary;

  // two passes: squared deviations from the mean, not the sum of squares
  double squared_deviations = 0.0;
  for (double value : sorted) squared_deviations += (value - summary.mean) * (value - summary.mean);
  summary.stddev = std::sqrt(squared_deviations / static_cast<double>(count - 1));

  // t interval of the mean
  if (!(confidence > 0.0 && confidence < 1.0)) return summary;
  const double t = StudentTQuantile(0.5 * (1.0 + confidence), static_cast<double>(count - 1));
  if (std::isfinite(t)) {
    const double half_width = t * summary.stddev / std::sqrt(static_cast<double>(count));
    summary.ci_low = summary.mean - half_width;
    summary.ci_high = summary.mean + half_width;
  }
  return summary;
}

}  // namespace liftoff::stats
