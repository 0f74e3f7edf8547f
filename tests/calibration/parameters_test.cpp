// Free parameters: unit coordinates and their transforms, ties, bounds and feasibility.

#include "calibration/parameters.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "common/error.hpp"
#include "solver/shapes.hpp"
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

// --- shape parameters ---------------------------------------------------------------------------

// Two blocks for the shape tests: "slab", a box whose knobs are its size (no roughness), and
// "scan", a fixed shape (as a point cloud's: no maker). The slab's maker keeps its density, so the
// made shape's mass says which size it was made from; a size with an axis above 5 m is refused
// (as a density outside the scene's bounds would be).
std::vector<ensemble::Block> TestBlocks() {
  ensemble::Block slab;
  slab.id = "slab";
  slab.knobs.size_m = Eigen::Vector3d(1.0, 0.5, 0.25);
  slab.make = [](const ensemble::ShapeKnobs& k) {
    if (k.size_m.maxCoeff() > 5) throw InputError("the volume is outside the bounds");
    return MakeRockShape(MakeBox(k.size_m.x(), k.size_m.y(), k.size_m.z()), 2000);
  };
  slab.shape = std::make_shared<const RockShape>(slab.make(slab.knobs));
  ensemble::Block scan;
  scan.id = "scan";
  scan.shape = std::make_shared<const RockShape>(MakeRockShape(MakeBox(1, 1, 1), 2700));
  return {slab, scan};
}

ParameterSpec ShapeSpec(const std::string& block, ShapeField field, double lower, double upper,
                        const std::string& tie = "") {
  ParameterSpec s;
  s.block = block;
  s.shape_field = field;
  s.lower = lower;
  s.upper = upper;
  s.tie = tie;
  return s;
}

std::string ShapeErrorOf(std::vector<ParameterSpec> specs) {
  try {
    ParameterSet set(std::move(specs), GroundTable::BuiltIn(), TestBlocks());
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// A shape parameter beside a ground one: named after its block, linear, its start the block's own
// knob; Apply leaves it alone, ApplyShapes writes it into the block's knobs and remakes that
// block's shape (mass 2000 kg/m3 x the new volume), leaving the other block's shape as it was.
TEST(ParameterSet, ShapeParametersRemakeTheirBlock) {
  GroundTable table = GroundTable::BuiltIn();
  std::vector<ensemble::Block> blocks = TestBlocks();
  const ParameterSet set(
      {Spec("medium", GroundField::kMuMin, 0.1, 0.9), ShapeSpec("slab", ShapeField::kSizeX, 0.5, 2)},
      table, blocks);
  ASSERT_EQ(set.size(), 2);
  EXPECT_TRUE(set.has_shapes());
  EXPECT_EQ(set.coordinates()[1].name, "blocks.slab.size_x_m");
  EXPECT_FALSE(set.coordinates()[1].log);
  EXPECT_EQ(set.specs()[1].Unit(), std::string("m"));
  EXPECT_NEAR(set.UnitOf(table)[1], (1.0 - 0.5) / 1.5, 1e-15);

  std::string why;
  const GroundTable before = table;
  ASSERT_TRUE(set.Apply(Eigen::Vector2d(0.5, 1), table, &why)) << why;
  EXPECT_EQ(table.params(table.IndexOfName("medium")).mu_min, 0.5);
  const std::shared_ptr<const RockShape> scan = blocks[1].shape;
  ASSERT_TRUE(set.ApplyShapes(Eigen::Vector2d(0.5, 1), blocks, &why)) << why;
  EXPECT_EQ(blocks[0].knobs.size_m, Eigen::Vector3d(2, 0.5, 0.25));
  EXPECT_NEAR(blocks[0].shape->mass_kg, 2000 * 2 * 0.5 * 0.25, 1e-9);
  EXPECT_EQ(blocks[1].shape, scan);  // not touched
  // Without shape parameters there is nothing to do.
  const ParameterSet ground({Spec("medium", GroundField::kMuMin, 0.1, 0.9)}, before, blocks);
  EXPECT_FALSE(ground.has_shapes());
  EXPECT_TRUE(ground.ApplyShapes(Eigen::VectorXd::Constant(1, 0.3), blocks, &why));
  EXPECT_EQ(blocks[0].knobs.size_m.x(), 2);
}

// A knob whose shape cannot be made makes the vector infeasible, naming the block.
TEST(ParameterSet, AShapeThatCannotBeMadeIsRefused) {
  std::vector<ensemble::Block> blocks = TestBlocks();
  const ParameterSet set({ShapeSpec("slab", ShapeField::kSizeY, 0.1, 8)}, GroundTable::BuiltIn(),
                         blocks);
  std::string why;
  EXPECT_FALSE(set.ApplyShapes(Eigen::VectorXd::Constant(1, 1.0), blocks, &why));
  EXPECT_EQ(why, "block 'slab': the volume is outside the bounds");
}

TEST(ParameterSet, ShapeParametersNeedABlockWithTheKnob) {
  EXPECT_EQ(ShapeErrorOf({ShapeSpec("boulder", ShapeField::kSizeX, 0.5, 2)}),
            "blocks.boulder.size_x_m: no block 'boulder'");
  EXPECT_EQ(ShapeErrorOf({ShapeSpec("slab", ShapeField::kRoughness, 0, 0.3)}),
            "blocks.slab.roughness: block 'slab' has no roughness (only a rock block has one)");
  EXPECT_EQ(ShapeErrorOf({ShapeSpec("scan", ShapeField::kSizeX, 0.5, 2)}),
            "blocks.scan.size_x_m: block 'scan' has a fixed shape (a point cloud): only built-in "
            "blocks have knobs");
  EXPECT_EQ(ShapeErrorOf({ShapeSpec("slab", ShapeField::kSizeX, 0, 2)}),
            "blocks.slab.size_x_m: lower = 0 must be > 0 (a size is positive)");
  ParameterSpec both = ShapeSpec("slab", ShapeField::kSizeX, 0.5, 2);
  both.category = "medium";
  EXPECT_EQ(ShapeErrorOf({both}), "blocks.slab.size_x_m: names both a ground category and a block");
  // A tie joins one field: a size and a friction coefficient cannot share a coordinate.
  EXPECT_NE(ShapeErrorOf({ShapeSpec("slab", ShapeField::kSizeX, 0.5, 2, "t"),
                          Spec("medium", GroundField::kMuMin, 0.5, 2, "t")})
                .find("joins parameters of one field"),
            std::string::npos);
  EXPECT_EQ(ShapeErrorOf({ShapeSpec("slab", ShapeField::kSizeX, 0.5, 2),
                          ShapeSpec("slab", ShapeField::kSizeX, 0.6, 2)}),
            "blocks.slab.size_x_m: freed twice");
  // A roughness may start at 0 (a smooth ellipsoid), and stops at 0.5.
  ParameterSpec r = ShapeSpec("any", ShapeField::kRoughness, 0, 0.6);
  std::string why;
  EXPECT_FALSE(r.IsValid(&why));
  EXPECT_EQ(why, "blocks.any.roughness: upper = 0.6 must be <= 0.5 for a roughness");
  r.upper = 0.5;
  EXPECT_TRUE(r.IsValid(&why));
}

}  // namespace
}  // namespace talus::calibration
