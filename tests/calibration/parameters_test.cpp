// Free parameters: unit coordinates and their transforms, ties, bounds and feasibility.

#include "calibration/parameters.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.hpp"
#include "tests/calibration/fixtures.hpp"

namespace talus::calibration {
namespace {

using testing::Spec;

std::string ErrorOf(std::vector<ParameterSpec> specs) {
  try {
    ParameterSet set(std::move(specs), GroundTable::BuiltIn());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// Linear for mu, log for beta, kappa, nu by default; the ends map exactly onto the bounds and a
// value maps back onto its coordinate to round-off (1e-12 of the unit range: a few ulps of the
// log/exp pair).
TEST(ParameterSet, UnitCoordinatesMapOntoTheBounds) {
  const ParameterSet set(
      {Spec("medium", GroundField::kMuMin, 0.1, 0.9), Spec("medium", GroundField::kBeta, 10, 1000)},
      GroundTable::BuiltIn());
  ASSERT_EQ(set.size(), 2);
  EXPECT_FALSE(set.coordinates()[0].log);
  EXPECT_TRUE(set.coordinates()[1].log);
  const Eigen::VectorXd lo = set.Values(Eigen::Vector2d(0, 0));
  const Eigen::VectorXd hi = set.Values(Eigen::Vector2d(1, 1));
  EXPECT_EQ(lo[0], 0.1);
  EXPECT_EQ(lo[1], 10);
  EXPECT_EQ(hi[0], 0.9);
  EXPECT_EQ(hi[1], 1000);
  const Eigen::VectorXd mid = set.Values(Eigen::Vector2d(0.5, 0.5));
  EXPECT_NEAR(mid[0], 0.5, 1e-15);
  EXPECT_NEAR(mid[1], 100, 1e-12);  // geometric mean of 10 and 1000
  // Table 1's medium: mu_min 0.35, beta 150.
  const Eigen::VectorXd u = set.UnitOf(GroundTable::BuiltIn());
  EXPECT_NEAR(u[0], (0.35 - 0.1) / 0.8, 1e-12);
  EXPECT_NEAR(u[1], std::log(15.0) / std::log(100.0), 1e-12);
  const Eigen::VectorXd back = set.Values(u);
  EXPECT_NEAR(back[0], 0.35, 1e-12);
  EXPECT_NEAR(back[1], 150, 150 * 1e-12);
}

TEST(ParameterSet, TiedParametersMoveTogether) {
  GroundTable table = GroundTable::BuiltIn();
  const ParameterSet set({Spec("medium", GroundField::kMuMax, 0.5, 3, "mu_max_all"),
                          Spec("hard", GroundField::kMuMax, 0.5, 3, "mu_max_all"),
                          Spec("hard", GroundField::kNu, 0.1, 1)},
                         table);
  ASSERT_EQ(set.size(), 2);
  EXPECT_EQ(set.coordinates()[0].name, "mu_max_all");
  EXPECT_EQ(set.coordinates()[0].members.size(), 2u);
  std::string why;
  ASSERT_TRUE(set.Apply(Eigen::Vector2d(1, 0), table, &why)) << why;
  EXPECT_EQ(table.params(table.IndexOfName("medium")).mu_max, 3);
  EXPECT_EQ(table.params(table.IndexOfName("hard")).mu_max, 3);
  EXPECT_EQ(table.params(table.IndexOfName("hard")).nu_1_s, 0.1);
  EXPECT_EQ(table.params(table.IndexOfName("soft")).mu_max, 2.0);  // untouched
}

TEST(ParameterSet, BadSpecsAreClearErrors) {
  EXPECT_EQ(ErrorOf({Spec("medium", GroundField::kMuMin, 0.5, 0.5)}),
            "medium.mu_min: upper = 0.5 must be > lower = 0.5 (the bounds are empty)");
  EXPECT_EQ(ErrorOf({Spec("medium", GroundField::kBeta, 0, 10)}),
            "medium.beta: lower = 0 must be > 0 (every ground parameter is positive)");
  EXPECT_EQ(ErrorOf({Spec("medium", GroundField::kMuMax, 1, 6)}),
            "medium.mu_max: upper = 6 must be <= 5 for a friction coefficient");
  EXPECT_EQ(ErrorOf({Spec("meadow", GroundField::kMuMin, 0.1, 1)}),
            "meadow.mu_min: no ground category 'meadow'");
  EXPECT_EQ(
      ErrorOf({Spec("medium", GroundField::kNu, 0.1, 1), Spec("medium", GroundField::kNu, 0.2, 1)}),
      "medium.nu: freed twice");
  EXPECT_EQ(ErrorOf({Spec("medium", GroundField::kNu, 0.1, 1, "t"),
                     Spec("hard", GroundField::kKappa, 0.1, 1, "t")}),
            "hard.kappa: tie 't' joins parameters of one field with equal bounds and transform, "
            "unlike medium.nu");
  // Table 1's snow: mu_max 0.35, so mu_min >= 0.5 can never lie below it.
  EXPECT_EQ(ErrorOf({Spec("snow", GroundField::kMuMin, 0.5, 1)}),
            "snow: mu_min >= 0.5 and mu_max <= 0.35 within the bounds: no parameter vector has "
            "mu_min <= mu_max");
  EXPECT_EQ(ErrorOf({}), "no free parameter");
  // A soil parameter of a category without the scarring soil would change nothing.
  EXPECT_EQ(ErrorOf({Spec("medium", GroundField::kSoilStrength, 5, 50)}),
            "medium.soil_strength: category 'medium' has no scarring soil (a soil parameter acts "
            "only with model = \"lu2019\")");
}

// A tie named as another free parameter outside the tie would label one parameter's values with
// the other's name: tie = "medium.mu_max" on mu_min and "medium.mu_min" on mu_max swapped the
// labels of every report. Refused; a tie that names a parameter inside it, or a plain name, is not.
TEST(ParameterSet, ATieNamedAsAnotherFreeParameterIsRefused) {
  EXPECT_EQ(ErrorOf({Spec("medium", GroundField::kMuMin, 0.1, 1, "medium.mu_max"),
                     Spec("medium", GroundField::kMuMax, 0.1, 2, "medium.mu_min")}),
            "medium.mu_min: tie 'medium.mu_max' is the name of the free parameter medium.mu_max, "
            "which is not in the tie (its tie is 'medium.mu_min'): name the tie otherwise (e.g. "
            "'mu_min'), or give medium.mu_max the same tie");
  EXPECT_EQ(ErrorOf({Spec("medium", GroundField::kMuMax, 0.5, 3, "hard.mu_max"),
                     Spec("hard", GroundField::kMuMax, 0.5, 3)}),
            "medium.mu_max: tie 'hard.mu_max' is the name of the free parameter hard.mu_max, which "
            "is not in the tie: name the tie otherwise (e.g. 'mu_max'), or give hard.mu_max the "
            "same tie");
  // Accepted: the named parameter is in the tie; the tie is the parameter's own name.
  const ParameterSet joined({Spec("medium", GroundField::kMuMax, 0.5, 3, "hard.mu_max"),
                             Spec("hard", GroundField::kMuMax, 0.5, 3, "hard.mu_max")},
                            GroundTable::BuiltIn());
  EXPECT_EQ(joined.size(), 1);
  EXPECT_EQ(ErrorOf({Spec("medium", GroundField::kMuMin, 0.1, 1, "medium.mu_min"),
                     Spec("medium", GroundField::kMuMax, 0.1, 2)}),
            "");
}

// The calibrated fields are kGroundFields' rows in the enum's order, with their units and
// default transforms: one list of names for the scene, the calibration file and the outputs.
TEST(GroundField, IsTheGroundFieldTablesCalibratedRows) {
  std::vector<std::string> calibrated;
  for (const GroundFieldInfo& f : kGroundFields)
    if (f.calibrated) calibrated.emplace_back(f.key);
  const std::vector<std::string> expected = {"mu_min", "mu_max", "beta",           "kappa",
                                             "nu",     "soil_strength", "compaction_drag"};
  EXPECT_EQ(calibrated, expected);
  for (std::size_t k = 0; k < expected.size(); ++k) {
    GroundField field;
    ASSERT_TRUE(ParseGroundField(expected[k], &field));
    EXPECT_EQ(static_cast<std::size_t>(field), k);
    EXPECT_EQ(ToString(field), expected[k]);
  }
  EXPECT_STREQ(UnitOf(GroundField::kSoilStrength), "MN/m^2");
  ParameterSpec strength;
  strength.field = GroundField::kSoilStrength;
  EXPECT_TRUE(strength.UsesLog());
  ParameterSpec drag;
  drag.field = GroundField::kCompactionDrag;
  EXPECT_FALSE(drag.UsesLog());

  // Freed on a soil category, they reach the table.
  GroundTable table = GroundTable::BuiltIn();
  table.mutable_params(table.IndexOfName("medium")).model = GroundModel::kLu2019;
  const ParameterSet set({Spec("medium", GroundField::kSoilStrength, 5, 50),
                          Spec("medium", GroundField::kCompactionDrag, 0.1, 4)},
                         table);
  std::string why;
  ASSERT_TRUE(set.Apply(Eigen::Vector2d(1, 0), table, &why)) << why;
  EXPECT_EQ(table.params(table.IndexOfName("medium")).soil_strength_mn_m2, 50);
  EXPECT_EQ(table.params(table.IndexOfName("medium")).compaction_drag, 0.1);
}

// Both friction bounds free: the corner mu_min = 1.5 > mu_max = 1 is infeasible, says why and
// how far; a coordinate outside the cube or NaN too.
TEST(ParameterSet, InfeasibleVectorsAreRefusedWithTheirViolation) {
  GroundTable table = GroundTable::BuiltIn();
  const ParameterSet set(
      {Spec("medium", GroundField::kMuMin, 0.5, 1.5), Spec("medium", GroundField::kMuMax, 1, 3)},
      table);
  std::string why;
  double violation = -1;
  EXPECT_FALSE(set.Apply(Eigen::Vector2d(1, 0), table, &why, &violation));
  EXPECT_EQ(why, "medium: mu_max = 1 violates mu_min <= mu_max < infinity");
  EXPECT_DOUBLE_EQ(violation, 0.5);
  EXPECT_FALSE(set.Apply(Eigen::Vector2d(0, 1.25), table, &why, &violation));
  EXPECT_EQ(why, "medium.mu_max: coordinate 1.25 outside [0, 1]");
  EXPECT_DOUBLE_EQ(violation, 0.25);
  EXPECT_FALSE(set.Apply(Eigen::Vector2d(NAN, 0), table, &why, &violation));
  EXPECT_TRUE(std::isinf(violation));
  EXPECT_TRUE(set.Apply(Eigen::Vector2d(0.5, 0.5), table, &why, &violation));
  EXPECT_EQ(violation, 0);
}

}  // namespace
}  // namespace talus::calibration
