#include <gtest/gtest.h>

#include "common/time.h"

namespace kestrel {
namespace {

TEST(Time, ParsesTumStampsExactly) {
  // 1305031229.528784 is not representable as a double to the microsecond.
  EXPECT_EQ(parse_seconds("1305031229.528784"), 1305031229528784);
  EXPECT_EQ(parse_seconds("1305031229.5287845"), 1305031229528785);  // rounded half up
  EXPECT_EQ(parse_seconds("1305031229.5287844"), 1305031229528784);
  EXPECT_EQ(parse_seconds("12"), 12000000);
  EXPECT_EQ(parse_seconds("0.5"), 500000);
}

TEST(Time, RejectsMalformedStamps) {
  for (const char* bad : {"", ".5", "1.", "-1.0", "1e9", "12a.3", "1.2.3", "nan"})
    EXPECT_FALSE(parse_seconds(bad).has_value()) << bad;
}

TEST(Time, FormatsSixDecimalsAndRoundTrips) {
  EXPECT_EQ(format_seconds(1305031229528784), "1305031229.528784");
  EXPECT_EQ(format_seconds(5), "0.000005");
  EXPECT_EQ(format_seconds(-1500000), "-1.500000");
  EXPECT_EQ(parse_seconds(format_seconds(987654321012345)), 987654321012345);
}

}  // namespace
}  // namespace kestrel
