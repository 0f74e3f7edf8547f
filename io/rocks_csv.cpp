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

RockRow RockRowOf(const ensemble::RockOutcome& rock, const Scene& scene,
                  const ensemble::ReleaseSpec& release) {
  const RockResult& r = rock.result;
  const Eigen::Vector3d& end = r.final_state.position_m;
  const Eigen::Vector3d& start = rock.start.position_m;
  const ensemble::ReleaseRun* run =
      release.runs.empty() ? nullptr : &release.runs[static_cast<std::size_t>(rock.release)];
  RockRow row;
  row.rock = rock.rock;
  row.release = rock.release;
  row.run = release.ReleaseName(rock.release);
  row.seed = release.seed;
  row.end = ToString(r.end);
  row.x_end = end.x();
  row.y_end = end.y();
  row.z_end = end.z();
  row.runout_m = r.runout_m;
  row.path_length_m = r.path_length_m;
  row.travel_time_s = r.travel_time_s;
  row.max_speed_m_s = r.max_speed_m_s;
  row.max_kinetic_energy_j = r.max_kinetic_energy_j;
  row.max_jump_height_m = r.max_jump_height_m;
  row.max_angular_speed_rad_s = r.max_angular_speed_rad_s;
  row.max_scar_m = r.max_scar_m;
  if (run && run->block >= 0) row.block = release.blocks[static_cast<std::size_t>(run->block)].id;
  row.mass_kg = rock.shape ? rock.shape->mass_kg : 0.0;
  row.x_start = start.x();
  row.y_start = start.y();
  row.z_start = start.z();
  row.travel_angle_deg = std::atan2(start.z() - end.z(), r.runout_m) * 180.0 / std::numbers::pi;
  row.end_ground = scene.ground.category(scene.terrain.GroundAt(end.x(), end.y())).name;
  // The barrier that stopped it (the last it met), empty for every other ending.
  if (r.end == EndReason::kBarrier && !r.barrier_events.empty())
    row.end_barrier = scene.barriers[static_cast<std::size_t>(r.barrier_events.back().barrier)].name;
  return row;
}

void RocksCsvWriter::Write(const ensemble::RockOutcome& rock) {
  const RockRow r = RockRowOf(rock, scene_, release_);
  std::fprintf(
      file_.get(),
      "%ld,%d,%s,%llu,%s,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,"
      "%s,%.10g,%.10g,%.10g,%.10g,%.10g,%s,%s\n",
      r.rock, r.release, CsvField(r.run).c_str(), static_cast<unsigned long long>(r.seed), r.end,
      r.x_end, r.y_end, r.z_end, r.runout_m, r.path_length_m, r.travel_time_s, r.max_speed_m_s,
      r.max_kinetic_energy_j, r.max_jump_height_m, r.max_angular_speed_rad_s, r.max_scar_m,
      CsvField(r.block).c_str(), r.mass_kg, r.x_start, r.y_start, r.z_start, r.travel_angle_deg,
      CsvField(r.end_ground).c_str(), CsvField(r.end_barrier).c_str());
}

void RocksCsvWriter::Commit() { file_.Commit(); }

}  // namespace talus::io
