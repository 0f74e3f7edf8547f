#pragma once
// The simulated counterparts of observations: what each rock of an ensemble gives for every
// observable quantity, kept per run. It is a sink of the ensemble runner, so it sees the rocks in
// rock order and its contents do not depend on the number of threads. About 100 bytes per rock.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "ensemble/runner.hpp"
#include "fieldobs/observations.hpp"

namespace talus::fieldobs {

// A recorder (EnsembleOptions::extra_recorders) of each rock's statistics over the first
// window_s[release] seconds of its run (0: none): largest speed, mean angular speed, largest jump
// height (centre of mass above the terrain along its normal), the start state included. They are
// the simulated counterparts of observed trajectory segments; EnsembleSamples reads them.
ensemble::RecorderFactory SegmentRecorders(const Terrain& terrain, std::vector<double> window_s);

// The windows SegmentRecorders needs for the segment observations of `observations`, per release
// of `release` (the longest window of a run's observations).
std::vector<double> SegmentWindows(const ObservationSet& observations,
                                   const ensemble::ReleaseSpec& release);

// A recorder of each rock's passage through `zones`: for a line, whether the centre of mass crossed
// it and the speed, angular speed and jump height at the first crossing (interpolated within the
// step); for a polygon, whether the centre of mass entered it and the largest values inside.
ensemble::RecorderFactory ZoneRecorders(std::vector<Zone> zones);

// Adds to options.extra_recorders the recorders `observations` need for EnsembleSamples to give
// their values: SegmentRecorders for trajectory segments, ZoneRecorders for zones; none when they
// need neither. Validation and calibration runs both call it, so an observation that validates
// can be calibrated against. `terrain` must outlive the run.
void AddRecordersFor(const ObservationSet& observations, const Terrain& terrain,
                     const ensemble::ReleaseSpec& release, ensemble::EnsembleOptions& options);

class EnsembleSamples : public ensemble::RockSink {
 public:
  // `release` names the runs; it must outlive this object. The runner must record episodes
  // (EnsembleOptions::episodes) for the impact and scar quantities to have values.
  explicit EnsembleSamples(const ensemble::ReleaseSpec& release);
  void OnRock(const ensemble::RockOutcome& outcome) override;

  // True when `run` is a run (or release) of the ensemble; "" (the whole scene) always is.
  bool HasRun(const std::string& run) const;
  // The values of `quantity` over the rocks of `run` ("": every rock), in rock order. Rocks that
  // do not give the quantity (no contact episode for an impact quantity) are left out.
  // Zone quantities take the zone's index.
  std::vector<double> Values(Quantity quantity, const std::string& run, int zone = -1) const;
  // End positions (map coordinates) of the rocks of `run`, in rock order: where each came to rest,
  // was stopped or cut off, and for a rock that left the DEM, where it left.
  std::vector<Eigen::Vector2d> EndPositions(const std::string& run) const;
  // The same, of only the rocks that left the DEM (left_dem) or only the others.
  std::vector<Eigen::Vector2d> EndPositions(const std::string& run, bool left_dem) const;
  // Start position (horizontal) of `run`'s first rock, or nullopt for "" or an unknown run.
  std::optional<Eigen::Vector2d> StartOf(const std::string& run) const;
  long rocks() const { return static_cast<long>(rocks_.size()); }

  // The rocks received so far as bytes (exact: every double bit for bit), and the rocks of such
  // bytes appended after those here: samples of rocks [a, b) and [b, c) of one release, appended
  // in that order, equal the samples of [a, c). For dividing an ensemble among processes (MPI).
  // Append throws std::runtime_error when the bytes are not such a record.
  std::string Serialize() const;
  void Append(const std::string& bytes);

 private:
  struct Rock {
    int release = 0;
    double runout_m = 0;
    Eigen::Vector2d end_m = Eigen::Vector2d::Zero();
    Eigen::Vector2d start_m = Eigen::Vector2d::Zero();
    bool left_dem = false;  // ended as EndReason::kLeftDomain: end_m is where it left
    // From the first contact episode (and the first loaded one, for the scar).
    std::optional<double> speed_out_m_s, energy_ratio, angular_speed_out_rad_s, duration_s, scar_m,
        scar_depth_m;
    // Over the run's observed segment (SegmentRecorders).
    std::optional<double> segment_max_speed_m_s, segment_mean_angular_speed_rad_s,
        segment_max_jump_m;
    std::vector<double>
        zones;  // per zone: passed, speed, angular speed, jump height (ZoneRecorders)
  };
  template <class F>
  void ForRun(const std::string& run, F&& f) const;

  const ensemble::ReleaseSpec& release_;
  std::unordered_map<std::string, int> run_index_;
  std::vector<Rock> rocks_;
};

}  // namespace talus::fieldobs
