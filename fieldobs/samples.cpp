#include "fieldobs/samples.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>

#include "ensemble/evaluation_lines.hpp"

namespace talus::fieldobs {

EnsembleSamples::EnsembleSamples(const ensemble::ReleaseSpec& release) : release_(release) {
  for (long k = 0; k < release.release_count(); ++k)
    run_index_[release.ReleaseName(static_cast<int>(k))] = static_cast<int>(k);
}

namespace {

class SegmentRecorder : public ensemble::RockRecorder {
 public:
  SegmentRecorder(const Terrain& terrain, const std::vector<double>& window_s)
      : terrain_(terrain), window_s_(window_s) {}
  void Begin(const ensemble::RockOutcome& outcome) override {
    const auto r = static_cast<std::size_t>(outcome.release);
    window_ = r < window_s_.size() ? window_s_[r] : 0.0;
    if (window_ <= 0) return;
    t0_ = outcome.start.time_s;
    last_t_ = t0_;
    max_speed_ = 0;
    omega_sum_ = 0;
    samples_ = 0;
    max_jump_ = -1e300;
    TerrainSample ground;
    const Eigen::Vector3d& p = outcome.start.position_m;
    Add(outcome.start, terrain_.Sample(p.x(), p.y(), &ground) ? &ground : nullptr);
  }
  void OnStep(const RockState& state, const StepReport&, const TerrainSample& ground) override {
    if (window_ <= 0) return;
    const double dt = state.time_s - last_t_;
    last_t_ = state.time_s;
    if (state.time_s - t0_ <= window_ + 0.5 * dt) Add(state, &ground);
  }
  void Finish(ensemble::RockOutcome& outcome) override {
    if (window_ <= 0) return;
    outcome.extra["segment"] = {max_speed_, omega_sum_ / double(samples_), max_jump_};
  }

 private:
  void Add(const RockState& s, const TerrainSample* ground) {
    max_speed_ = std::max(max_speed_, s.velocity_m_s.norm());
    omega_sum_ += s.angular_velocity_rad_s.norm();
    ++samples_;
    if (ground)
      max_jump_ = std::max(max_jump_, (s.position_m.z() - ground->height_m) * ground->normal.z());
  }

  const Terrain& terrain_;
  const std::vector<double>& window_s_;
  double window_ = 0, t0_ = 0, last_t_ = 0;
  double max_speed_ = 0, omega_sum_ = 0, max_jump_ = 0;
  long samples_ = 0;
};

class ZoneRecorder : public ensemble::RockRecorder {
 public:
  explicit ZoneRecorder(std::shared_ptr<const std::vector<Zone>> zones)
      : zones_(std::move(zones)) {}
  void Begin(const ensemble::RockOutcome& outcome) override {
    const double nan = std::numeric_limits<double>::quiet_NaN();
    values_.assign(4 * zones_->size(), nan);
    for (std::size_t z = 0; z < zones_->size(); ++z) values_[4 * z] = 0;
    previous_ = outcome.start;
    previous_jump_ = nan;  // unknown until the first step's terrain sample
  }
  void OnStep(const RockState& state, const StepReport&, const TerrainSample& ground) override {
    const double jump = (state.position_m.z() - ground.height_m) * ground.normal.z();
    const Eigen::Vector2d a = previous_.position_m.head<2>(), b = state.position_m.head<2>();
    const double v0 = previous_.velocity_m_s.norm(), v1 = state.velocity_m_s.norm();
    const double w0 = previous_.angular_velocity_rad_s.norm(),
                 w1 = state.angular_velocity_rad_s.norm();
    const double j0 = std::isnan(previous_jump_) ? jump : previous_jump_;
    for (std::size_t z = 0; z < zones_->size(); ++z) {
      const Zone& zone = (*zones_)[z];
      double* v = &values_[4 * z];
      if (zone.polygon) {
        if (!ensemble::InsidePolygon({zone.points}, b)) continue;
        v[0] = 1;
        v[1] = std::isnan(v[1]) ? v1 : std::max(v[1], v1);
        v[2] = std::isnan(v[2]) ? w1 : std::max(v[2], w1);
        v[3] = std::isnan(v[3]) ? jump : std::max(v[3], jump);
        continue;
      }
      if (v[0] == 1) continue;  // the first crossing counts
      const double t = ensemble::CrossPolyline(a, b, zone.points).fraction;
      if (t < 0) continue;
      v[0] = 1;
      v[1] = v0 + t * (v1 - v0);
      v[2] = w0 + t * (w1 - w0);
      v[3] = j0 + t * (jump - j0);
    }
    previous_ = state;
    previous_jump_ = jump;
  }
  void Finish(ensemble::RockOutcome& outcome) override { outcome.extra["zones"] = values_; }

 private:
  std::shared_ptr<const std::vector<Zone>> zones_;
  std::vector<double> values_;
  RockState previous_;
  double previous_jump_ = 0;
};

bool IsSegment(Quantity q) {
  return q == Quantity::kSegmentMaxSpeed || q == Quantity::kSegmentMeanAngularSpeed ||
         q == Quantity::kSegmentMaxJumpHeight;
}

}  // namespace

ensemble::RecorderFactory SegmentRecorders(const Terrain& terrain, std::vector<double> window_s) {
  auto windows = std::make_shared<const std::vector<double>>(std::move(window_s));
  return [&terrain, windows]() -> std::unique_ptr<ensemble::RockRecorder> {
    // The recorder refers to the shared windows, which the factory keeps alive.
    struct Owning : SegmentRecorder {
      Owning(const Terrain& t, std::shared_ptr<const std::vector<double>> w)
          : SegmentRecorder(t, *w), keep(std::move(w)) {}
      std::shared_ptr<const std::vector<double>> keep;
    };
    return std::make_unique<Owning>(terrain, windows);
  };
}

ensemble::RecorderFactory ZoneRecorders(std::vector<Zone> zones) {
  auto shared = std::make_shared<const std::vector<Zone>>(std::move(zones));
  return [shared]() -> std::unique_ptr<ensemble::RockRecorder> {
    return std::make_unique<ZoneRecorder>(shared);
  };
}

void AddRecordersFor(const ObservationSet& observations, const Terrain& terrain,
                     const ensemble::ReleaseSpec& release, ensemble::EnsembleOptions& options) {
  const std::vector<double> windows = SegmentWindows(observations, release);
  if (std::any_of(windows.begin(), windows.end(), [](double w) { return w > 0; }))
    options.extra_recorders.push_back(SegmentRecorders(terrain, windows));
  if (!observations.zones.empty())
    options.extra_recorders.push_back(ZoneRecorders(observations.zones));
}

std::vector<double> SegmentWindows(const ObservationSet& observations,
                                   const ensemble::ReleaseSpec& release) {
  std::vector<double> windows(static_cast<std::size_t>(release.release_count()), 0.0);
  for (const ScalarObservation& o : observations.scalars) {
    if (!IsSegment(o.quantity)) continue;
    for (long r = 0; r < release.release_count(); ++r)
      if (o.run.empty() || release.ReleaseName(static_cast<int>(r)) == o.run)
        windows[static_cast<std::size_t>(r)] =
            std::max(windows[static_cast<std::size_t>(r)], o.window_s);
  }
  return windows;
}

void EnsembleSamples::OnRock(const ensemble::RockOutcome& outcome) {
  Rock rock;
  rock.release = outcome.release;
  rock.runout_m = outcome.result.runout_m;
  rock.end_m = outcome.result.final_state.position_m.head<2>();
  rock.start_m = outcome.start.position_m.head<2>();
  rock.left_dem = outcome.result.end == EndReason::kLeftDomain;
  if (!outcome.episodes.empty()) {
    const ContactEpisode& e = outcome.episodes.front();
    const double in2 = e.velocity_in_m_s.squaredNorm();
    rock.speed_out_m_s = e.velocity_out_m_s.norm();
    if (in2 > 0) rock.energy_ratio = e.velocity_out_m_s.squaredNorm() / in2;
    rock.angular_speed_out_rad_s = e.angular_velocity_out_rad_s.norm();
    rock.duration_s = e.duration_s();
    rock.scar_depth_m = e.max_scar_depth_m;
    for (const ContactEpisode& loaded : outcome.episodes)
      if (loaded.loaded) {
        rock.scar_m = loaded.max_scar_m;
        break;
      }
  }
  if (const auto it = outcome.extra.find("segment"); it != outcome.extra.end()) {
    const std::vector<double>& s = it->second;
    rock.segment_max_speed_m_s = s[0];
    rock.segment_mean_angular_speed_rad_s = s[1];
    if (s[2] > -1e299) rock.segment_max_jump_m = s[2];
  }
  if (const auto it = outcome.extra.find("zones"); it != outcome.extra.end())
    rock.zones = it->second;
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
  const long first = release_.FirstRockOf(static_cast<int>(it->second));
  const long end = first + release_.RocksOf(static_cast<int>(it->second));
  for (long k = first; k < end && k < rocks(); ++k) f(rocks_[static_cast<std::size_t>(k)]);
}

std::vector<double> EnsembleSamples::Values(Quantity quantity, const std::string& run,
                                            int zone) const {
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
      case Quantity::kImpactScarDepth:
        v = r.scar_depth_m;
        break;
      case Quantity::kSegmentMaxSpeed:
        v = r.segment_max_speed_m_s;
        break;
      case Quantity::kSegmentMeanAngularSpeed:
        v = r.segment_mean_angular_speed_rad_s;
        break;
      case Quantity::kSegmentMaxJumpHeight:
        v = r.segment_max_jump_m;
        break;
      case Quantity::kZonePassed:
      case Quantity::kZoneSpeed:
      case Quantity::kZoneAngularSpeed:
      case Quantity::kZoneJumpHeight: {
        const std::size_t at = 4 * static_cast<std::size_t>(zone);
        if (zone < 0 || at + 3 >= r.zones.size() + 0 || r.zones.size() < at + 4) break;
        const int offset = quantity == Quantity::kZonePassed         ? 0
                           : quantity == Quantity::kZoneSpeed        ? 1
                           : quantity == Quantity::kZoneAngularSpeed ? 2
                                                                     : 3;
        if (!std::isnan(r.zones[at + offset])) v = r.zones[at + offset];
        break;
      }
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

std::vector<Eigen::Vector2d> EnsembleSamples::EndPositions(const std::string& run,
                                                           bool left_dem) const {
  std::vector<Eigen::Vector2d> out;
  ForRun(run, [&](const Rock& r) {
    if (r.left_dem == left_dem) out.push_back(r.end_m);
  });
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

namespace {

template <class T>
void Put(std::string& out, const T& value) {
  out.append(reinterpret_cast<const char*>(&value), sizeof value);
}

void PutOptional(std::string& out, const std::optional<double>& value) {
  Put<std::uint8_t>(out, value ? 1 : 0);
  if (value) Put(out, *value);
}

class Reader {
 public:
  explicit Reader(const std::string& bytes) : bytes_(bytes) {}
  template <class T>
  T Get() {
    if (bytes_.size() - at_ < sizeof(T))
      throw std::runtime_error("ensemble samples: the record ends early");
    T value;
    std::memcpy(&value, bytes_.data() + at_, sizeof value);
    at_ += sizeof value;
    return value;
  }
  std::optional<double> GetOptional() {
    if (Get<std::uint8_t>() == 0) return std::nullopt;
    return Get<double>();
  }
  bool done() const { return at_ == bytes_.size(); }

 private:
  const std::string& bytes_;
  std::size_t at_ = 0;
};

}  // namespace

std::string EnsembleSamples::Serialize() const {
  std::string out;
  Put<std::uint64_t>(out, rocks_.size());
  for (const Rock& r : rocks_) {
    Put<std::int32_t>(out, r.release);
    Put(out, r.runout_m);
    for (double v : {r.end_m.x(), r.end_m.y(), r.start_m.x(), r.start_m.y()}) Put(out, v);
    Put<std::uint8_t>(out, r.left_dem ? 1 : 0);
    for (const auto* v :
         {&r.speed_out_m_s, &r.energy_ratio, &r.angular_speed_out_rad_s, &r.duration_s, &r.scar_m,
          &r.scar_depth_m, &r.segment_max_speed_m_s, &r.segment_mean_angular_speed_rad_s, &r.segment_max_jump_m})
      PutOptional(out, *v);
    Put<std::uint64_t>(out, r.zones.size());
    for (double v : r.zones) Put(out, v);
  }
  return out;
}

void EnsembleSamples::Append(const std::string& bytes) {
  Reader in(bytes);
  const auto n = in.Get<std::uint64_t>();
  for (std::uint64_t k = 0; k < n; ++k) {
    Rock r;
    r.release = in.Get<std::int32_t>();
    if (r.release < 0 || r.release >= release_.release_count())
      throw std::runtime_error("ensemble samples: a rock of release " + std::to_string(r.release) +
                               ", which this ensemble does not have");
    r.runout_m = in.Get<double>();
    r.end_m.x() = in.Get<double>();
    r.end_m.y() = in.Get<double>();
    r.start_m.x() = in.Get<double>();
    r.start_m.y() = in.Get<double>();
    r.left_dem = in.Get<std::uint8_t>() != 0;
    for (auto* v :
         {&r.speed_out_m_s, &r.energy_ratio, &r.angular_speed_out_rad_s, &r.duration_s, &r.scar_m,
          &r.scar_depth_m, &r.segment_max_speed_m_s, &r.segment_mean_angular_speed_rad_s, &r.segment_max_jump_m})
      *v = in.GetOptional();
    const auto zones = in.Get<std::uint64_t>();
    if (zones > (std::uint64_t{1} << 32))
      throw std::runtime_error("ensemble samples: a rock with " + std::to_string(zones) + " zones");
    for (std::uint64_t z = 0; z < zones; ++z) r.zones.push_back(in.Get<double>());
    rocks_.push_back(std::move(r));
  }
  if (!in.done()) throw std::runtime_error("ensemble samples: bytes after the last rock");
}

}  // namespace talus::fieldobs
