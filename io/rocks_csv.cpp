#include "io/rocks_csv.hpp"

#include <stdexcept>

namespace talus::io {

const char* RocksCsvWriter::Header() {
  return "rock,release,seed,end,x_end,y_end,z_end,runout_m,path_length_m,travel_time_s,max_speed_m_"
         "s,"
         "max_kinetic_energy_j,max_jump_height_m,max_angular_speed_rad_s,max_scar_m";
}

RocksCsvWriter::RocksCsvWriter(const std::string& path, std::uint64_t seed)
    : file_(path), seed_(seed) {
  out_ = std::fopen(file_.temp_path().c_str(), "w");
  if (!out_) throw std::runtime_error("cannot create " + file_.temp_path());
  std::fprintf(out_, "%s\n", Header());
}

RocksCsvWriter::~RocksCsvWriter() {
  if (out_) std::fclose(out_);
}

void RocksCsvWriter::Write(const ensemble::RockOutcome& rock) {
  const RockResult& r = rock.result;
  const Eigen::Vector3d& end = r.final_state.position_m;
  const double runout = (end - rock.start.position_m).head<2>().norm();
  std::fprintf(
      out_, "%ld,%d,%llu,%s,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g,%.10g\n",
      rock.rock, rock.release, static_cast<unsigned long long>(seed_), ToString(r.end), end.x(),
      end.y(), end.z(), runout, r.path_length_m, r.travel_time_s, r.max_speed_m_s,
      r.max_kinetic_energy_j, r.max_jump_height_m, r.max_angular_speed_rad_s, r.max_scar_m);
}

void RocksCsvWriter::Commit() {
  const bool ok = std::fflush(out_) == 0 && !std::ferror(out_);
  std::fclose(out_);
  out_ = nullptr;
  if (!ok) throw std::runtime_error("cannot write " + file_.temp_path());
  file_.Commit();
}

}  // namespace talus::io
