// FieldChecker, the one checker of the model, synth spec and calibration readers: the
// message's shape, the first problem kept, the error class.
#include "liftoff/core/field_checker.h"

#include <limits>

#include <gtest/gtest.h>

namespace liftoff {
namespace {

TEST(FieldChecker, NamesSourceFieldAndExpectedRange) {
  FieldChecker check("sim.json");
  EXPECT_TRUE(check.ok());
  check.Number("/bodies/0/radius_m", 0.5, {.min = 0, .max = 1});
  EXPECT_TRUE(check.status().ok());
  check.Number("/bodies/1/radius_m", 2.0, {.min = 0, .max = 1});
  EXPECT_FALSE(check.ok());
  EXPECT_EQ(check.field(), "/bodies/1/radius_m");
  EXPECT_EQ(check.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(check.status().message(),
            "sim.json: /bodies/1/radius_m: expected a number in [0, 1], got 2");
}

TEST(FieldChecker, KeepsTheFirstProblemOnly) {
  FieldChecker check;
  check.Integer("camera.width_px", 7, {.min = 320, .max = 1920});
  check.Fail("camera.fps", "never reported");
  check.Unsupported("camera.codec", "never reported");
  EXPECT_EQ(check.status().message(), "camera.width_px: expected an integer in [320, 1920], got 7");
  EXPECT_EQ(check.message(), "expected an integer in [320, 1920], got 7");
}

TEST(FieldChecker, UnsupportedIsItsOwnClass) {
  FieldChecker check("model.json");
  check.Unsupported("/hinges/0/parent", "chains of hinges are not supported");
  check.Number("/x", -1, {.min = 0});
  EXPECT_EQ(check.status().code(), StatusCode::kUnsupported);
  EXPECT_EQ(check.status().message(),
            "model.json: /hinges/0/parent: chains of hinges are not supported");
}

TEST(FieldChecker, RejectsNonFiniteNumbers) {
  FieldChecker check;
  check.Number("/k", std::numeric_limits<double>::quiet_NaN(), {});
  EXPECT_FALSE(check.ok());
}

}  // namespace
}  // namespace liftoff
