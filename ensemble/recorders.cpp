#include "ensemble/recorders.hpp"

#include <optional>
#include <utility>

namespace talus::ensemble {
namespace {

class TrajectoryRecorder : public RockRecorder {
 public:
  TrajectoryRecorder(double interval_s, double dt_s, std::function<bool(long)> wanted)
      : interval_s_(interval_s), dt_s_(dt_s), wanted_(std::move(wanted)) {}

  void Begin(const RockOutcome& outcome) override {
    active_ = wanted_(outcome.rock);
    samples_.clear();
    if (!active_) return;
    shape_ = outcome.shape.get();
    Record(outcome.start, false);
    next_t_ = outcome.start.time_s + interval_s_;
    last_.reset();
    last_recorded_ = true;
  }
  void OnStep(const RockState& state, const StepReport& step, const TerrainSample&) override {
    if (!active_) return;
    last_ = state;
    last_contact_ = step.contacts > 0;
    if (state.time_s >= next_t_ - 0.5 * dt_s_) {
      Record(state, last_contact_);
      next_t_ += interval_s_;
      last_recorded_ = true;
    } else {
      last_recorded_ = false;
    }
  }
  void Finish(RockOutcome& outcome) override {
    if (!active_) return;
    if (!last_recorded_ && last_) Record(*last_, last_contact_);
    outcome.trajectory = std::move(samples_);
    samples_ = {};
  }

 private:
  void Record(const RockState& s, bool contact) {
    TrajectorySample sample;
    sample.t_s = s.time_s;
    sample.position_m = s.position_m;
    sample.orientation = shape_->ShapeOrientation(s.orientation);
    sample.velocity_m_s = s.velocity_m_s;
    sample.angular_velocity_rad_s = s.orientation * s.angular_velocity_rad_s;
    sample.contact = contact;
    sample.scar_m = s.scar_m;
    samples_.push_back(sample);
  }

  double interval_s_, dt_s_;
  std::function<bool(long)> wanted_;
  bool active_ = false;
  const RockShape* shape_ = nullptr;
  double next_t_ = 0;
  std::vector<TrajectorySample> samples_;
  std::optional<RockState> last_;
  bool last_contact_ = false;
  bool last_recorded_ = true;
};

class EpisodeRecording : public RockRecorder {
 public:
  EpisodeRecording(const Terrain& terrain, const EpisodeOptions& options)
      : recorder_(terrain, options) {}
  void Begin(const RockOutcome& outcome) override { recorder_.Begin(outcome.start); }
  void OnStep(const RockState& state, const StepReport& step,
              const TerrainSample& ground) override {
    recorder_.OnStep(state, step, ground);
  }
  void Finish(RockOutcome& outcome) override { outcome.episodes = recorder_.Finish(); }

 private:
  EpisodeRecorder recorder_;
};

}  // namespace

std::unique_ptr<RockRecorder> MakeTrajectoryRecorder(double interval_s, double dt_s,
                                                     std::function<bool(long rock)> wanted) {
  return std::make_unique<TrajectoryRecorder>(interval_s, dt_s, std::move(wanted));
}

std::unique_ptr<RockRecorder> MakeEpisodeRecorder(const Terrain& terrain,
                                                  const EpisodeOptions& options) {
  return std::make_unique<EpisodeRecording>(terrain, options);
}

}  // namespace talus::ensemble
