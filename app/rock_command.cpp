// talus rock info | hull: a rock from a point cloud or a built-in shape, its mass properties and
// shape (info), or its convex hull as PLY for viewing (hull).

#include <Eigen/Geometry>
#include <iostream>
#include <memory>
#include <new>
#include <string>

#include "app/commands.hpp"
#include "app/console.hpp"
#include "pointclouds/rock_source.hpp"

namespace talus::app {
namespace {

struct RockArgs {
  pointclouds::RockSpec spec;
  double volume_m3 = 0;  // only when given
  double mass_kg = 0;
  CLI::Option* volume = nullptr;
  CLI::Option* mass = nullptr;
  bool json = false;
  std::string out;
  bool principal = false;
};

// The options both verbs share: where the rock comes from and how it is built.
void AddShapeOptions(CLI::App* verb, RockArgs& args) {
  auto& spec = args.spec;
  verb->add_option("file", spec.file, "Point cloud: .pcd, .ply, .xyz, .txt, .csv or .pts (metres)");
  verb->add_option("--builtin", spec.builtin,
                   "Built-in shape instead of a file: box, ellipsoid, icosphere, "
                   "cylinder, disk, rock, eota111, eota221");
  verb->add_option("--dimensions", spec.dimensions_m,
                   "Built-in dimensions in m (box a b c, cylinder diameter "
                   "height, ...)")
      ->expected(1, 3);
  verb->add_option("--points", spec.points, "Built-in rock: random points on the ellipsoid")
      ->capture_default_str();
  verb->add_option("--roughness", spec.roughness,
                   "Built-in rock: radial perturbation of the points (0 .. 0.5)")
      ->capture_default_str();
  verb->add_option("--shape-seed", spec.shape_seed, "Built-in rock: seed of the points")
      ->capture_default_str();
  verb->add_option("--density", spec.density_kg_m3, "Density in kg/m^3")->capture_default_str();
  args.volume =
      verb->add_option("--volume", args.volume_m3, "Scale the rock to this volume in m^3");
  args.mass = verb->add_option("--mass", args.mass_kg,
                               "Mass in kg: sets the density of a built-in of given dimensions, "
                               "else scales the rock")
                  ->excludes(args.volume);
  verb->add_option("--max-vertices", spec.max_vertices,
                   "Simplify the hull to at most K vertices (0: off)")
      ->capture_default_str();
  // The fields of pointclouds::CleanOptions, the keys of a scene's [rock] clean = { ... }.
  verb->add_option("--outliers,--outlier-neighbours", spec.clean.outlier_neighbours,
                   "Statistical outlier removal over K nearest neighbours (0: off)")
      ->capture_default_str();
  verb->add_option("--outlier-std,--outlier-std-ratio", spec.clean.outlier_std_ratio,
                   "Outlier threshold in standard deviations of the mean neighbour distance")
      ->capture_default_str();
  verb->add_option("--outlier-spacing-ratio", spec.clean.outlier_spacing_ratio,
                   "Drop an outlier only when its mean neighbour distance is also this many times "
                   "the median (0: the statistical rule alone)")
      ->capture_default_str();
  verb->add_option("--outlier-passes", spec.clean.outlier_passes,
                   "Repeat outlier removal until a pass drops nothing, at most this often")
      ->capture_default_str();
  verb->add_option("--voxel,--voxel-m", spec.clean.voxel_m,
                   "Downsample to one point per voxel of this size in m (0: off)")
      ->capture_default_str();
}

// Builds the rock; on failure prints one line on stderr and returns the exit code (bad input, or
// a run that failed for want of memory), else kExitOk.
int BuildRock(const char* verb, RockArgs& args, pointclouds::RockReport* report) {
  if (args.spec.file.empty() == args.spec.builtin.empty()) {
    std::cerr << "talus rock " << verb
              << ": give a point cloud FILE or --builtin NAME (one of them)\n";
    return kExitBadInput;
  }
  if (*args.volume) args.spec.volume_m3 = args.volume_m3;
  if (*args.mass) args.spec.mass_kg = args.mass_kg;
  try {
    pointclouds::MakeRock(args.spec, report);
    for (const std::string& warning : report->warnings) Warn(std::string("rock ") + verb, warning);
    return kExitOk;
  } catch (const std::bad_alloc&) {
    std::cerr << "talus rock " << verb << ": out of memory\n";
    return kExitRunFailed;
  } catch (const std::exception& e) {  // unreadable or invalid point clouds, impossible shapes
    std::string message = e.what();
    for (char& ch : message)
      if (ch == '\n') ch = ' ';
    std::cerr << "talus rock " << verb << ": " << message << "\n";
    return kExitBadInput;
  }
}

int RunInfo(RockArgs& args) {
  pointclouds::RockReport report;
  if (const int status = BuildRock("info", args, &report); status != kExitOk) return status;
  // The report is what the verb is for: printed with --quiet too.
  std::cout << (args.json ? report.ToJson() + "\n" : report.FullReport());
  return kExitOk;
}

int RunHull(RockArgs& args) {
  pointclouds::RockReport report;
  if (const int status = BuildRock("hull", args, &report); status != kExitOk) return status;
  Polyhedron hull = report.hull;
  Eigen::Vector3d offset_m = report.recentred_by_m;
  if (args.principal) {
    // x_principal = axes' (x_input - centroid), with both relative to the recentring offset.
    const Eigen::Vector3d centroid = report.centroid_m - report.recentred_by_m;
    for (auto& v : hull.vertices_m) v = report.principal_axes.transpose() * (v - centroid);
    offset_m.setZero();
  }
  try {
    pointclouds::WritePolyhedronPly(hull, offset_m, args.out);
  } catch (const std::exception& e) {
    std::cerr << "talus rock hull: " << e.what() << "\n";
    return kExitRunFailed;
  }
  Say("Wrote the hull of %s (%zu vertices, %zu triangles, %s frame) to %s\n", report.source.c_str(),
      static_cast<std::size_t>(report.hull_vertices), static_cast<std::size_t>(report.hull_faces),
      args.principal ? "principal" : "input", args.out.c_str());
  return kExitOk;
}

}  // namespace

Runner AddRockCommand(CLI::App& app) {
  auto info_args = std::make_shared<RockArgs>();
  auto hull_args = std::make_shared<RockArgs>();
  CLI::App* rock = app.add_subcommand("rock", "Rock shapes from point clouds or built-ins");
  rock->require_subcommand(1);

  CLI::App* info = rock->add_subcommand(
      "info", "Print a rock's hull, mass properties, principal frame and shape");
  AddShapeOptions(info, *info_args);
  info->add_flag("--json", info_args->json, "Print JSON (the stable interface for scripts)");

  CLI::App* hull = rock->add_subcommand("hull", "Write a rock's convex hull as PLY for viewing");
  AddShapeOptions(hull, *hull_args);
  hull->add_option("--out,-o", hull_args->out, "Output PLY file")->required();
  hull->add_flag("--principal", hull_args->principal,
                 "Write in the principal frame at the centre of mass (default: the input frame)");

  return [rock, info, hull, info_args, hull_args]() {
    if (!*rock) return -1;
    if (*info) return RunInfo(*info_args);
    if (*hull) return RunHull(*hull_args);
    return -1;
  };
}

}  // namespace talus::app
