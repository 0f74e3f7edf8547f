#pragma once
// Contact episodes: the stretches of ground contact along a rock's path, the simulated
// counterpart of an observed impact or scar. Recorded by an observer, only when asked for.

#include <Eigen/Core>
#include <vector>

#include "solver/simulate.hpp"

namespace talus {

// One stretch of ground contact (a closed contact, or part of the hull in a soil layer). It begins with the first step that closes a contact after a
// flight (or at release, when the rock starts on the ground) and ends with the last contact step
// before a flight of at least EpisodeOptions::min_flight_s (or at the rock's end). "In" is the
// state just before the first contact step, "out" the state after the last one. World frame, SI.
struct ContactEpisode {
  double start_time_s = 0, end_time_s = 0;
  Eigen::Vector3d start_position_m = Eigen::Vector3d::Zero();  // centre of mass, "in" state
  Eigen::Vector3d end_position_m = Eigen::Vector3d::Zero();    // centre of mass, "out" state
  Eigen::Vector3d velocity_in_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d velocity_out_m_s = Eigen::Vector3d::Zero();
  Eigen::Vector3d angular_velocity_in_rad_s = Eigen::Vector3d::Zero();   // world frame
  Eigen::Vector3d angular_velocity_out_rad_s = Eigen::Vector3d::Zero();  // world frame
  double max_scar_m = 0;     // longest scar reached in the episode
  // Scarring soil (Lu et al. 2019): the deepest the hull reached below the terrain's tangent plane
  // (along its normal) in the episode, m; 0 on hard ground. The simulated scar depth.
  double max_scar_depth_m = 0;
  // Scarring soil: the scar's extent seen at the surface, along the horizontal direction of the
  // incoming velocity: from the rearmost to the foremost point of the hull's part below the
  // surface over the episode (Lu et al. 2019's scar length), m; 0 on hard ground.
  double scar_extent_m = 0;
  double path_length_m = 0;  // horizontal path of the centre of mass during the episode
  int ground = -1;           // ground index under the centre of mass at the first contact step
  long contact_steps = 0;    // steps with a closed contact
  bool loaded = false;       // a contact carried load (the scar grew)

  double duration_s() const { return end_time_s - start_time_s; }
};

struct EpisodeOptions {
  // Flights shorter than this (s) do not end an episode: a tumbling block's micro-hops between
  // edges belong to one impact. 0.05 s is a hop of about 3 mm at g.
  double min_flight_s = 0.05;
};

// Records the episodes of one rock at a time; reuse it across rocks (Begin clears it).
class EpisodeRecorder : public StepObserver {
 public:
  explicit EpisodeRecorder(const Terrain& terrain, EpisodeOptions options = {})
      : terrain_(terrain), options_(options) {}
  void Begin(const RockState& start);
  void OnStep(const RockState& state, const StepReport& step, const TerrainSample& ground) override;
  // Closes an open episode at the last state and hands the episodes over.
  std::vector<ContactEpisode> Finish();

 private:
  void Close();

  const Terrain& terrain_;
  EpisodeOptions options_;
  std::vector<ContactEpisode> episodes_;
  ContactEpisode current_;
  bool open_ = false;       // an episode has begun and not been closed
  double flight_s_ = 0;     // time since the last contact step of the open episode
  double hop_path_m_ = 0;   // horizontal path since then
  RockState previous_;      // state before the current step
  RockState last_contact_;  // state after the open episode's last contact step
  // Soil: the rear- and foremost projections of the submerged part on the episode's direction.
  double scar_rear_m_ = 0, scar_front_m_ = 0;
  bool scarred_ = false;
};

}  // namespace talus
