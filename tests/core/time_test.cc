#include "liftoff/core/time.h"

#include <cstdint>
#include <limits>
#include <string>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

namespace liftoff {
namespace {

using ::testing::HasSubstr;

constexpr int64_t kSecond = kNanosecondsPerSecond;
constexpr int64_t kMillisecond = kNanosecondsPerMillisecond;

int64_t ParseOrDie(std::string_view text, int64_t unit_ns) {
  const Result<int64_t> result = ParseDecimalNs(text, unit_ns);
  EXPECT_TRUE(result.ok()) << text << ": " << result.status().ToString();
  return result.value_or(-1);
}

TEST(ParseDecimalNs, ReadsSecondsExactly) {
  // 8.02 has no exact double; the parse must not go through one
  EXPECT_EQ(ParseOrDie("8.02", kSecond), 8'020'000'000);
  EXPECT_EQ(ParseOrDie("5.67", kSecond), 5'670'000'000);
  EXPECT_EQ(ParseOrDie("0.1", kSecond), 100'000'000);
  EXPECT_EQ(ParseOrDie("12", kSecond), 12'000'000'000);
  EXPECT_EQ(ParseOrDie("12.345678901", kSecond), 12'345'678'901);
}

TEST(ParseDecimalNs, ReadsMillisecondsExactly) {
  EXPECT_EQ(ParseOrDie("1074.33", kMillisecond), 1'074'330'000);
  EXPECT_EQ(ParseOrDie("4", kMillisecond), 4'000'000);
  EXPECT_EQ(ParseOrDie("0.000001", kMillisecond), 1);
}

TEST(ParseDecimalNs, ReadsSignsAndZero) {
  EXPECT_EQ(ParseOrDie("0", kSecond), 0);
  EXPECT_EQ(ParseOrDie("-0.0", kSecond), 0);
  EXPECT_EQ(ParseOrDie("-1.5", kSecond), -1'500'000'000);
  EXPECT_EQ(ParseOrDie("+2.25", kSecond), 2'250'000'000);
  EXPECT_EQ(ParseOrDie("007.5", kSecond), 7'500'000'000);
  EXPECT_EQ(ParseOrDie("3.", kSecond), 3'000'000'000);
}

TEST(ParseDecimalNs, RoundsSubNanosecondDigitsHalfAwayFromZero) {
  EXPECT_EQ(ParseOrDie("0.0000000005", kSecond), 1);
  EXPECT_EQ(ParseOrDie("0.0000000004999", kSecond), 0);
  EXPECT_EQ(ParseOrDie("-0.0000000005", kSecond), -1);
  EXPECT_EQ(ParseOrDie("1.2345678915", kSecond), 1'234'567'892);
  EXPECT_EQ(ParseOrDie("2.5", 1), 3);
  EXPECT_EQ(ParseOrDie("-2.5", 1), -3);
}

TEST(ParseDecimalNs, IgnoresDigitsFarBelowANanosecond) {
  EXPECT_EQ(ParseOrDie("1.2345678901234567890123456789012345678901", kSecond), 1'234'567'890);
  EXPECT_EQ(ParseOrDie("0.000000000000000000000000000000000000000000000001", kSecond), 0);
  EXPECT_EQ(ParseOrDie("0.99999999999999999999999999999999999999999", kSecond), kSecond);
}

TEST(ParseDecimalNs, ReadsTheWholeInt64Range) {
  EXPECT_EQ(ParseOrDie("9223372036.854775807", kSecond), std::numeric_limits<int64_t>::max());
  EXPECT_EQ(ParseOrDie("-9223372036.854775808", kSecond), std::numeric_limits<int64_t>::min());
  EXPECT_EQ(ParseOrDie("9223372036854775807", 1), std::numeric_limits<int64_t>::max());
}

TEST(ParseDecimalNs, RejectsOverflowAsOutOfRange) {
  for (const char* text : {"9223372036.854775808", "-9223372036.854775809", "9223372037",
                           "99999999999999999999999999999999999999999999", "1e400"}) {
    const Result<int64_t> result = ParseDecimalNs(text, kSecond);
    ASSERT_FALSE(result.ok()) << text;
    if (std::string(text) == "1e400") {
      EXPECT_EQ(result.status().code(), StatusCode::kParse);  // exponents are not accepted
      continue;
    }
    EXPECT_EQ(result.status().code(), StatusCode::kOutOfRange) << text;
    EXPECT_THAT(result.status().message(), HasSubstr(text));
  }
}

TEST(ParseDecimalNs, RejectsMalformedTextNamingIt) {
  for (const char* text : {"", "-", "+", ".", "-.", "1e3", " 1", "1 ", "1.2.3", "abc", "1,5",
                           "1074.33,", "--1", "0x10", "nan", "inf"}) {
    const Result<int64_t> result = ParseDecimalNs(text, kMillisecond);
    ASSERT_FALSE(result.ok()) << '"' << text << '"';
    EXPECT_EQ(result.status().code(), StatusCode::kParse) << text;
    EXPECT_THAT(result.status().message(), HasSubstr("\"" + std::string(text) + "\""));
  }
}

TEST(TimeConversions, NsFromSecondsRoundsToNearest) {
  EXPECT_EQ(NsFromSeconds(5.67), 5'670'000'000);
  EXPECT_EQ(NsFromSeconds(-0.25), -250'000'000);
  EXPECT_EQ(NsFromSeconds(1e-9 * 0.4), 0);
  EXPECT_DOUBLE_EQ(SecondsFromNs(1'500'000'000), 1.5);
  EXPECT_EQ(NsFromMilliseconds(1074), 1'074'000'000);
  EXPECT_EQ(NsFromMicroseconds(-3), -3'000);
}

TEST(TimeConversions, NsFromSecondsSaturatesInsteadOfOverflowing) {
  constexpr int64_t kMax = std::numeric_limits<int64_t>::max();
  constexpr int64_t kMin = std::numeric_limits<int64_t>::min();
  EXPECT_EQ(NsFromSeconds(1e10), kMax);  // once INT64_MIN through llround's overflow
  EXPECT_EQ(NsFromSeconds(-1e10), kMin);
  EXPECT_EQ(NsFromSeconds(std::numeric_limits<double>::infinity()), kMax);
  EXPECT_EQ(NsFromSeconds(std::numeric_limits<double>::quiet_NaN()), 0);
  EXPECT_EQ(NsFromSeconds(kMaxTimeSeconds), 1'000'000 * kSecond);
}

TEST(FormatMilliseconds, PrintsMillisecondsWithTheUnit) {
  EXPECT_EQ(FormatMilliseconds(4'249'000), "4.2 ms");
  EXPECT_EQ(FormatMilliseconds(16'666'667, 3), "16.667 ms");
  EXPECT_EQ(FormatMilliseconds(-1'500'000, 0), "-2 ms");
}

TEST(FormatSeconds, PrintsRequestedDecimals) {
  EXPECT_EQ(FormatSeconds(1'500'000'000), "1.500");
  EXPECT_EQ(FormatSeconds(-250'000'000, 2), "-0.25");
  EXPECT_EQ(FormatSeconds(12'345'678'901, 9), "12.345678901");
  EXPECT_EQ(FormatSeconds(2'600'000'000, 0), "3");
}

TEST(ClockMap, UnitScaleShiftsOriginsExactly) {
  const ClockMap log_from_video{
      .source_origin_ns = 1'000'000'000, .target_at_origin_ns = 5'000'000'000, .scale = 1.0};
  EXPECT_EQ(log_from_video(1'000'000'000), 5'000'000'000);
  EXPECT_EQ(log_from_video(1'500'000'007), 5'500'000'007);
  EXPECT_EQ(log_from_video(0), 4'000'000'000);
  // large values stay exact: no trip through a double
  EXPECT_EQ(log_from_video(4'000'000'000'000'000'001), 4'000'000'004'000'000'001);
}

TEST(ClockMap, ScaleStretchesDurationsAboutTheOrigin) {
  const ClockMap target_from_source{
      .source_origin_ns = 2'000'000'000, .target_at_origin_ns = 0, .scale = 1.001};
  EXPECT_EQ(target_from_source(2'000'000'000), 0);
  EXPECT_EQ(target_from_source(3'000'000'000), 1'001'000'000);
  EXPECT_EQ(target_from_source(1'000'000'000), -1'001'000'000);
  EXPECT_EQ(target_from_source.MapDuration(1'000'000), 1'001'000);
}

TEST(ClockMap, RoundsMappedDurationsHalfAwayFromZero) {
  const ClockMap map{.source_origin_ns = 0, .target_at_origin_ns = 0, .scale = 1.5};
  EXPECT_EQ(map.MapDuration(3), 5);  // 4.5
  EXPECT_EQ(map.MapDuration(-3), -5);
  EXPECT_EQ(map.MapDuration(2), 3);
}

TEST(HostClocks, AreInThePresentAndMonotonic) {
  EXPECT_GT(HostNowNs(), 1'577'836'800 * kSecond);  // after 2020-01-01
  const int64_t first = MonotonicNowNs();
  const int64_t second = MonotonicNowNs();
  EXPECT_LE(first, second);
}

}  // namespace
}  // namespace liftoff
