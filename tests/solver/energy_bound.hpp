#pragma once
// How much one step of the midpoint scheme may raise a rock's mechanical energy (kinetic plus
// m g z) when its contacts are plastic (epsilon_N = 0): derived, so that energy checks need no
// measured slack.
//
// Against the free motion (gravity and free rotation over the step, which keeps the mechanical
// energy exactly: gravity's kinetic gain equals the potential drop of the position update), let
// Delta u be the change of the centre-of-mass velocity that the percussions (and any implicit
// drag) make. The end position takes half a step of the end velocity, so the potential energy
// changes by m g dt/2 Delta u_z more than in the free motion. The solve gives
// T_E - T_free = P' gamma_E - P' G P / 2, with P' gamma_E <= 0 (P_N gamma_N,E = 0 at a closed
// contact, -P_N g / dt at a predicted one; Coulomb and viscous friction oppose the slip) and
// P' G P = m |Delta u|^2 + Delta w' Theta Delta w >= m Delta u_z^2; an implicit drag u_E = a
// u_free, 0 < a <= 1, obeys the same inequality. So one step changes the energy by at most -m Delta
// u_z^2 / 2 + m g dt/2 Delta u_z <= m g^2 dt^2 / 8, whatever the contacts do: the scheme's own
// order-dt^2 drift (a block pivoting on a sticking vertex climbs by it for tens of steps). A solve
// stopped by its tolerance (no contact velocity changed by more than tolerance_m_s in its last
// sweep) meets each law to within about that velocity, so its percussions may do about
// tolerance_m_s * sum |P| more work (at the default 1e-3 m/s one ramp step exceeded m g^2 dt^2 / 8
// by 2.1e-10 of the release energy; none did at 1e-7 m/s).

#include "solver/scene.hpp"
#include "solver/step.hpp"

namespace talus::testing {

// The bound, J, for the step that just ran in `ws` and reported `step`.
inline double StepEnergyBound(const Scene& scene, const StepWorkspace& ws, const StepReport& step) {
  const double m = scene.rock.mass_kg, g = scene.options.gravity_m_s2, dt = scene.options.dt_s;
  double percussions = 0;  // sum of |P| over the step's contacts, N s
  if (step.contacts > 0)
    for (const Contact& c : ws.contacts) percussions += c.percussion.norm();
  return m * g * g * dt * dt / 8 + scene.options.tolerance_m_s * percussions;
}

// Round-off of a difference of energies summed from terms of the release energy's size, relative
// to it.
constexpr double kEnergyRoundOff = 1e-12;

}  // namespace talus::testing
