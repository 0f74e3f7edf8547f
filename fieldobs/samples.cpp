#include "fieldobs/samples.hpp"

namespace talus::fieldobs {

EnsembleSamples::EnsembleSamples(const ensemble::ReleaseSpec& release) : release_(release) {
  for (long k = 0; k < release.release_count(); ++k)
    run_index_[release.ReleaseName(static_cast<int>(k))] = static_cast<int>(k);
}

void EnsembleSamples::OnRock(const ensemble::RockOutcome& outcome) {
  Rock rock;
  rock.release = outcome.release;
  rock.runout_m = outcome.result.runout_m;
  rock.end_m = outcome.result.final_state.position_m.head<2>();
  rock.start_m = outcome.start.position_m.head<2>();
  if (!outcome.episodes.empty()) {
    const ContactEpisode& e = outcome.episodes.front();
    const double in2 = e.velocity_in_m_s.squaredNorm();
    rock.speed_out_m_s = e.velocity_out_m_s.norm();
    if (in2 > 0) rock.energy_ratio = e.velocity_out_m_s.squaredNorm() / in2;
    rock.angular_speed_out_rad_s = e.angular_velocity_out_rad_s.norm();
    rock.duration_s = e.duration_s();
    for (const ContactEpisode& loaded : outcome.episodes)
      if (loaded.loaded) {
        rock.scar_m = loaded.max_scar_m;
        break;
      }
  }
  rocks_.push_back(rock);
}

bool EnsembleSamples::HasRun(const std::string& run) const {
  return run.empty() || run_index_.count(run) > 0;
}

template <class F>
void EnsembleSamples::ForRun(const std::string& run, F&& f) const {
  if (run.empty()) {
    for (const Rock& r : rocks_) f(r);
    return;
  }
  const auto it = run_index_.find(run);
  if (it == run_index_.end()) return;
  // Rocks of one release are consecutive (ReleaseSpec::ReleaseOf).
  const long first = static_cast<long>(it->second) * release_.rocks_per_release;
  for (long k = first; k < first + release_.rocks_per_release && k < rocks(); ++k)
    f(rocks_[static_cast<std::size_t>(k)]);
}

std::vector<double> EnsembleSamples::Values(Quantity quantity, const std::string& run) const {
  std::vector<double> out;
  ForRun(run, [&](const Rock& r) {
    std::optional<double> v;
    switch (quantity) {
      case Quantity::kRunout:
        v = r.runout_m;
        break;
      case Quantity::kImpactSpeedOut:
        v = r.speed_out_m_s;
        break;
      case Quantity::kImpactEnergyRatio:
        v = r.energy_ratio;
        break;
      case Quantity::kImpactAngularSpeedOut:
        v = r.angular_speed_out_rad_s;
        break;
      case Quantity::kImpactDuration:
        v = r.duration_s;
        break;
      case Quantity::kScarLength:
        v = r.scar_m;
        break;
    }
    if (v) out.push_back(*v);
  });
  return out;
}

std::vector<Eigen::Vector2d> EnsembleSamples::EndPositions(const std::string& run) const {
  std::vector<Eigen::Vector2d> out;
  ForRun(run, [&](const Rock& r) { out.push_back(r.end_m); });
  return out;
}

std::optional<Eigen::Vector2d> EnsembleSamples::StartOf(const std::string& run) const {
  if (run.empty()) return std::nullopt;
  std::optional<Eigen::Vector2d> start;
  ForRun(run, [&](const Rock& r) {
    if (!start) start = r.start_m;
  });
  return start;
}

}  // namespace talus::fieldobs
