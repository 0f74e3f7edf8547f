#include "common/format.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

namespace talus {
namespace {

TEST(Format, PrintfConversionsTenDigitsAndMissingValues) {
  EXPECT_EQ(FormatDouble(3.14159, "%.2f"), "3.14");
  EXPECT_EQ(FormatDouble(12345.678, "%.3g"), "1.23e+04");
  EXPECT_EQ(TenDigits(0.1), "0.1");
  EXPECT_EQ(TenDigits(1.0 / 3), "0.3333333333");
  EXPECT_EQ(TenDigits(-1e-7), "-1e-07");
  EXPECT_EQ(TenDigits(NAN), "nan");
  EXPECT_EQ(FormatOrMissing(NAN, "%.3g", "-"), "-");
  EXPECT_EQ(FormatOrMissing(INFINITY, "%.3g", "-"), "inf");  // only NaN is missing
  EXPECT_EQ(FormatOrMissing(2.5, "%.10g", ""), "2.5");
}

TEST(Format, RoundTripIsTheShortestTextThatReadsBack) {
  EXPECT_EQ(RoundTrip(0.1), "0.1");
  EXPECT_EQ(RoundTrip(1e-7), "1e-07");
  EXPECT_EQ(RoundTrip(300), "300");
  EXPECT_EQ(RoundTrip(-INFINITY), "-inf");
  EXPECT_EQ(RoundTrip(NAN), "nan");
  for (double v :
       {1.0 / 3, 2.0 / 7 * 1e-300, std::numeric_limits<double>::max(), 0.30000000000000004})
    EXPECT_EQ(std::stod(RoundTrip(v)), v) << RoundTrip(v);
}

// XML's five special characters but the apostrophe (attributes are written in double quotes);
// anything else, UTF-8 included, passes unchanged.
TEST(Format, XmlEscapedEscapesMarkupCharacters) {
  EXPECT_EQ(XmlEscaped("a < b && c > \"d\" 'e' μ"),
            "a &lt; b &amp;&amp; c &gt; &quot;d&quot; 'e' μ");
  EXPECT_EQ(XmlEscaped(""), "");
}

}  // namespace
}  // namespace talus
