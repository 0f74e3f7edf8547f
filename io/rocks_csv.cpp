#include "io/rocks_csv.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace talus::io {
std::string CsvField(const std::string& text) {
  // Blanks around a field are trimmed by readers (CsvTable) unless quoted.
  const auto blank = [](char c) { return c == ' ' || c == '\t'; };
  if (text.find_first_of(",\"\n\r") == std::string::npos &&
      (text.empty() || (!blank(text.front()) && !blank(text.back()))))
    return text;
  std::string out = "\"";
  for (char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

const char* RocksCsvWriter::Header() {
  return "rock,release,run,seed,end,x_end,y_end,z_end,runout_m,path_length_m,travel_time_s,"
         "max_speed_m_s,max_kinetic_energy_j,max_jump_height_m,max_angular_speed_rad_s,max_scar_m,"
         "block,mass_kg,x_start,y_start,z_start,travel_angle_deg,end_ground,end_barrier";
}

RocksCsvWriter::RocksCsvWriter(const std::string& path, const Scene& scene,
                               const ensemble::ReleaseSpec& release)
    : file_(path, Header()), scene_(scene), release_(release) {}

void RocksCsvWriter::Write(const ensemble::RockOutcome& rock) {
  const RockResult& r = rock.result;
  const Eigen::Vector3d& end = r.final_state.position_m;
  const ensemble::ReleaseRun* run =
      release_.runs.empty() ? nullptr : &release_.runs[static_cast<std::size_t>(rock.release)];
  const std::string block =
      run && run->block >= 0 ? release_.blocks[static_cast<std::size_t>(run->block)].id : "";
  const Eigen::Vector3d& start = rock.start.position_m;
  // Travel angle (Fahrboeschung) of the centre of mass, release to end.
  const double travel_angle_deg =
      std::atan2(start.z() - end.z(), r.runout_m) * 180.0 / std::numbers::pi;
  const std::string& end_ground =
      scene_.ground.category(scene_.terrain.GroundAt(end.x(), end.y())).name;
  // The barrier that stopped it (the last it met), empty for every other ending.
  const std::string end_barrier =
      r.end == EndReason::kBarrier && !r.barrier_events.empty()
          ? scene_.barriers[static_cast<std::size_t>(r.barrier_events.back().barrier)].name
          : std::string();
  std::fprintf(
      file_.get(),
      "%ld,%d,%s,%llu,%s,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,"
      "%s,%.10g,%.10g,%.10g,%.10g,%.10g,%s,%s\n",
      rock.rock, rock.release, CsvField(release_.ReleaseName(rock.release)).c_str(),
      static_cast<unsigned long long>(release_.seed), ToString(r.end), end.x(), end.y(), end.z(),
      r.runout_m, r.path_length_m, r.travel_time_s, r.max_speed_m_s, r.max_kinetic_energy_j,
      r.max_jump_height_m, r.max_angular_speed_rad_s, r.max_scar_m, CsvField(block).c_str(),
      rock.shape ? rock.shape->mass_kg : 0.0, start.x(), start.y(), start.z(), travel_angle_deg,
      CsvField(end_ground).c_str(), CsvField(end_barrier).c_str());
}

void RocksCsvWriter::Commit() { file_.Commit(); }

}  // namespace talus::io
