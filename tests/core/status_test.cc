#include "liftoff/core/status.h"

#include <memory>
#include <set>
#include <string>

#include <gtest/gtest.h>

namespace liftoff {
namespace {

TEST(Status, DefaultIsOkWithEmptyMessage) {
  const Status status;
  EXPECT_TRUE(status.ok());
  EXPECT_EQ(status.code(), StatusCode::kOk);
  EXPECT_EQ(status.message(), "");
  EXPECT_EQ(status.ToString(), "ok");
  EXPECT_TRUE(Status::Ok().ok());
}

TEST(Status, ConstructorsSetTheirCode) {
  EXPECT_EQ(InvalidArgumentError("m").code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(NotFoundError("m").code(), StatusCode::kNotFound);
  EXPECT_EQ(ParseError("m").code(), StatusCode::kParse);
  EXPECT_EQ(IoError("m").code(), StatusCode::kIo);
  EXPECT_EQ(TimeoutError("m").code(), StatusCode::kTimeout);
  EXPECT_EQ(UnsupportedError("m").code(), StatusCode::kUnsupported);
  EXPECT_EQ(OutOfRangeError("m").code(), StatusCode::kOutOfRange);
  EXPECT_FALSE(IoError("m").ok());
  EXPECT_EQ(IoError("disk full").message(), "disk full");
}

TEST(Status, CodeNamesAreDistinctAndReadable) {
  EXPECT_EQ(StatusCodeName(StatusCode::kOk), "ok");
  EXPECT_EQ(StatusCodeName(StatusCode::kInvalidArgument), "invalid argument");
  EXPECT_EQ(StatusCodeName(StatusCode::kNotFound), "not found");
  std::set<std::string_view> names;
  for (StatusCode code :
       {StatusCode::kOk, StatusCode::kInvalidArgument, StatusCode::kNotFound, StatusCode::kParse,
        StatusCode::kIo, StatusCode::kTimeout, StatusCode::kUnsupported, StatusCode::kOutOfRange}) {
    EXPECT_FALSE(StatusCodeName(code).empty());
    names.insert(StatusCodeName(code));
  }
  EXPECT_EQ(names.size(), 8u);
}

TEST(Status, ToStringPutsCodeNameBeforeMessage) {
  EXPECT_EQ(NotFoundError("trials.json: no such file").ToString(),
            "not found: trials.json: no such file");
}

TEST(Status, WithContextPrefixesMessageAndKeepsCode) {
  const Status status = ParseError("/trials/3/foot: bad").WithContext("trials.json");
  EXPECT_EQ(status.code(), StatusCode::kParse);
  EXPECT_EQ(status.message(), "trials.json: /trials/3/foot: bad");
}

TEST(Status, WithContextLeavesOkAlone) {
  const Status status = Status::Ok().WithContext("trials.json");
  EXPECT_TRUE(status.ok());
  EXPECT_EQ(status.message(), "");
}

TEST(Result, HoldsValue) {
  Result<int> result = 42;
  ASSERT_TRUE(result.ok());
  EXPECT_TRUE(result.status().ok());
  EXPECT_EQ(result.value(), 42);
  EXPECT_EQ(*result, 42);
  EXPECT_EQ(result.value_or(7), 42);
}

TEST(Result, HoldsError) {
  const Result<std::string> result = NotFoundError("gone");
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kNotFound);
  EXPECT_EQ(result.status().message(), "gone");
  EXPECT_EQ(result.value_or("fallback"), "fallback");
}

TEST(Result, ArrowReachesMembers) {
  const Result<std::string> result = std::string("abc");
  EXPECT_EQ(result->size(), 3u);
}

TEST(Result, MovesOutMoveOnlyValues) {
  Result<std::unique_ptr<int>> result = std::make_unique<int>(5);
  std::unique_ptr<int> value = std::move(result).value();
  ASSERT_NE(value, nullptr);
  EXPECT_EQ(*value, 5);
}

Status FailIfNegative(int x) {
  if (x < 0) return InvalidArgumentError("x: expected >= 0, got " + std::to_string(x));
  return Status::Ok();
}

Result<int> Doubled(int x) {
  LIFTOFF_RETURN_IF_ERROR(FailIfNegative(x));
  return 2 * x;
}

Result<int> DoubledPlusOne(int x) {
  LIFTOFF_ASSIGN_OR_RETURN(const int doubled, Doubled(x));
  LIFTOFF_ASSIGN_OR_RETURN(int again, Doubled(0));  // two on one function: distinct names
  return doubled + again + 1;
}

TEST(StatusMacros, ReturnIfErrorPassesErrorsUp) {
  EXPECT_EQ(Doubled(4).value(), 8);
  const Result<int> result = Doubled(-1);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(result.status().message(), "x: expected >= 0, got -1");
}

TEST(StatusMacros, AssignOrReturnDeclaresValueOrReturnsError) {
  EXPECT_EQ(DoubledPlusOne(3).value(), 7);
  const Result<int> result = DoubledPlusOne(-2);
  ASSERT_FALSE(result.ok());
  EXPECT_EQ(result.status().message(), "x: expected >= 0, got -2");
}

}  // namespace
}  // namespace liftoff
