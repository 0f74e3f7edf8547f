#pragma once
// Forest: explicit trees whose stems the rocks hit (docs/model.md, "Forest"). Each stem is a
// vertical cylinder of diameter DBH standing on the terrain up to a stated height. After every
// step a rock whose hull overlaps a stem (in plan view, below the stem's top) and moves into it
// gets one impulsive contact with it: fully plastic along the horizontal normal, Coulomb friction
// on the stem's surface. The stem absorbs what that impact dissipates up to its breaking energy
// E_max(DBH); an impact that would take more breaks it, the rock loses the stem's remaining
// energy (its velocities scaled, directions kept, as for barriers) and that stem is gone for the
// rest of this rock, not for the other rocks. A scene without trees does no forest work.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "solver/polyhedron.hpp"
#include "solver/state.hpp"
#include "solver/terrain.hpp"

namespace talus {

// A breaking-energy law: E_max = factor * (coefficient * DBH[cm]^exponent) (J); ForestModel::Law
// gives a stem's.
struct BreakingLaw {
  double factor = 1;
  double coefficient_J = 0;
  double exponent = 0;

  double Energy_J(double dbh_m) const;
};

// A tree species whose stems break by a law of their own ([forest.species.<name>]; docs/model.md
// "Forest"): the forest's law times energy_factor, or (factor 1) its own coefficient and/or
// exponent, the other taken from the forest's. The user states it, from the source they trust.
struct TreeSpecies {
  std::string name;                            // non-empty, no control characters
  double energy_factor = 1;                    // > 0; 1 when the species has a law of its own
  std::optional<double> energy_coefficient_J;  // J, > 0; absent: the forest's
  std::optional<double> energy_exponent;       // > 0; absent: the forest's
  // Checks the fields; *why names the field (as the scene key), the value and the bound.
  bool IsValid(std::string* why) const;
};

// The mechanics shared by all stems of a scene.
struct ForestModel {
  double stem_height_m = 10;  // stems reach this high above the terrain at their axis (m), > 0
  double friction = 0.5;      // Coulomb coefficient between rock and stem, >= 0
  // Breaking energy E_max = coefficient * DBH[cm]^exponent (J) of stems without a species;
  // defaults: Dorren & Berger 2006 as docs/model.md "Forest" states (and what of it could be
  // checked).
  double energy_coefficient_J = 38.7;
  double energy_exponent = 2.31;
  // The species a stem or stand may name (Stem::species indexes it); empty: one law for all.
  std::vector<TreeSpecies> species;

  // The law of species k (an index into `species`; -1: none, the forest's own law, factor 1).
  BreakingLaw Law(int k = -1) const;
  double BreakingEnergy_J(double dbh_m, int k = -1) const { return Law(k).Energy_J(dbh_m); }
  // Checks the fields and every species; *why names the field, the value and the bound.
  bool IsValid(std::string* why) const;
};

// One tree.
struct Stem {
  Eigen::Vector2d position_m = Eigen::Vector2d::Zero();  // axis, map coordinates (m)
  double dbh_m = 0;                                      // stem diameter (m), > 0
  double ground_m = 0;  // terrain height at the axis (m): the stem's foot
  int species = -1;     // index into ForestModel::species; -1: none (the forest's law)
};

// The trees of a scene and a uniform grid of them for cheap look-ups.
class Forest {
 public:
  Forest() = default;
  // Requires model.IsValid() and finite stems of positive DBH, each of a species of the model or
  // none.
  Forest(std::vector<Stem> stems, const ForestModel& model);

  bool empty() const { return stems_.empty(); }
  const std::vector<Stem>& stems() const { return stems_; }
  const ForestModel& model() const { return model_; }
  double capacity_J(int stem) const { return capacity_J_[static_cast<std::size_t>(stem)]; }
  double max_radius_m() const { return max_radius_m_; }
  bool IsValid(std::string* why) const;

  // Calls f(stem index) for every stem whose axis may lie within `reach` (m) of `centre` in plan
  // view (a superset: those in the grid cells the square of half-width reach touches), in
  // ascending cell order, each once.
  template <class F>
  void ForEachNear(const Eigen::Vector2d& centre, double reach, F&& f) const {
    if (stems_.empty()) return;
    const double u0 = (centre.x() - reach - x0_m_) / cell_m_,
                 u1 = (centre.x() + reach - x0_m_) / cell_m_;
    const double v0 = (centre.y() - reach - y0_m_) / cell_m_,
                 v1 = (centre.y() + reach - y0_m_) / cell_m_;
    if (!(u1 >= 0 && u0 < nx_ && v1 >= 0 && v0 < ny_)) return;
    const int i0 = u0 < 0 ? 0 : static_cast<int>(u0),
              i1 = u1 >= nx_ ? nx_ - 1 : static_cast<int>(u1);
    const int j0 = v0 < 0 ? 0 : static_cast<int>(v0),
              j1 = v1 >= ny_ ? ny_ - 1 : static_cast<int>(v1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) {
        const std::size_t cell = static_cast<std::size_t>(j) * nx_ + i;
        for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k)
          f(order_[static_cast<std::size_t>(k)]);
      }
  }

  static constexpr double kCell_m = 5;  // grid cell of the look-up (m)

 private:
  std::vector<Stem> stems_;
  ForestModel model_;
  std::vector<double> capacity_J_;  // per stem, model_.BreakingEnergy_J(dbh, species)
  double max_radius_m_ = 0;
  double x0_m_ = 0, y0_m_ = 0, cell_m_ = kCell_m;
  int nx_ = 0, ny_ = 0;
  std::vector<int> cell_start_;  // nx * ny + 1 offsets into order_
  std::vector<int> order_;       // stem indices sorted by cell
};

// Forest as a drag layer (`[forest] model = "drag"`; docs/model.md, "Forest as a drag layer"):
// stands of stem density n (stems/m^2) and mean DBH D on a grid of their own, independent of the
// ground categories. A rock whose centre of mass is in a stand and at most the stand's height
// above the terrain meets, per metre of horizontal travel, lambda = n (D + w) stems on average (w
// the rock's width: the diameter of the sphere of its volume). Each hit takes
// dE = min(E_max(D), eta E) of its kinetic energy E (translational + rotational): eta = 2/3, the
// mean share a fully plastic impact on a fixed round stem takes from a round rock over a uniform
// impact parameter, and at most the stem's breaking energy (it breaks then). Spread over the
// path, dE/dt = -lambda |v_h| dE: as a drag on v and Omega with one rate
//   c = lambda |v_h| min(E_max, eta E) / (2 E)   (1/s),
// evaluated at the step's beginning and integrated by the drag layer's exact form
// (solver/step.cpp).
struct DragStand {
  double stems_per_m2 = 0;       // n, > 0
  double dbh_m = 0;              // D, > 0
  double breaking_energy_J = 0;  // E_max(D) of the ForestModel and the stand's species, > 0
};

class ForestDrag {
 public:
  static constexpr double kPlasticShare = 2.0 / 3.0;  // eta

  ForestDrag() = default;
  // cells: one per node of `grid` (cells centred on the nodes, as GroundGrid), row after row along
  // y, each an index into `stands` or -1 (no forest); height_m: the layer's height above the
  // terrain (the stems' height), > 0.
  ForestDrag(GridGeometry grid, std::vector<int> cells, std::vector<DragStand> stands,
             double height_m);

  bool empty() const { return stands_.empty(); }
  double height_m() const { return height_m_; }
  const GridGeometry& grid() const { return grid_; }
  const std::vector<int>& cells() const { return cells_; }
  const std::vector<DragStand>& stands() const { return stands_; }
  // The stand of the cell holding (x, y), or null.
  const DragStand* StandAt(double x_m, double y_m) const;
  bool IsValid(std::string* why) const;

  // c (1/s) of the header for a rock of this shape with the velocities of `begin` in `stand`.
  static double Rate_1_s(const DragStand& stand, const RockShape& rock, const RockState& begin);
  // w: the diameter of the sphere of the rock's volume (m).
  static double RockWidth_m(const RockShape& rock);

 private:
  GridGeometry grid_;
  std::vector<int> cells_;
  std::vector<DragStand> stands_;
  double height_m_ = 0;
};

// The rate (1/s) of the forest's drag on the rock whose centre of mass is at `centre`, above_m
// over the terrain, with the velocities of `begin`; 0 outside every stand or above the layer.
double ForestDragRate_1_s(const ForestDrag& drag, const RockShape& rock, const RockState& begin,
                          const Eigen::Vector3d& centre, double above_m);

// What a rock did to one stem over its run (one record per stem it touched).
struct StemHit {
  int stem = 0;                                      // index into Forest::stems()
  Eigen::Vector2d stem_m = Eigen::Vector2d::Zero();  // the stem's axis (map coordinates, m)
  int impacts = 0;  // contact episodes (a rock leaning on a stem for many steps is one)
  double t_s = 0;   // time of the first impact
  Eigen::Vector3d position_m = Eigen::Vector3d::Zero();  // centre of mass at the first impact
  double energy_J = 0;    // kinetic energy just before the first impact
  double absorbed_J = 0;  // energy the stem took from this rock, <= its breaking energy
  bool broken = false;    // this rock broke it (it is gone for the rest of the rock's run)
  bool touching = false;  // in contact in the last step (bookkeeping of episodes)
};

// The stems the rock at *state (at a step's end) overlaps and moves into, each met as the header
// says. Stems broken earlier by this rock (in `hits`) are gone. Updates *state's velocities and
// `hits`; returns true when a stem changed the rock's velocity.
bool MeetStems(const Forest& forest, const RockShape& rock, RockState* state,
               std::vector<StemHit>* hits);

// The impulsive plastic, frictional contact of a rock with a fixed point: the percussion P
// (world) that the point `lever_m` (world, from the centre of mass) of the rock gets, in the
// contact frame `directions` (world columns n, t1, t2; n the contact normal, pointing into the
// rock), such that the point's normal velocity ends at 0 (from < 0) and its tangential percussion
// lies in Coulomb's disk mu P_N (sticking when it can). Never adds kinetic energy: when the local
// iteration does not meet the laws to round-off it falls back to the frictionless plastic impulse.
// Applies P to `velocity` and `omega` (body frame). Returns the percussion (world).
Eigen::Vector3d PlasticFrictionalImpulse(const RockShape& rock, const Eigen::Matrix3d& rotation,
                                         const Eigen::Vector3d& lever_m,
                                         const Eigen::Matrix3d& directions, double mu,
                                         Eigen::Vector3d* velocity, Eigen::Vector3d* omega);

}  // namespace talus
