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
  const GroundTable t = GroundTable::BuiltIn();
  ASSERT_EQ(t.size(), 8);
  const int hard = t.IndexOfName("hard");
  ASSERT_GE(hard, 0);
  EXPECT_EQ(t.category(hard).code, 6);
  EXPECT_DOUBLE_EQ(t.params(hard).mu_min, 0.55);
  EXPECT_DOUBLE_EQ(t.params(hard).beta_1_s, 185);
  EXPECT_DOUBLE_EQ(t.params(t.IndexOfCode(8)).mu_max, 0.35);  // snow
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
