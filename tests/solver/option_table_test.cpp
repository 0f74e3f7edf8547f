// The pieces of the options tables (solver/option_table.hpp): EnumNames on a list of its own, the
// Bounds constructors at and beyond each end and their printed forms, and every row of the ground
// table kGroundFields: its default inside its bounds, and a value beyond either end refused by
// GroundParams::IsValid with the key, the value and the bound named. (The solver table's rows
// are swept the same way in options_test.cpp.)

#include "solver/option_table.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "solver/ground.hpp"

namespace talus {
namespace {

enum class Colour { kRed, kGreen, kBlue };
constexpr const char* kColours[] = {"red", "green", "blue"};
constexpr EnumNames kColourNames{"colour", kColours};

TEST(EnumNames, NamesFindsListsAndParsesItsOwnList) {
  EXPECT_EQ(kColourNames.size(), 3);
  EXPECT_STREQ(kColourNames.NameOf(Colour::kGreen), "green");
  EXPECT_STREQ(kColourNames.Name(2), "blue");
  EXPECT_STREQ(kColourNames.Name(3), "unknown");
  EXPECT_STREQ(kColourNames.Name(-1), "unknown");
  EXPECT_EQ(kColourNames.Find("red"), 0);
  EXPECT_EQ(kColourNames.Find("Red"), -1);   // names are case-sensitive
  EXPECT_EQ(kColourNames.Find("re"), -1);    // and whole
  EXPECT_EQ(kColourNames.Find("reds"), -1);
  EXPECT_EQ(kColourNames.Find(""), -1);
  EXPECT_EQ(kColourNames.List(), "red, green, blue");
  Colour c = Colour::kRed;
  EXPECT_TRUE(kColourNames.Parse("blue", &c));
  EXPECT_EQ(c, Colour::kBlue);
  EXPECT_FALSE(kColourNames.Parse("purple", &c));
  EXPECT_EQ(c, Colour::kBlue);  // left as it was
  constexpr const char* kOne[] = {"only"};
  EXPECT_EQ((EnumNames{"thing", kOne}.List()), "only");
  EXPECT_EQ((EnumNames{"nothing", {}}.List()), "");
  EXPECT_STREQ((EnumNames{"nothing", {}}.Name(0)), "unknown");
}

// Each constructor's ends: a closed end is in, an open end is out, the next double beyond an end
// is out; infinite and NaN values are never in, even with no bound at that end.
TEST(Bounds, EveryConstructorHasTheDocumentedEnds) {
  struct Case {
    Bounds b;
    bool lower_in, upper_in;
  };
  const Case cases[] = {{Bounds::Between(-1, 2), true, true},
                        {Bounds::Inside(-1, 2), false, false},
                        {Bounds::AboveAtMost(-1, 2), false, true}};
  for (const Case& c : cases) {
    EXPECT_EQ(c.b.Contains(-1), c.lower_in);
    EXPECT_EQ(c.b.Contains(2), c.upper_in);
    EXPECT_FALSE(c.b.Contains(std::nextafter(-1.0, -2.0)));
    EXPECT_FALSE(c.b.Contains(std::nextafter(2.0, 3.0)));
    EXPECT_TRUE(c.b.Contains(std::nextafter(-1.0, 0.0)));
    EXPECT_TRUE(c.b.Contains(std::nextafter(2.0, 0.0)));
  }
  EXPECT_TRUE(Bounds::AtLeast(3).Contains(3));
  EXPECT_FALSE(Bounds::Above(3).Contains(3));
  EXPECT_TRUE(Bounds::Above(3).Contains(std::nextafter(3.0, 4.0)));
  for (const Bounds& b : {Bounds{}, Bounds::AtLeast(0), Bounds::Above(0)}) {
    EXPECT_FALSE(b.Contains(INFINITY));
    EXPECT_FALSE(b.Contains(-INFINITY));
    EXPECT_FALSE(b.Contains(std::nan("")));
    EXPECT_TRUE(b.Contains(1e308));
  }
  EXPECT_TRUE(Bounds{}.Contains(-1e308));
}

// Describe and Interval for the shapes options_test.cpp does not print: an upper bound alone, a
// negative and a non-round number (as an ostream writes it: 6 significant digits), an infinite
// lower end with a closed finite upper one.
TEST(Bounds, DescribeAndIntervalOfUpperOnlyAndUnroundBounds) {
  const Bounds at_most{-Bounds::kInf, 5, false, false};
  EXPECT_EQ(at_most.Describe("x"), "x <= 5");
  EXPECT_EQ(at_most.Interval(), "(-inf, 5]");
  const Bounds below{-Bounds::kInf, 5, false, true};
  EXPECT_EQ(below.Describe("x"), "x < 5");
  EXPECT_EQ(below.Interval(), "(-inf, 5)");
  EXPECT_EQ(Bounds::Between(-0.5, 1e-5).Describe("y"), "-0.5 <= y <= 1e-05");
  EXPECT_EQ(Bounds::AboveAtMost(1.0 / 3, 2).Describe("z"), "0.333333 < z <= 2");
  EXPECT_EQ(Bounds::Inside(0, 2).Interval(), "(0, 2)");
  EXPECT_EQ(Bounds::AtLeast(1).Interval(), "[1, inf)");
  EXPECT_EQ(Bounds{}.Interval(), "(-inf, inf)");
}

// Every row of kGroundFields: the default inside, both closed ends valid, the next double beyond
// either end (and NaN, +-inf) refused with "<key> = <value> violates <bounds>" and the unit. mu_min
// and mu_max are kept in order (IsValid also requires mu_min <= mu_max): for a valid value of one,
// the other is moved with it.
TEST(GroundFieldTable, EveryRowsBoundsRefuseOutOfRangeValuesWithTheKeyNamed) {
  const GroundParams defaults;
  for (const GroundFieldInfo& f : kGroundFields) {
    EXPECT_TRUE(f.valid.Contains(defaults.*f.member)) << f.key;
    EXPECT_EQ(FindGroundField(f.key), &f);
    const std::string key = f.key;
    auto check = [&](double value, std::string* why) {
      GroundParams p;
      p.*f.member = value;
      if (key == "mu_min" && f.valid.Contains(value)) p.mu_max = std::max(p.mu_max, value);
      if (key == "mu_max" && f.valid.Contains(value)) p.mu_min = std::min(p.mu_min, value);
      return p.IsValid(why);
    };
    ASSERT_TRUE(std::isfinite(f.valid.lower) && std::isfinite(f.valid.upper))
        << f.key << ": every ground field has two finite bounds";
    std::string why;
    EXPECT_TRUE(check(f.valid.lower, &why)) << f.key << ": " << why;
    EXPECT_TRUE(check(f.valid.upper, &why)) << f.key << ": " << why;
    const std::string unit =
        std::string(f.unit) == "1" ? "" : " (" + std::string(f.unit) + ")";
    for (double bad : {std::nextafter(f.valid.lower, -Bounds::kInf),
                       std::nextafter(f.valid.upper, Bounds::kInf), std::nan(""), Bounds::kInf,
                       -Bounds::kInf}) {
      why.clear();
      EXPECT_FALSE(check(bad, &why)) << f.key << " = " << bad;
      EXPECT_EQ(why.rfind(key + " = ", 0), 0u) << why;
      EXPECT_NE(why.find("violates " + f.valid.Describe(f.key) + unit), std::string::npos)
          << why;
    }
  }
  EXPECT_EQ(FindGroundField("nu_1_s"), nullptr);  // the member's name is not the key
}

}  // namespace
}  // namespace talus
