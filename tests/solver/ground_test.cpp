#include "solver/ground.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace talus {
namespace {

TEST(GroundParams, DefaultsAreValid) {
  std::string why;
  EXPECT_TRUE(GroundParams{}.IsValid(&why)) << why;
  EXPECT_TRUE(GroundTable::BuiltIn().IsValid(&why)) << why;
}

TEST(GroundParams, FrictionFollowsSeedPaperEquation2) {
  // Seed paper Eq. 2: mu(s) = mu_min + 2/pi (mu_max - mu_min) atan(kappa s).
  const GroundParams p{0.4, 2.0, 175, 2.5, 0.5};
  EXPECT_DOUBLE_EQ(p.Friction(0.0), 0.4);
  EXPECT_NEAR(p.Friction(1.0 / 2.5), 0.4 + 0.5 * 1.6, 1e-15);  // atan(1) = pi/4
  EXPECT_NEAR(p.Friction(1e9), 2.0, 1e-8);
}

TEST(GroundTable, BuiltInMatchesTable1) {
  // Seed paper, Table 1 ("Ground categories and associated friction parameters in the
  // RAMMS::ROCKFALL program"), all 40 values as printed there, in the paper's order of categories
  // (reference/000_e89aa5aad63e1e53.txt, lines 82-85), with the raster codes 1-8 of DESIGN.md in
  // that order. Exact: the built-in table holds the printed decimals.
  struct Row {
    const char* name;
    int code;
    double mu_min, mu_max, beta_1_s, kappa_1_m, nu_1_s;
  };
  const Row table1[] = {
      {"extra_soft", 1, 0.2, 2, 50, 1, 0.9},      // Extra Soft (moor)
      {"soft", 2, 0.25, 2, 100, 1.25, 0.8},       // Soft (moist, deep meadow)
      {"medium_soft", 3, 0.3, 2, 125, 1.5, 0.7},  // Medium Soft (deep meadow)
      {"medium", 4, 0.35, 2, 150, 2, 0.6},        // Medium (meadow)
      {"medium_hard", 5, 0.4, 2, 175, 2.5, 0.5},  // Medium Hard (shallow meadow)
      {"hard", 6, 0.55, 2, 185, 3, 0.4},          // Hard (rock scree)
      {"extra_hard", 7, 0.8, 2, 200, 4, 0.3},     // Extra Hard (rock face, bedrock)
      {"snow", 8, 0.1, 0.35, 150, 2, 0.7},        // Snow
  };
  const GroundTable t = GroundTable::BuiltIn();
  ASSERT_EQ(t.size(), 8);
  for (const Row& row : table1) {
    SCOPED_TRACE(row.name);
    const int i = t.IndexOfName(row.name);
    ASSERT_GE(i, 0);
    EXPECT_EQ(t.IndexOfCode(row.code), i);
    EXPECT_EQ(t.category(i).code, row.code);
    const GroundParams& p = t.params(i);
    EXPECT_EQ(p.mu_min, row.mu_min);
    EXPECT_EQ(p.mu_max, row.mu_max);
    EXPECT_EQ(p.beta_1_s, row.beta_1_s);
    EXPECT_EQ(p.kappa_1_m, row.kappa_1_m);
    EXPECT_EQ(p.nu_1_s, row.nu_1_s);
  }
  EXPECT_EQ(t.IndexOfName("gravel"), -1);
}

TEST(GroundTable, UserCategoriesAddOrOverride) {
  GroundTable t = GroundTable::BuiltIn();
  const int scree = t.Set({"my_scree", 11, {0.5, 2.0, 180, 3.0, 0.4}});
  EXPECT_EQ(t.IndexOfCode(11), scree);
  t.Set({"medium", 4, {0.36, 2.0, 150, 2.0, 0.6}});
  EXPECT_EQ(t.size(), 9);
  EXPECT_DOUBLE_EQ(t.params(t.IndexOfName("medium")).mu_min, 0.36);
  std::string why;
  t.Set({"clash", 5, {}});
  EXPECT_FALSE(t.IsValid(&why));
  EXPECT_NE(why.find("share code 5"), std::string::npos) << why;
}

TEST(GroundParams, NonPhysicalValuesNameTheField) {
  std::string why;
  GroundParams p;
  p.mu_max = 0.1;  // below mu_min
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("mu_max"), std::string::npos) << why;
  p = GroundParams{};
  p.nu_1_s = std::nan("");
  EXPECT_FALSE(p.IsValid(&why));
  EXPECT_NE(why.find("nu"), std::string::npos) << why;
}

}  // namespace
}  // namespace talus
