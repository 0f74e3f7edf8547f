#include "io/rock_input.hpp"

#include "pointclouds/rock_source.hpp"

namespace talus::io {

RockShape BuildRock(const RockInput& in, std::string* hull_report) {
  pointclouds::RockSpec spec;
  spec.file = in.file;
  spec.builtin = in.builtin;
  spec.dimensions_m = in.dimensions_m;
  spec.density_kg_m3 = in.density_kg_m3;
  spec.volume_m3 = in.volume_m3;
  spec.mass_kg = in.mass_kg;
  spec.max_vertices = in.max_vertices;
  pointclouds::RockReport report;
  RockShape rock = pointclouds::MakeRock(spec, &report);
  if (hull_report) *hull_report = report.source;
  return rock;
}

}  // namespace talus::io
