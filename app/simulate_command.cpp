// talus simulate: run a scene's ensemble and write rocks.csv, rasters, trajectories and a summary.

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <string>

#include "app/commands.hpp"
#include "app/console.hpp"
#include "app/interrupt.hpp"
#include "app/run_outputs.hpp"
#include "app/run_verb.hpp"
#include "app/simulate.hpp"
#include "common/atomic_file.hpp"
#include "common/error.hpp"
#include "ensemble/run_warnings.hpp"
#include "ensemble/runner.hpp"
#include "io/resources.hpp"
#include "io/scene_file.hpp"

namespace talus::app {

// "rock <shape> (<mass> kg, <n> hull vertices); <k> releases x <n> rocks, seed <s>", or the runs
// and blocks of a run table.
std::string DescribeRocks(const io::SceneFile& scene) {
  const ensemble::ReleaseSpec& r = scene.release;
  char line[512];
  if (!r.runs.empty()) {
    std::snprintf(line, sizeof line, "%zu runs x %ld rocks, %zu blocks%s, seed %llu", r.runs.size(),
                  r.rocks_per_release, r.blocks.size(),
                  r.shape_per_rock ? " (a shape of its own per rock)" : "",
                  static_cast<unsigned long long>(r.seed));
  } else {
    char rocks[96];
    if (r.release_first_rock.empty())
      std::snprintf(rocks, sizeof rocks, "%zu releases x %ld rocks", r.releases.size(),
                    r.rocks_per_release);
    else  // rocks per area
      std::snprintf(rocks, sizeof rocks, "%zu releases, %ld rocks by area", r.releases.size(),
                    r.total_rocks());
    std::snprintf(line, sizeof line, "rock %s (%.1f kg, %zu hull vertices)%s; %s, seed %llu",
                  scene.rock_description.c_str(), scene.scene.rock.mass_kg,
                  scene.scene.rock.vertices_m.size(),
                  r.shape_per_rock ? ", a shape of its own per rock" : "", rocks,
                  static_cast<unsigned long long>(r.seed));
  }
  return line;
}

void PrintSceneWarnings(const io::SceneFile& scene, const char* command) {
  for (const std::string& warning : scene.warnings) Warn(command, warning);
}

void PrintRunWarnings(const ensemble::EnsembleReport& report, const io::SceneFile& scene,
                      const char* command) {
  for (const std::string& warning : ensemble::RunWarnings(report, scene.scene.options))
    Warn(command, warning);
}

void PrintNotScored(const std::vector<std::string>& not_scored) {
  for (const std::string& line : not_scored) Say("Not scored: %s\n", line.c_str());
}

int LoadForSimulate(const SimulateArgs& args, io::SceneFile* scene, std::pair<long, long>* range,
                    std::string* message) {
  namespace fs = std::filesystem;
  if (std::error_code error; fs::is_directory(args.scene, error)) {
    *message = args.scene + " is a directory, not a scene file";
    if (fs::is_regular_file(fs::path(args.scene) / "scene.toml", error))
      *message += " (did you mean " + (fs::path(args.scene) / "scene.toml").string() + "?)";
    return kExitBadInput;
  }
  try {
    *scene = io::LoadScene(args.scene);
    if (!args.preset.empty()) {
      SolverPreset preset = SolverPreset::kDefault;
      if (!ParseSolverPreset(args.preset, &preset))
        throw InputError("--preset: unknown preset '" + args.preset +
                         "'; known: " + kSolverPresetNames.List());
      io::UseSolverPreset(*scene, preset);
      for (const std::string& key : scene->solver_keys_overridden)
        Say("--preset %s overrides the scene's %s\n", args.preset.c_str(), key.c_str());
    }
    args.ensemble.ApplyTo(scene->release);
    // --self-check wins over the scene's [solver] self_check.
    const std::string check_key = args.self_check >= 0 ? "--self-check" : "[solver] self_check";
    if (args.self_check >= 0) scene->self_check = args.self_check;
    if (scene->self_check > 0 && !args.rock_range.empty())
      throw InputError(check_key + ": not with --rock-range (check the whole run, not a part)");
    if (scene->self_check > scene->release.total_rocks())
      throw InputError(check_key + " " + std::to_string(scene->self_check) + ": the run has " +
                       std::to_string(scene->release.total_rocks()) + " rocks");
    *range = {0, scene->release.total_rocks()};
    if (!args.rock_range.empty()) {
      *range = ParseRockRange(args.rock_range);
      if (range->second > scene->release.total_rocks())
        throw InputError("--rock-range " + args.rock_range + ": the ensemble has rocks 0:" +
                         std::to_string(scene->release.total_rocks()) + " only");
    }
  } catch (const InputError& e) {
    *message = e.what();
    return kExitBadInput;
  } catch (const std::exception& e) {  // e.g. out of memory while reading the inputs
    *message = "cannot load " + args.scene + ": " + e.what();
    return kExitRunFailed;
  }
  return kExitOk;
}

namespace {

int RunSimulate(const SimulateArgs& args) {
  if (const int ranks = LaunchedRanks(); ranks > 1) return RunSimulateOnRanks(args);
  io::SceneFile scene;
  std::pair<long, long> range;  // rocks [first, end) to run
  if (std::string message; const int code = LoadForSimulate(args, &scene, &range, &message)) {
    Fail("simulate", message);
    return code;
  }
  Verb verb{.name = "simulate", .out = args.out};
  // A run too large for this machine fails now, with the estimate and the knob to turn.
  const io::ResourceEstimate needs = io::EstimateResources(
      scene, ensemble::WorkerThreads(args.ensemble.threads, scene.release.total_rocks()));
  io::MachineCapacity capacity;
  verb.checks = [&] {
    capacity = io::MeasureCapacity(args.out);
    return io::CheckResources(needs, capacity);
  };
  verb.say_removed_temporaries = true;
  ProgressBar progress;
  verb.hooks.on_failure = [&progress](bool) { progress.Break(); };
  return RunVerb(verb, [&](std::optional<StagingDirectory>& staging) {
    Say("Scene %s: %s; %s\n", args.scene.c_str(), scene.terrain_description.c_str(),
        DescribeRocks(scene).c_str());
    PrintSceneWarnings(scene);
    Say("Needs about %s of memory (%s available) and %s of disk (%s free)\n",
        io::FormatBytes(needs.memory_bytes()).c_str(),
        io::FormatBytes(capacity.memory_bytes).c_str(), io::FormatBytes(needs.disk_bytes()).c_str(),
        io::FormatBytes(capacity.disk_bytes).c_str());
    // Every output is written into a staging directory and moved into --out only when all are
    // complete: a failed or interrupted run leaves --out as it was.
    staging.emplace(args.out);
    // Thrown on the calling thread, Interrupted stops the workers and comes out of RunEnsemble.
    auto show_progress = [&progress](long done, long total) {
      ThrowIfInterrupted();
      progress(done, total);
    };
    // The self-check runs first: its subsample is small, and its report goes into summary.json.
    std::optional<ensemble::SelfCheckReport> self_check;
    if (scene.self_check > 0) {
      ensemble::SelfCheckOptions check;
      check.rocks = scene.self_check;
      check.threads = args.ensemble.threads;
      if (!scene.evaluation_lines.empty())
        check.evaluation_lines =
            std::make_shared<const std::vector<ensemble::EvaluationLine>>(scene.evaluation_lines);
      Say("Self-check: %ld rocks at dt %g s and %g s ...\n", check.rocks, scene.scene.options.dt_s,
          scene.scene.options.dt_s / check.dt_divisor);
      self_check = ensemble::RunSelfCheck(scene.scene, scene.release, check);
      ThrowIfInterrupted();
    }
    ensemble::EnsembleReport report;
    const std::vector<std::string> files = RunIntoStaging(
        scene, args.ensemble.threads, range.first, range.second, !args.rock_range.empty(), *staging,
        show_progress, &report, self_check ? &*self_check : nullptr);
    CommitOutputs(*staging, files, args.out);
    Say("%s\n", report.BriefReport().c_str());
    if (self_check)
      Say("%s(%.1f s; statistics as run, refined, difference +- standard error; * beyond "
          "%.2f standard errors, a 5 %% chance of a false alarm over all)\n",
          self_check->BriefReport().c_str(), self_check->wall_time_s, self_check->threshold);
    if (!args.rock_range.empty())
      Say("Wrote rocks %ld:%ld of %ld as a partial result (merge with talus merge)\n", range.first,
          range.second, scene.release.total_rocks());
    Say("Wrote %zu files to %s\n", files.size(), args.out.c_str());
    PrintRunWarnings(report, scene);
  });
}

}  // namespace

Runner AddSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd = app.add_subcommand(
      "simulate", "Run a scene's rocks and write rocks.csv, rasters, trajectories");
  cmd->add_option("scene", args->scene, "Scene file (TOML)")->required();
  cmd->add_option("--out", args->out, "Output directory")->required();
  AddEnsembleOptions(cmd, &args->ensemble, "release");
  cmd->add_option("--preset", args->preset,
                  "Solver accuracy: fast, default or accurate (wins over the scene's [solver] "
                  "preset and its dt_s, tolerance_m_s and max_iterations; each value it changes "
                  "is printed and listed in summary.json)");
  cmd->add_option("--self-check", args->self_check,
                  "Rerun N rocks (every total/N-th) at half the time step and a 1e-7 m/s contact "
                  "solve, and report each headline statistic's difference with its standard error "
                  "(console and summary.json); 0: none, whatever the scene's [solver] self_check")
      ->check(IntegerRange(0, std::numeric_limits<long>::max()))
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            // An integer >= 0 by now (IntegerRange).
            return std::stoll(text) == 1 ? "must be 0 (none) or at least 2 rocks" : "";
          },
          "0 or >= 2"));
  cmd->add_option("--rock-range", args->rock_range,
                  "Run only rocks A .. B-1 (A:B) and write a partial result for talus merge");
  return [cmd, args]() { return *cmd ? RunSimulate(*args) : -1; };
}

}  // namespace talus::app
