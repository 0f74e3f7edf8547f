// Benchmark: what the output phases after the rocks hold in memory, one phase per run of the
// program (peak resident memory only rises, so each phase is measured in a process of its own).
// Prints the phase's wall time and the process's peak resident memory before and after it.
//   --phase spill: RasterSpill::Percentiles over --records synthetic passages (three values each,
//     cells spread like the paths below a release line) on a grid of --nx x --ny cells, within
//     --budget-mib; the spill's size for 10^5 cases/tirol rocks is about 3.3e7 records.
//   --phase geopackage: WriteRocksGeoPackage of an existing run's rocks.csv and
//     evaluation_lines.csv (--run DIR, e.g. an --out of talus simulate with trajectories off).
//   --phase statistics: the statistics report.html reads back from that run's rocks.csv
//     (SummarizeColumns within --budget-mib).

#include <cpl_error.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "bench/bench_main.hpp"
#include "common/column_statistics.hpp"
#include "ensemble/raster_spill.hpp"
#include "io/geopackage.hpp"
#include "io/report_html.hpp"

namespace {

void Spill(long records, int nx, int ny, std::size_t budget_bytes) {
  talus::GridGeometry grid;
  grid.nx = nx;
  grid.ny = ny;
  talus::ensemble::RasterSpillOptions options;
  options.memory_bytes = budget_bytes;
  talus::ensemble::RasterSpill spill(grid, 3, options);
  std::vector<int> passages(static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny), 0);
  std::mt19937 random(1);
  std::normal_distribution<double> column(nx / 2.0, nx / 9.0), row(ny / 2.0, ny / 4.0);
  for (long i = 0; i < records; ++i) {
    const int x = std::clamp(static_cast<int>(column(random)), 0, nx - 1);
    const int y = std::clamp(static_cast<int>(row(random)), 0, ny - 1);
    const int cell = y * nx + x;
    const float values[3] = {float(i % 97), float(i % 89), float(i % 83)};
    spill.Append(cell, values);
    ++passages[static_cast<std::size_t>(cell)];
  }
  std::vector<std::vector<float>> out(3, std::vector<float>(passages.size(), 0));
  const double before = PeakRssMiB();
  const auto t0 = std::chrono::steady_clock::now();
  spill.Percentiles(passages, {95}, out);
  const auto t1 = std::chrono::steady_clock::now();
  std::printf(
      "spill: %ld records, %.1f MB on disk, budget %.1f MiB: %.2f s, peak RSS %.1f -> %.1f MiB\n",
      records, double(spill.DiskBytes()) / 1e6, double(budget_bytes) / (1 << 20),
      std::chrono::duration<double>(t1 - t0).count(), before, PeakRssMiB());
}

}  // namespace

int RunBenchmark(int argc, char** argv) {
  CLI::App app{"Memory of the output phases after the rocks"};
  std::string phase, run;
  long records = 33'000'000;
  int nx = 270, ny = 370;  // cases/tirol's DEM
  double budget_mib = -1;
  app.add_option("--phase", phase, "spill, geopackage or statistics")
      ->required()
      ->check(CLI::IsMember({"spill", "geopackage", "statistics"}));
  app.add_option("--run", run, "An output directory of talus simulate (geopackage, statistics)");
  app.add_option("--records", records, "Spilled passages (spill)");
  app.add_option("--nx", nx, "Grid columns (spill)");
  app.add_option("--ny", ny, "Grid rows (spill)");
  app.add_option("--budget-mib", budget_mib,
                 "Memory budget, MiB (spill: RasterSpillOptions::memory_bytes; statistics: "
                 "SummarizeColumns); default: the program's");
  CLI11_PARSE(app, argc, argv);
  PrintMachine(argc, argv);
  const auto budget = [&](std::size_t fallback) {
    return budget_mib > 0 ? static_cast<std::size_t>(budget_mib * (1 << 20)) : fallback;
  };

  if (phase == "spill") {
    Spill(records, nx, ny, budget(talus::ensemble::RasterSpillOptions{}.memory_bytes));
    return 0;
  }
  if (run.empty()) {
    std::fprintf(stderr, "--phase %s needs --run DIR\n", phase.c_str());
    return 2;
  }
  const std::string rocks = run + "/rocks.csv", lines = run + "/evaluation_lines.csv";
  const std::string with_lines = std::filesystem::exists(lines) ? lines : std::string();
  const double before = PeakRssMiB();
  const auto t0 = std::chrono::steady_clock::now();
  if (phase == "geopackage") {
    const std::string out =
        (std::filesystem::temp_directory_path() / "talus_bench_output_memory.gpkg").string();
    CPLPushErrorHandler(CPLQuietErrorHandler);  // GDAL's warning on the temporary file's name
    talus::io::WriteRocksGeoPackage(out, rocks, "", "", with_lines);
    CPLPopErrorHandler();
    std::filesystem::remove(out);
  } else {
    const std::size_t b = budget(talus::kColumnStatisticsBudgetBytes);
    const talus::ColumnSource file = talus::io::RockColumns(rocks);
    int readings = 0;
    const talus::ColumnSource counted = [&](const talus::ColumnSink& emit) {
      ++readings;
      file(emit);
    };
    const auto s =
        talus::SummarizeColumns(counted, talus::io::kRockColumnCount, {50, 90, 95, 99, 100}, b);
    std::printf("rocks.csv: %ld rocks, read %d times, runout p95 %.6g m\n",
                s[talus::io::kRunoutColumn].count, readings,
                s[talus::io::kRunoutColumn].percentiles[2]);
  }
  const auto t1 = std::chrono::steady_clock::now();
  std::printf("%s of %s: %.2f s, peak RSS %.1f -> %.1f MiB\n", phase.c_str(), run.c_str(),
              std::chrono::duration<double>(t1 - t0).count(), before, PeakRssMiB());
  return 0;
}
