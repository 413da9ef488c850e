// The strict text helpers every reader of outside text uses (common/text.h), on hand-written
// cases: each answer below is what the format says, not what the code happened to print.
#include "common/text.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

namespace kestrel {
namespace {

std::vector<std::string> fields_of(std::string_view line) {
  std::vector<std::string> out;
  for (std::string_view f : split_fields(line)) out.emplace_back(f);
  return out;
}

TEST(Text, FieldsSplitOnSpacesAndTabsAndIgnoreACarriageReturn) {
  EXPECT_EQ(fields_of("1.5 rgb/a.png\t 2\r"), (std::vector<std::string>{"1.5", "rgb/a.png", "2"}));
  EXPECT_TRUE(fields_of("  \t\r").empty());
  EXPECT_EQ(fields_of("x"), std::vector<std::string>{"x"});
}

TEST(Text, CommentsAndBlankLines) {
  EXPECT_TRUE(is_comment_or_blank(""));
  EXPECT_TRUE(is_comment_or_blank(" \t\r"));
  EXPECT_TRUE(is_comment_or_blank("  # timestamp tx ty tz"));
  EXPECT_FALSE(is_comment_or_blank("1 # trailing"));
}

TEST(Text, ANumberIsTheWholeToken) {
  EXPECT_EQ(parse_double("1.25"), 1.25);
  EXPECT_EQ(parse_double("+2e-3"), 0.002);
  EXPECT_EQ(parse_double("-0.5"), -0.5);
  EXPECT_TRUE(std::isnan(*parse_double("nan")));
  EXPECT_TRUE(std::isinf(*parse_double("inf")));
  for (const char* bad : {"", "+", "1.0x", " 1", "1 ", "0x10", "1,5", "++1"}) {
    EXPECT_FALSE(parse_double(bad).has_value()) << "'" << bad << "'";
  }
  EXPECT_EQ(parse_int("-42"), -42);
  for (const char* bad : {"", "4.0", "42a", "99999999999999999999", "+"}) {
    EXPECT_FALSE(parse_int(bad).has_value()) << "'" << bad << "'";
  }
}

TEST(Text, NumbersInMessagesHaveSixSignificantDigits) {
  EXPECT_EQ(number_text(0.5), "0.5");
  EXPECT_EQ(number_text(10000.0), "10000");
  EXPECT_EQ(number_text(1e6), "1e+06");
  EXPECT_EQ(number_text(1.0 / 3.0), "0.333333");
  EXPECT_EQ(number_text(-2.5e-7), "-2.5e-07");
  EXPECT_EQ(number_text(std::nan("")), "nan");
  EXPECT_EQ(number_text(-HUGE_VAL), "-inf");
}

TEST(Text, BytesThatDoNotPrintAreEscaped) {
  EXPECT_EQ(escape_bytes("plain text"), "plain text");
  EXPECT_EQ(escape_bytes("a\nb\tc\rd"), "a\\nb\\tc\\rd");
  EXPECT_EQ(escape_bytes(std::string("\x1b[2J\x7f\0", 6)), "\\x1B[2J\\x7F\\x00");
  EXPECT_EQ(escape_bytes("caf\xc3\xa9 \xe2\x86\x92"), "caf\xc3\xa9 \xe2\x86\x92");  // UTF-8 é and →
  EXPECT_EQ(escape_bytes("\xc2\x9b"), "\\xC2\\x9B");      // U+009B, a C1 control (CSI)
  EXPECT_EQ(escape_bytes("\xc0\xaf"), "\\xC0\\xAF");      // an overlong '/'
  EXPECT_EQ(escape_bytes("\xed\xa0\x80"), "\\xED\\xA0\\x80");  // a UTF-16 surrogate
  EXPECT_EQ(escape_bytes("\xe2\x86"), "\\xE2\\x86");      // cut short
  EXPECT_EQ(escape_bytes("a=b;c", "=;"), "a\\=b\\;c");
}

}  // namespace
}  // namespace kestrel
