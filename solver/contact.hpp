#pragma once
// Contact data shared by the detection and solve stages, and the per-thread step workspace.

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <vector>

#include "solver/kinematics.hpp"
#include "solver/soil.hpp"
#include "solver/terrain.hpp"

namespace talus {

// One vertex contact of the step: closed at the midpoint configuration (gap_m = 0), or open there
// and predicted to close before the next midpoint (gap_m > 0, see DetectContacts).
struct Contact {
  int vertex = 0;    // hull vertex index
  double gap_m = 0;  // open contact's gap along n at the midpoint; 0 for a closed one
  // The second contact of a closed vertex heading across a concave change of the terrain: the
  // face ahead, as a predicted contact (DetectContacts). Not warm-started.
  bool corner = false;
  // A held contact (ContactHold::kHeld): a contact of the step before, open at the midpoint, that
  // the free motion carries below the terrain by the next midpoint but not below the tolerance;
  // gap_m is its own gap. It never splits a step.
  bool held = false;
  // ContactHold::kHeld: the lift along n (>= 0) that the drift to the next midpoint gives the
  // vertex of a closed or held contact beyond the straight line of its velocity, the turn's
  // h^2 / 2 w x (w x arm), where gravity presses the vertex harder than the turn lifts it; the law
  // lets the vertex move that much towards the terrain, gap_m + lift_m + dt gamma_N,E >= 0, so
  // that a pivot the closed form loads keeps its load in every step (docs/model.md, "Held
  // contacts"). 0 otherwise.
  double lift_m = 0;
  int ground = 0;  // ground index at the contact point
  // Body frame: where the percussion acts; the vertex itself, or for a predicted contact with
  // SolverOptions::predicted_lever = kTouch the vertex turned to where it touches.
  Eigen::Vector3d lever_m = Eigen::Vector3d::Zero();
  double mu = 0;               // friction coefficient mu(s) for this step
  Eigen::Matrix3d directions;  // world: columns n, t1, t2
  Eigen::Matrix3d arms;        // body: columns b x (R' d) for d = n, t1, t2 (rotational Jacobian)
  Eigen::Matrix3d inv_inertia_arms;  // Theta^-1 arms
  Eigen::Matrix3d delassus;          // G = W' M^-1 W for this contact (1/kg), and its inverse
  Eigen::Matrix3d delassus_inverse;
  double r_normal = 0;  // prox step lengths (kg), used when the exact local solve fails
  double r_tangent = 0;
  // Contact-friction reading of the viscous term: nu dt m (kg), the tangential damping this
  // contact gets when it carries the whole normal load; 0 otherwise (SolveContacts).
  double viscous_kg = 0;
  // Added to the end contact velocity in the laws: xi = gamma_E + eps gamma_B (Newton's law: a
  // closed contact, or a predicted one reached within the step), else xi = gamma_E + ((gap_m +
  // lift_m)/dt, 0, 0).
  Eigen::Vector3d velocity_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d percussion = Eigen::Vector3d::Zero();  // (P_N, P_T1, P_T2), N s
};

// The scarring soil as contact detection leaves it for the rest of the step.
struct SoilContact {
  int ground = -1;         // soil category of the episode; -1: no vertex in a soil layer
  double depth_m = 0;      // rebound plane below the surface (eq. 11), m
  bool submerged = false;  // a vertex over soil is below the surface at the midpoint
};

// Scratch space reused across steps; one per thread. Reset() before each new rock.
struct StepWorkspace {
  std::vector<Contact> contacts;
  SoilContact soil;
  SubmergedPart submerged;  // the hull's part below the terrain (soil steps only)
  // Warm start: world percussion of each vertex in the previous step, and whether it was closed.
  std::vector<Eigen::Vector3d> last_percussion;
  std::vector<char> last_closed;
  std::vector<int> last_closed_list;
  DriftTurn drift_turn;  // the last half-step's turn, which the next half-step mostly repeats
  // The scar's last decay factor exp(-beta dt) and its beta (1/s) and dt (s); NaN: none yet.
  struct ScarDecay {
    double beta_1_s = std::numeric_limits<double>::quiet_NaN();
    double dt_s = std::numeric_limits<double>::quiet_NaN();
    double factor = 1;
  } scar_decay;
  // What the scene holds, looked up once per rock (SimulateRock) instead of in every step: some
  // ground category with the scarring soil, and some drag layer (a category's or the forest's).
  // True, i.e. looked for in every step, until set; Reset makes them true again.
  bool scene_has_soil = true;
  bool scene_has_drag = true;
  // Contact detection on hulls of many vertices (DetectContacts): where the last two walks to a
  // lowest vertex ended, whether to walk in the next detection, and the vertices that may touch,
  // found from there (marked with the search's stamp). Only the time taken depends on them.
  int walk_end[2] = {0, 0};
  bool walk_pays = true;
  std::vector<int> candidates;
  std::vector<unsigned> marks;
  unsigned stamp = 0;
  // Contact detection's local plane (DetectContacts), taken over a box wider than the detection's
  // and kept while the detection boxes of later steps lie inside it: the heights it was taken on
  // (null: none kept), the box's centre and half-width, and the plane. Only the time taken depends
  // on it.
  struct KeptPlane {
    std::shared_ptr<const Heightfield> heights;
    double x_m = 0, y_m = 0, half_m = 0;
    Terrain::LocalPlane plane;
  } kept_plane;

  void Reset(std::size_t vertex_count) {
    contacts.clear();
    scene_has_soil = scene_has_drag = true;
    last_percussion.assign(vertex_count, Eigen::Vector3d::Zero());
    last_closed.assign(vertex_count, 0);
    last_closed_list.clear();
    walk_end[0] = walk_end[1] = 0;
    walk_pays = true;
    kept_plane.heights.reset();
  }
  // Forgets the previous step's percussions (cost proportional to the contacts it had).
  void ForgetPercussions() {
    for (int v : last_closed_list) last_closed[v] = 0;
    last_closed_list.clear();
  }
};

}  // namespace talus
