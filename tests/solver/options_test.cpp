// The solver options and their table (kSolverOptions): defaults, bounds and IsValid, the enums'
// names, the presets, and the docs' [solver] table against the code's.

#include "solver/options.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "solver/ground.hpp"

namespace talus {
namespace {

TEST(Options, DefaultsAreValidAndBadValuesAreNamed) {
  std::string why;
  EXPECT_TRUE(SolverOptions{}.IsValid(&why)) << why;
  SolverOptions o;
  o.dt_s = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("dt_s"), std::string::npos) << why;
  o = SolverOptions{};
  o.prox_alpha = 2.5;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("prox_alpha"), std::string::npos) << why;
  o = SolverOptions{};
  o.penetration_tolerance = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("penetration_tolerance"), std::string::npos) << why;
  o = SolverOptions{};
  o.predicted_lever = static_cast<PredictedLever>(7);
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("predicted_lever"), std::string::npos) << why;
  o = SolverOptions{};
  o.normal_restitution = std::nan("");
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_NE(why.find("normal_restitution"), std::string::npos) << why;
  // One coefficient: equal pairs in [0, 1] are accepted, any other pair is refused by name
  // (Energy.NewtonRestitutionNeverAddsEnergyForAnyAcceptedCoefficient in step_test.cpp).
  for (const double eps : {0.0, 0.3, 1.0}) {
    o = SolverOptions{};
    o.normal_restitution = o.tangential_restitution = eps;
    EXPECT_TRUE(o.IsValid(&why)) << why;
  }
  for (const auto& [normal, tangential] :
       {std::pair{1.0, -1.0}, std::pair{0.5, 0.0}, std::pair{0.0, 0.5}, std::pair{1.2, 1.2}}) {
    o = SolverOptions{};
    o.normal_restitution = normal;
    o.tangential_restitution = tangential;
    EXPECT_FALSE(o.IsValid(&why)) << normal << ", " << tangential;
    EXPECT_NE(why.find("restitution"), std::string::npos) << why;
  }
  // Impact sub-steps split the plastic law's steps only: with restitution the steps are whole
  // (solver/step.cpp), and a scene that gives both is refused (io/scene_file.cpp); 1 .. 64.
  o = SolverOptions{};
  EXPECT_EQ(o.impact_substeps, 4);
  o.normal_restitution = o.tangential_restitution = 0.3;
  EXPECT_TRUE(o.IsValid(&why)) << why;
  for (const int k : {0, 65}) {
    o = SolverOptions{};
    o.impact_substeps = k;
    EXPECT_FALSE(o.IsValid(&why)) << k;
    EXPECT_NE(why.find("impact_substeps"), std::string::npos) << why;
  }
}

// IsValid's messages: the key, the value, the bound and the unit.
TEST(Options, MessagesStateTheValueTheBoundAndTheUnit) {
  std::string why;
  SolverOptions o;
  o.dt_s = -0.1;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "dt_s = -0.1 violates 0 < dt_s <= 0.1 s");
  o = SolverOptions{};
  o.max_time_s = INFINITY;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "max_time_s = inf violates max_time_s > 0 s");
  o = SolverOptions{};
  o.max_iterations = 0;
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "max_iterations = 0 violates 1 <= max_iterations <= 100000");
  o = SolverOptions{};
  o.soil_drag = static_cast<SoilDragPoint>(2);
  EXPECT_FALSE(o.IsValid(&why));
  EXPECT_EQ(why, "soil_drag = 2 is not one of centre_of_mass, submerged_centroid");
}

TEST(Options, ViscousReadingNamesRoundTrip) {
  EXPECT_EQ(SolverOptions{}.viscous, ViscousReading::kContactFriction);  // docs/model.md
  for (ViscousReading r : {ViscousReading::kCentreOfMass, ViscousReading::kContactFriction}) {
    ViscousReading parsed = r == ViscousReading::kCentreOfMass ? ViscousReading::kContactFriction
                                                               : ViscousReading::kCentreOfMass;
    EXPECT_TRUE(ParseViscousReading(ToString(r), &parsed));
    EXPECT_EQ(parsed, r);
  }
  ViscousReading parsed = ViscousReading::kCentreOfMass;
  EXPECT_FALSE(ParseViscousReading("drag", &parsed));
}

TEST(Options, ContactHoldNamesRoundTrip) {
  EXPECT_EQ(SolverOptions{}.contact_hold, ContactHold::kMidpoint);
  for (ContactHold h : {ContactHold::kMidpoint, ContactHold::kHeld}) {
    ContactHold parsed = ContactHold::kMidpoint;
    EXPECT_TRUE(ParseContactHold(ToString(h), &parsed));
    EXPECT_EQ(parsed, h);
  }
  ContactHold parsed = ContactHold::kHeld;
  EXPECT_FALSE(ParseContactHold("hold", &parsed));
}

TEST(Options, SubstepImpactsNamesRoundTrip) {
  EXPECT_EQ(SolverOptions{}.substep_impacts, SubstepImpacts::kFast);
  for (SubstepImpacts i : {SubstepImpacts::kFast, SubstepImpacts::kAll}) {
    SubstepImpacts parsed = SubstepImpacts::kFast;
    EXPECT_TRUE(ParseSubstepImpacts(ToString(i), &parsed));
    EXPECT_EQ(parsed, i);
  }
  SubstepImpacts parsed = SubstepImpacts::kAll;
  EXPECT_FALSE(ParseSubstepImpacts("every", &parsed));
}

TEST(Options, PredictedLeverNamesRoundTrip) {
  EXPECT_EQ(SolverOptions{}.predicted_lever, PredictedLever::kMidpoint);
  for (PredictedLever l : {PredictedLever::kMidpoint, PredictedLever::kTouch}) {
    PredictedLever parsed = PredictedLever::kMidpoint;
    EXPECT_TRUE(ParsePredictedLever(ToString(l), &parsed));
    EXPECT_EQ(parsed, l);
  }
  PredictedLever parsed = PredictedLever::kTouch;
  EXPECT_FALSE(ParsePredictedLever("contact", &parsed));
  EXPECT_EQ(parsed, PredictedLever::kTouch);
}

// Every enum's names: each enumerator's name is the one its list gives, and parses back to it.
TEST(EnumNames, EveryEnumeratorHasItsNameAndParsesBack) {
  EXPECT_STREQ(ToString(ViscousReading::kCentreOfMass), "centre_of_mass");
  EXPECT_STREQ(ToString(ViscousReading::kContactFriction), "contact_friction");
  EXPECT_STREQ(ToString(ContactSolveMethod::kGaussSeidel), "gauss_seidel");
  EXPECT_STREQ(ToString(ContactSolveMethod::kBlock), "block");
  EXPECT_STREQ(ToString(PredictedLever::kMidpoint), "midpoint");
  EXPECT_STREQ(ToString(PredictedLever::kTouch), "touch");
  EXPECT_STREQ(ToString(SoilDragPoint::kCentreOfMass), "centre_of_mass");
  EXPECT_STREQ(ToString(SoilDragPoint::kSubmergedCentroid), "submerged_centroid");
  EXPECT_STREQ(ToString(SolverPreset::kFast), "fast");
  EXPECT_STREQ(ToString(SolverPreset::kDefault), "default");
  EXPECT_STREQ(ToString(SolverPreset::kAccurate), "accurate");
  EXPECT_STREQ(ToString(GroundModel::kHard), "hard");
  EXPECT_STREQ(ToString(GroundModel::kLu2019), "lu2019");
  for (const EnumNames* names :
       {&kViscousReadingNames, &kContactSolveMethodNames, &kPredictedLeverNames,
        &kSoilDragPointNames, &kSolverPresetNames, &kGroundModelNames}) {
    std::set<std::string> seen;
    for (int k = 0; k < names->size(); ++k) {
      EXPECT_EQ(names->Find(names->Name(k)), k) << names->Name(k);
      EXPECT_TRUE(seen.insert(names->Name(k)).second) << names->Name(k);
    }
    EXPECT_STREQ(names->Name(names->size()), "unknown");
    EXPECT_STREQ(names->Name(-1), "unknown");
    EXPECT_EQ(names->Find("unknown"), -1);
  }
  EXPECT_EQ(kSolverPresetNames.List(), "fast, default, accurate");
  SolverPreset preset = SolverPreset::kAccurate;
  EXPECT_FALSE(ParseSolverPreset("fats", &preset));
  EXPECT_EQ(preset, SolverPreset::kAccurate);  // left as it was
}

TEST(Bounds, ContainDescribeAndPrintAsAnInterval) {
  const Bounds b = Bounds::AboveAtMost(0, 0.1);
  EXPECT_FALSE(b.Contains(0));
  EXPECT_TRUE(b.Contains(1e-300));
  EXPECT_TRUE(b.Contains(0.1));
  EXPECT_FALSE(b.Contains(std::nextafter(0.1, 1)));
  EXPECT_FALSE(b.Contains(std::nan("")));
  EXPECT_EQ(b.Describe("dt_s"), "0 < dt_s <= 0.1");
  EXPECT_EQ(b.Interval(), "(0, 0.1]");
  const Bounds above = Bounds::Above(0);
  EXPECT_FALSE(above.Contains(INFINITY));  // always finite
  EXPECT_TRUE(above.Contains(1e300));
  EXPECT_EQ(above.Describe("x"), "x > 0");
  EXPECT_EQ(above.Interval(), "(0, inf)");
  EXPECT_EQ(Bounds::AtLeast(0).Describe("x"), "x >= 0");
  EXPECT_EQ(Bounds::Between(-1, 1).Interval(), "[-1, 1]");
  EXPECT_EQ(Bounds::Inside(0, 2).Describe("prox_alpha"), "0 < prox_alpha < 2");
  EXPECT_EQ(Bounds{}.Describe("x"), "x finite");
}

TEST(SolverOptionTable, KeysAreUniqueAndFoundAndEveryMemberReadsItsOwnValue) {
  std::set<std::string> keys;
  for (const SolverOptionInfo& f : kSolverOptions) {
    EXPECT_TRUE(keys.insert(f.key).second) << f.key;
    EXPECT_EQ(FindSolverOption(f.key), &f);
    EXPECT_EQ(f.type == SolverOptionInfo::Type::kChoice, f.choices != nullptr) << f.key;
    EXPECT_NE(std::string(f.doc), "") << f.key;
  }
  EXPECT_EQ(FindSolverOption("preset"), nullptr);  // the scene's, not an option
  // Setting one option changes that member only (each row reads and writes its own member).
  for (const SolverOptionInfo& f : kSolverOptions) {
    SolverOptions o;
    const double value = f.member.get(o) == 0 ? 1 : 0;
    f.member.set(o, value);
    EXPECT_EQ(f.member.get(o), value) << f.key;
    for (const SolverOptionInfo& other : kSolverOptions)
      if (&other != &f) {
        EXPECT_EQ(other.member.get(o), other.member.get(SolverOptions{})) << f.key;
      }
  }
}

// Each row's bounds are what IsValid checks: its default inside, a closed end valid, a value just
// beyond either end (or at an open end) invalid and named.
TEST(SolverOptionTable, DefaultsAreInsideAndIsValidChecksEveryRowsBounds) {
  const SolverOptions defaults;
  for (const SolverOptionInfo& f : kSolverOptions) {
    EXPECT_TRUE(f.valid.Contains(f.member.get(defaults))) << f.key;
    const auto valid = [&](double v) {
      SolverOptions o;
      f.member.set(o, v);
      // The restitution coefficients are one (IsValid requires them equal): set as a pair.
      const std::string key = f.key;
      if (key == "normal_restitution") o.tangential_restitution = v;
      if (key == "tangential_restitution") o.normal_restitution = v;
      std::string why;
      const bool ok = o.IsValid(&why);
      const bool pair = key == "normal_restitution" || key == "tangential_restitution";
      if (!ok && pair) {
        EXPECT_NE(why.find("restitution = "), std::string::npos) << why;
      } else if (!ok) {
        EXPECT_EQ(why.rfind(key + " = ", 0), 0u) << why;
      }
      return ok;
    };
    const bool integral = f.type != SolverOptionInfo::Type::kNumber;
    const double step = integral ? 1 : 0;
    if (f.valid.lower > -Bounds::kInf) {
      const double below = integral ? f.valid.lower - step : std::nextafter(f.valid.lower, -1e300);
      EXPECT_FALSE(valid(f.valid.lower_open ? f.valid.lower : below)) << f.key;
      if (!f.valid.lower_open) {
        EXPECT_TRUE(valid(f.valid.lower)) << f.key;
      }
    }
    if (f.valid.upper < Bounds::kInf) {
      const double above = integral ? f.valid.upper + step : std::nextafter(f.valid.upper, 1e300);
      EXPECT_FALSE(valid(f.valid.upper_open ? f.valid.upper : above)) << f.key;
      if (!f.valid.upper_open) {
        EXPECT_TRUE(valid(f.valid.upper)) << f.key;
      }
    }
    if (!integral) {
      EXPECT_FALSE(valid(std::nan(""))) << f.key;
      EXPECT_FALSE(valid(INFINITY)) << f.key;
    }
    // The range scene files accept is inside the valid one.
    if (f.HasPlausibleRange()) {
      EXPECT_TRUE(f.valid.Contains(f.plausible_lower)) << f.key;
      EXPECT_TRUE(f.valid.Contains(f.plausible_upper)) << f.key;
      EXPECT_TRUE(f.plausible_lower <= f.member.get(defaults) &&
                  f.member.get(defaults) <= f.plausible_upper)
          << f.key;
    }
  }
}

// A preset sets exactly the rows marked preset_knob.
TEST(SolverOptionTable, PresetsSetTheKnobRowsAndNoOther) {
  for (SolverPreset p : {SolverPreset::kFast, SolverPreset::kDefault, SolverPreset::kAccurate}) {
    SolverOptions o;
    for (const SolverOptionInfo& f : kSolverOptions) f.member.set(o, f.valid.upper_open ? 0.5 : 1);
    const SolverOptions before = o;
    ApplyPreset(p, &o);
    std::string why;
    for (const SolverOptionInfo& f : kSolverOptions) {
      if (f.preset_knob) continue;
      EXPECT_EQ(f.member.get(o), f.member.get(before)) << ToString(p) << " " << f.key;
    }
    SolverOptions fresh;
    ApplyPreset(p, &fresh);
    EXPECT_TRUE(fresh.IsValid(&why)) << ToString(p) << ": " << why;
  }
  SolverOptions o;
  o.dt_s = 0.05;
  o.tolerance_m_s = 0.5;
  o.max_iterations = 3;
  ApplyPreset(SolverPreset::kDefault, &o);  // every knob back to its default
  const SolverOptions defaults;
  for (const SolverOptionInfo& f : kSolverOptions)
    if (f.preset_knob) {
      EXPECT_EQ(f.member.get(o), f.member.get(defaults)) << f.key;
    }
}

// docs/scenes.md's [solver] table as the table gives it: one row per scene key, in the table's
// order: | `key` | default | unit | bounds | meaning |.
std::string Number(double v) {
  char buffer[64];
  std::snprintf(buffer, sizeof buffer, "%.10g", v);
  return buffer;
}

std::string DocsRow(const SolverOptionInfo& f) {
  const double v = f.member.get(SolverOptions{});
  std::string row = "| `" + std::string(f.key) + "` | ";
  if (f.choices) {
    row += "`\"" + std::string(f.choices->Name(static_cast<int>(v))) + "\"` | — | ";
    for (int k = 0; k < f.choices->size(); ++k)
      row += std::string(k == 0                       ? ""
                         : k + 1 == f.choices->size() ? " or "
                                                      : ", ") +
             "`\"" + f.choices->Name(k) + "\"`";
  } else {
    row += Number(v) + " | " + (std::string(f.unit) == "1" ? "—" : f.unit) + " | ";
    const Bounds b =
        f.HasPlausibleRange() ? Bounds::Between(f.plausible_lower, f.plausible_upper) : f.valid;
    std::string bounds = b.Describe(std::string("`") + f.key + "`");
    for (const auto& [ascii, sign] : {std::pair{">=", "≥"}, std::pair{"<=", "≤"}})
      for (std::size_t at = bounds.find(ascii); at != std::string::npos; at = bounds.find(ascii))
        bounds.replace(at, 2, sign);
    row += bounds;
  }
  return row + " | " + f.doc + " |";
}

TEST(SolverOptionTable, DocsTableOfSceneKeysIsTheTables) {
  std::ifstream in(std::string(TALUS_SOURCE_DIR) + "/docs/scenes.md");
  ASSERT_TRUE(in) << "docs/scenes.md";
  std::vector<std::string> documented;
  bool in_section = false;
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("## ", 0) == 0) in_section = line == "## `[solver]`";
    if (!in_section || line.rfind("| `", 0) != 0) continue;
    const std::string key = line.substr(3, line.find('`', 3) - 3);
    if (FindSolverOption(key)) documented.push_back(line);
  }
  std::string expected, actual;
  for (const SolverOptionInfo& f : kSolverOptions) expected += DocsRow(f) + "\n";
  for (const std::string& line : documented) actual += line + "\n";
  EXPECT_EQ(actual, expected) << "docs/scenes.md, [solver]: the rows of the options should read\n"
                              << expected;
}

}  // namespace
}  // namespace talus
