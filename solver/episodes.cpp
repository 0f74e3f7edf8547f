#include "solver/episodes.hpp"

#include <algorithm>

namespace talus {

void EpisodeRecorder::Begin(const RockState& start) {
  episodes_.clear();
  open_ = false;
  flight_s_ = 0;
  previous_ = start;
}

void EpisodeRecorder::OnStep(const RockState& state, const StepReport& step,
                             const TerrainSample& /*ground*/) {
  const double dt = state.time_s - previous_.time_s;
  if (step.contacts > 0 || step.in_soil) {
    if (!open_) {
      current_ = ContactEpisode{};
      current_.start_time_s = previous_.time_s;
      current_.start_position_m = previous_.position_m;
      current_.velocity_in_m_s = previous_.velocity_m_s;
      current_.angular_velocity_in_rad_s = previous_.orientation * previous_.angular_velocity_rad_s;
      current_.ground = terrain_.GroundAt(state.position_m.x(), state.position_m.y());
      open_ = true;
      hop_path_m_ = 0;
      scarred_ = false;
    }
    if (step.in_soil) {
      const Eigen::Vector2d v = current_.velocity_in_m_s.head<2>();
      const Eigen::Vector2d d = v.norm() > 0 ? Eigen::Vector2d(v.normalized()) : Eigen::Vector2d::UnitX();
      const double rear = d.dot(step.soil_rear_m.head<2>());
      const double front = d.dot(step.soil_front_m.head<2>());
      scar_rear_m_ = scarred_ ? std::min(scar_rear_m_, rear) : rear;
      scar_front_m_ = scarred_ ? std::max(scar_front_m_, front) : front;
      scarred_ = true;
      current_.scar_extent_m = scar_front_m_ - scar_rear_m_;
    }
    // A short hop belongs to the episode: its path counts once contact resumes.
    current_.path_length_m +=
        hop_path_m_ + (state.position_m - previous_.position_m).head<2>().norm();
    hop_path_m_ = 0;
    current_.max_scar_m = std::max(current_.max_scar_m, state.scar_m);
    current_.max_scar_depth_m = std::max(current_.max_scar_depth_m, step.soil_penetration_m);
    ++current_.contact_steps;
    current_.loaded = current_.loaded || step.loaded;
    last_contact_ = state;
    flight_s_ = 0;
  } else {
    if (open_) {
      flight_s_ += dt;
      hop_path_m_ += (state.position_m - previous_.position_m).head<2>().norm();
      if (flight_s_ >= options_.min_flight_s - 1e-12) Close();
    }
  }
  previous_ = state;
}

void EpisodeRecorder::Close() {
  if (!open_) return;
  const RockState& out = last_contact_;
  current_.end_time_s = out.time_s;
  current_.end_position_m = out.position_m;
  current_.velocity_out_m_s = out.velocity_m_s;
  current_.angular_velocity_out_rad_s = out.orientation * out.angular_velocity_rad_s;
  episodes_.push_back(current_);
  open_ = false;
}

std::vector<ContactEpisode> EpisodeRecorder::Finish() {
  Close();
  return std::move(episodes_);
}

}  // namespace talus
