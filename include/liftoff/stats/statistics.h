// Descriptive statistics of a small sample (a handful of hardware trials per foot): count,
// range, mean, sample standard deviation, median and a Student's t confidence interval
// of the mean.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>

namespace liftoff::stats {

/// Summary of a sample. Every value is in the same unit as the inputs (radians for
/// liftoff rotations). Values that cannot be computed are NaN: all of them when n = 0;
/// stddev and the interval when n = 1.
struct Summary {
  /// Number of values summarised (non-finite inputs are not counted).
  int64_t n = 0;
  /// Smallest and largest value.
  double min = std::numeric_limits<double>::quiet_NaN();
  double max = std::numeric_limits<double>::quiet_NaN();
  /// Arithmetic mean.
  double mean = std::numeric_limits<double>::quiet_NaN();
  /// Sample standard deviation (divides by n - 1).
  double stddev = std::numeric_limits<double>::quiet_NaN();
  /// Middle value; the mean of the two middle values when n is even.
  double median = std::numeric_limits<double>::quiet_NaN();
  /// Confidence interval of the mean at `confidence` (95 % unless asked otherwise):
  /// mean -/+ t((1 + confidence) / 2, n - 1) * stddev / sqrt(n).
  double ci_low = std::numeric_limits<double>::quiet_NaN();
  double ci_high = std::numeric_limits<double>::quiet_NaN();
  /// Confidence level of [ci_low, ci_high], in (0, 1).
  double confidence = 0.95;

  /// "n 5, mean 0.4468, sd 0.0428, median 0.455, 95 % CI [0.3937, 0.4999], range
  /// [0.385, 0.502]" (4 significant digits; "n 0" alone for an empty sample).
  std::string Brief() const;
};

/// Summarises `values`. NaN and infinite values are skipped (they stand for missing
/// measurements). A `confidence` outside (0, 1) leaves the interval NaN.
Summary Summarize(std::span<const double> values, double confidence = 0.95);

/// Quantile of Student's t distribution: the t with P(T <= t) = `probability` for
/// `degrees_of_freedom` (> 0, need not be an integer). NaN when probability is outside
/// (0, 1) or degrees_of_freedom <= 0. StudentTQuantile(0.975, 4) = 2.7764451...
double StudentTQuantile(double probability, double degrees_of_freedom);

}  // namespace liftoff::stats
