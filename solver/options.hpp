#pragma once
// Solver options: every knob a user trades against accuracy, with defaults, units and a check.

#include <array>
#include <string>
#include <string_view>

#include "solver/option_table.hpp"

namespace talus {

// How the ground's viscous coefficient nu (1/s, GroundParams::nu_1_s) acts (docs/model.md,
// "The viscous term"). Scene files name the readings "centre_of_mass" and "contact_friction".
enum class ViscousReading {
  // Drag -m nu v_S on the centre of mass in every step with a contact (wave 1's reading; caps a
  // rolling or tumbling rock's speed at g sin(theta) / nu).
  kCentreOfMass,
  // Viscous friction in the tangential contact law of each loaded contact, acting on the slip
  // velocity of the contact point with the Coulomb friction: -nu m_i gamma_T, where the rock's mass
  // is shared among the loaded contacts in proportion to their normal percussions. A sliding rock
  // feels -m nu v (the seed's S_v); a rolling contact that does not slip feels nothing.
  kContactFriction,
};
extern const EnumNames kViscousReadingNames;   // "centre_of_mass", "contact_friction"
const char* ToString(ViscousReading reading);  // its name in kViscousReadingNames
// False, leaving *reading as it is, when `name` is not one of the names ToString gives.
bool ParseViscousReading(std::string_view name, ViscousReading* reading);

// How the contact solve treats a step with two contacts (a rock on an edge). Scene files name the
// methods "gauss_seidel", "block" and "block_on_stall".
enum class ContactSolveMethod {
  // Gauss-Seidel sweeps over the contacts, each solved exactly with the others held fixed.
  kGaussSeidel,
  // Two contacts solved as one coupled 6 x 6 problem (solver/contact_block.hpp): after one
  // warm-started sweep, the active-set case it suggests (each contact separated, sticking or
  // slipping) is solved exactly and checked against the laws, then the other cases; Gauss-Seidel
  // goes on when none verifies. Slip directions start from the previous iterate and Newton stops
  // at the solver tolerance. Other contact counts are solved as with kGaussSeidel.
  kBlock,
  // Gauss-Seidel, and a pair that has not converged after 20 sweeps solved as kBlock solves it
  // (then Gauss-Seidel again if no case verifies). Sweeps stall on some edges: on the ramp 0.7 %
  // of the two-contact steps ran to max_iterations, a fifth of all sweeps, and ended unconverged.
  // A step that converges within 20 sweeps is the same bits as under kGaussSeidel.
  kBlockOnStall,
};
extern const EnumNames kContactSolveMethodNames;  // "gauss_seidel", "block", "block_on_stall"
const char* ToString(ContactSolveMethod method);
bool ParseContactSolveMethod(std::string_view name, ContactSolveMethod* method);

// Where the percussion of a predicted contact (a vertex open at the midpoint that the step's free
// motion would carry into the terrain) acts. Scene files name them "midpoint" and "touch".
enum class PredictedLever {
  // At the vertex as it is at the step's midpoint, up to one step before it touches.
  kMidpoint,
  // At the vertex as it will be when it touches: turned by the free angular velocity over the time
  // its predicted path takes to reach the contact plane (docs/model.md, "Where a predicted
  // contact acts").
  kTouch,
};
extern const EnumNames kPredictedLeverNames;  // "midpoint", "touch"
const char* ToString(PredictedLever lever);
bool ParsePredictedLever(std::string_view name, PredictedLever* lever);

// Which open vertices join a step's contact set besides those predicted deeper than the
// penetration tolerance (docs/model.md, "Held contacts"). Scene files name them "midpoint" and
// "held".
enum class ContactHold {
  // None besides those: an open vertex is a contact only when predicted. A rock pivoting on a
  // vertex finds it a hair above the terrain at the midpoint in some steps (the midpoint drifts
  // with the begin velocities, without gravity's pull), and those steps are free flight: the scar
  // decays and the viscous term is off in about 3 % of a tipping block's steps at dt 2 ms and at
  // 0.5 ms alike. The default.
  kMidpoint,
  // Also a vertex that was a contact in the step before and that the free motion (gravity
  // included) carries below the terrain by the next midpoint, but not below the tolerance: it is
  // held by the gap law at its own gap, reaching the terrain at the next midpoint and no further.
  // Plastic law only; it never splits a step (SolverOptions::impact_substeps).
  kHeld,
};
extern const EnumNames kContactHoldNames;  // "midpoint", "held"
const char* ToString(ContactHold hold);
bool ParseContactHold(std::string_view name, ContactHold* hold);

// Which steps are impacts that SolverOptions::impact_substeps takes as sub-steps (docs/model.md,
// "Impact sub-steps"). Scene files name them "fast" and "all".
enum class SubstepImpacts {
  // Fast impacts: a step whose contact set holds a predicted contact (a vertex that the free motion
  // carries deeper than the penetration tolerance by the next midpoint), or a vertex that was
  // within the tolerance at the step's begin and is deeper than it at the midpoint. The default.
  kFast,
  // Every impact: also a step in which a vertex that was no contact in the step before closes,
  // however slowly it arrives. A strike (a vertex that meets the ground and leaves again) is then
  // charged a sub-step's scar growth and viscous term, not a whole step's (docs/model.md,
  // "Arrivals as impacts").
  kAll,
};
extern const EnumNames kSubstepImpactsNames;  // "fast", "all"
const char* ToString(SubstepImpacts impacts);
bool ParseSubstepImpacts(std::string_view name, SubstepImpacts* impacts);

// Where the scar drag of the scarring soil (Lu et al. 2019, eq. 9) acts. Scene files name the
// points "centre_of_mass" and "submerged_centroid".
enum class SoilDragPoint {
  // At the centre of mass, against its velocity, on the frontal area normal to it (the paper: the
  // rock keeps its rotation, no drag torque).
  kCentreOfMass,
  // At the centroid of the hull's part below the surface, against that point's velocity, on the
  // frontal area normal to it: the drag also exerts a torque (beyond the paper; its authors name
  // the missing drag torque as why rotational energy is matched only roughly).
  kSubmergedCentroid,
};
extern const EnumNames kSoilDragPointNames;  // "centre_of_mass", "submerged_centroid"
const char* ToString(SoilDragPoint point);
bool ParseSoilDragPoint(std::string_view name, SoilDragPoint* point);

// Every option below is a row of kSolverOptions (after the struct): its key, unit, bounds and doc
// line, from which [solver] in scene files, summary.json, IsValid and the docs' table are read.
struct SolverOptions {
  double dt_s = 0.002;         // time step
  double max_time_s = 300;     // a rock still moving then ends as max_time
  double gravity_m_s2 = 9.81;  // along -z
  // Newton's impact law xi = gamma_E + epsilon gamma_A, one coefficient for the normal and the
  // tangential directions: the model is fully plastic (0). Only equal coefficients in [0, 1] are
  // energetically consistent for every contact configuration (Glocker 2013, Part I): with
  // epsilon_T != epsilon_N a sticking contact of a rotating body can gain energy (Kane's
  // paradox), so IsValid requires tangential_restitution == normal_restitution.
  double normal_restitution = 0.0;      // epsilon_N in [0, 1]
  double tangential_restitution = 0.0;  // epsilon_T, equal to epsilon_N
  // Reading of the viscous ground term: the seed paper's viscous friction by default, the one the
  // field data and the ramp support (docs/model.md, "Which reading the data support").
  ViscousReading viscous = ViscousReading::kContactFriction;
  // Contact solve: Gauss-Seidel sweeps until the largest velocity change a sweep makes at any
  // contact point is below tolerance_m_s, or max_iterations sweeps. 1e-3 m/s: the ensemble
  // statistics of the ramp and cases/tirol agree with 1e-7 m/s within their standard errors, at
  // 1.4 times the ramp's trajectories per CPU second (bench/README.md, "Default tolerance").
  // Calibration runs its own tight solve (calibration::kCalibrationTolerance_m_s), and tests of
  // the contact solve itself set theirs.
  double tolerance_m_s = 1e-3;
  int max_iterations = 200;
  // Two-contact steps: Gauss-Seidel sweeps, one coupled block solve, or (the default) sweeps and
  // the block solve for a pair whose sweeps stall (bench/README.md, "A block solve for stalled
  // pairs", and "Block on stall as the default").
  ContactSolveMethod contact_solve = ContactSolveMethod::kBlockOnStall;
  double prox_alpha = 1.0;  // step length r = alpha / diag(W' M^-1 W), in (0, 2)
  // Contact prediction (plastic normal law only): a vertex that would sink deeper than this
  // fraction of the rock's thickness by the next midpoint joins the contact set early and is
  // stopped at that depth. In (0, 0.5]: above 0, since stopping vertices at the surface puts a
  // slowly arriving contact's percussion ahead of the pivot, a rolling resistance of order
  // v dt / r (docs/model.md, "Why delta > 0"); at most one half, since a resting rock sinks by
  // about this much and at half its thickness the centre of a symmetric rock reaches the surface
  // (a buried rock, not a tolerance).
  double penetration_tolerance = 0.01;
  // Where a predicted contact's percussion acts.
  PredictedLever predicted_lever = PredictedLever::kMidpoint;
  // Whether a contact of the step before that the free motion carries back below the terrain is
  // held (docs/model.md, "Held contacts"): without it a pivoting or sliding rock's load, and with
  // it the scar's growth and the viscous term, drop out of some of its steps. Not yet the default:
  // with it dt 2 ms is further from its fine-step limit on the ramp, and the shipped tables were
  // fitted without it.
  ContactHold contact_hold = ContactHold::kMidpoint;
  // Impact sub-steps (docs/model.md, "Impact sub-steps"): a step whose contact set holds a
  // predicted contact is taken as this many sub-steps of dt / impact_substeps, so that the
  // percussion acts near the instant of the impact instead of up to a step early; 1: never.
  // 4 brings cases/tirol at dt 2 ms within the standard errors of dt 0.5 ms (docs/model.md).
  // The plastic law's only: with normal_restitution > 0 every step is whole (Newton's law takes
  // the begin velocities of the step it acts in), and a scene that gives both is refused
  // (io/scene_file.cpp).
  int impact_substeps = 4;
  // Which steps are impacts for impact_substeps: fast ones only, or every step in which a vertex
  // closes that was no contact in the step before. With contact_hold "held", which it needs
  // (io/scene_file.cpp), "all" brings rock-like hulls at dt 2 ms close to the fine-step limit (the
  // Tschamut blocks' run-out median error 1.60 -> 0.65 m, p95 21 -> 4 m); not yet the default, as
  // "held" is not (docs/model.md, "Arrivals as impacts").
  SubstepImpacts substep_impacts = SubstepImpacts::kFast;
  // Where the scar drag of a soil category (GroundModel::kLu2019) acts.
  SoilDragPoint soil_drag = SoilDragPoint::kCentreOfMass;
  // Rest: speed and angular speed below these thresholds, in contact, for rest_hold_s.
  double rest_speed_m_s = 0.02;
  double rest_angular_speed_rad_s = 0.05;
  double rest_hold_s = 1.0;

  // False, with the field, value and violated bound in *why, when an option is out of range
  // (kSolverOptions' bounds).
  bool IsValid(std::string* why) const;
};

// One option of SolverOptions as scene files ([solver]), summary.json and docs/scenes.md name it:
// every list of solver options reads kSolverOptions, so that a new option is one row there (and
// the code that uses it).
struct SolverOptionInfo {
  enum class Type {
    kNumber,   // a double
    kInteger,  // an int
    kChoice,   // an enum, by the names of `choices`
  };
  // Reads and writes the option's member as a double (an enum: its enumerator's number).
  struct Member {
    double (*get)(const SolverOptions&);
    void (*set)(SolverOptions&, double);
  };
  const char* key;  // in [solver] and summary.json, e.g. "dt_s"
  Type type;
  Member member;
  const char* unit;  // "1" for dimensionless numbers and for choices
  // Valid values (IsValid); a choice: 0 .. the number of names - 1.
  Bounds valid;
  // Scene files also reject finite values outside plausible_lower .. plausible_upper (a typo or a
  // wrong unit that would otherwise run), where that is narrower than `valid`.
  double plausible_lower = -Bounds::kInf, plausible_upper = Bounds::kInf;
  const EnumNames* choices = nullptr;  // kChoice: the names of the values
  bool preset_knob = false;            // set by a SolverPreset (ApplyPreset)
  const char* doc = "";                // one line for the docs' table

  bool HasPlausibleRange() const {
    return plausible_lower > -Bounds::kInf || plausible_upper < Bounds::kInf;
  }
};
extern const std::array<SolverOptionInfo, 19> kSolverOptions;
// nullptr when `key` is no option's key.
const SolverOptionInfo* FindSolverOption(std::string_view key);

// Named settings of the accuracy knobs (dt_s, tolerance_m_s, max_iterations), chosen from the
// work-precision study on the ramp and cases/tirol (bench/README.md, "The work-precision map of
// every knob"), where runout median and 95th percentile, reach probability and energy p95 at
// evaluation lines were compared with each knob's tightest setting over five seeds:
// - kFast: tolerance 1e-2 m/s (1.7 times the ramp's trajectories per second of 1e-7 m/s, every
//   statistic within its standard errors on both scenes; little gain on real terrain);
// - kDefault: dt 2 ms, tolerance 1e-3 m/s, 200 sweeps (SolverOptions' defaults; 1e-3 m/s gives
//   1.4 times the ramp's trajectories per CPU second of 1e-7 m/s, every statistic within its
//   standard errors on both scenes);
// - kAccurate: dt 1 ms, tolerance 1e-7 m/s, 1000 sweeps (dt 1 ms alone costs 1.5-1.7 times the
//   default; it is the step whose statistics agree with dt 0.5 ms on both scenes, where dt 2 ms
//   shortens tirol's runout median by 81 +- 18 m: the setting to check a result against).
enum class SolverPreset { kFast, kDefault, kAccurate };
extern const EnumNames kSolverPresetNames;  // "fast", "default", "accurate"
const char* ToString(SolverPreset preset);
bool ParseSolverPreset(std::string_view name, SolverPreset* preset);
// Sets the preset's knobs (kSolverOptions' rows with preset_knob) in *options, leaving every other
// option as it is.
void ApplyPreset(SolverPreset preset, SolverOptions* options);

}  // namespace talus
