#include "core/base/text.h"

#include <gtest/gtest.h>

#include <string_view>
#include <vector>

namespace deform {
namespace {

TEST(Trim, DropsAsciiWhitespaceAtBothEnds) {
  EXPECT_EQ(Trim(" \t\r\n\v\fknee flexion \n"), "knee flexion");
  EXPECT_EQ(Trim("   "), "");
  EXPECT_EQ(Trim(""), "");
}

TEST(Split, KeepsEmptyParts) {
  EXPECT_EQ(Split("a:b:c", ':'), (std::vector<std::string_view>{"a", "b", "c"}));
  EXPECT_EQ(Split("a,,b,", ','), (std::vector<std::string_view>{"a", "", "b", ""}));
  EXPECT_EQ(Split("", ','), (std::vector<std::string_view>{""}));
}

TEST(ParseFiniteDouble, AcceptsWholeDecimalNumbers) {
  double value = 0;
  for (const auto& [text, expected] : std::vector<std::pair<const char*, double>>{
           {"90", 90}, {"-10.5", -10.5}, {"+3", 3}, {".5", 0.5}, {"1.", 1}, {"2.5e1", 25}}) {
    ASSERT_TRUE(ParseFiniteDouble(text, &value)) << text;
    EXPECT_EQ(value, expected) << text;
  }
}

TEST(ParseFiniteDouble, RefusesEverythingElse) {
  for (const char* text : {"", " 1", "1 ", "abc", "1x", "0x10", "inf", "-inf", "nan", "+-1", "++1",
                           "1e400", "-", ".", "1e"}) {
    double value = 7;
    EXPECT_FALSE(ParseFiniteDouble(text, &value)) << text;
    EXPECT_EQ(value, 7) << text;
  }
}

TEST(ParseInt, AcceptsOnlyAWholeDecimalInt) {
  int value = 0;
  EXPECT_TRUE(ParseInt("12", &value));
  EXPECT_EQ(value, 12);
  EXPECT_TRUE(ParseInt("-3", &value));
  EXPECT_EQ(value, -3);
  for (const char* text : {"", "1.5", " 1", "1a", "99999999999"}) {
    EXPECT_FALSE(ParseInt(text, &value)) << text;
  }
}

}  // namespace
}  // namespace deform
