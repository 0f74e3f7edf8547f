// talus: the command-line program. Each verb is registered from its own file (commands.hpp); all
// share the exit codes there: 0 done, 1 the run failed, 2 bad input or usage, 128 + signal.

#include <CLI/CLI.hpp>
#include <csignal>
#include <cstdio>
#include <exception>
#include <functional>
#include <vector>

#include "app/commands.hpp"
#include "app/console.hpp"
#include "talus/version.hpp"

namespace {

int Run(int argc, char** argv) {
  CLI::App app{"Talus: rockfall simulation with non-smooth contact mechanics"};
  app.set_version_flag("--version", std::string("talus ") + talus::kVersion);
  app.require_subcommand(1);
  // Usage errors are one line on stderr, like every other failure.
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return std::string(e.what()) + " (see --help)\n";
  });

  const std::vector<talus::app::Runner> runners = {
      talus::app::AddDemoCommand(app),      talus::app::AddRockCommand(app),
      talus::app::AddSimulateCommand(app),  talus::app::AddValidateCommand(app),
      talus::app::AddCalibrateCommand(app), talus::app::AddMergeCommand(app),
  };

  // --quiet on every verb: no information and no progress, warnings and errors still (console.hpp).
  bool quiet = false;
  const std::function<void(CLI::App*)> add_quiet = [&](CLI::App* verb) {
    verb->add_flag("-q,--quiet", quiet,
                   "Print no information or progress, only warnings and errors (run.log in --out "
                   "still has everything)");
    for (CLI::App* sub : verb->get_subcommands([](CLI::App*) { return true; })) add_quiet(sub);
  };
  for (CLI::App* verb : app.get_subcommands([](CLI::App*) { return true; })) add_quiet(verb);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version end here with 0; every usage error is bad input.
    return app.exit(e) == 0 ? talus::app::kExitOk : talus::app::kExitBadInput;
  }
  talus::app::SetQuiet(quiet);
  talus::app::SetCommandLine(argc, argv);
  // A runner returns -1 when its verb was not the one chosen. A verb that wrote into --out sets
  // where run.log goes; it is written when the verb succeeded.
  for (const auto& run : runners) {
    const int status = run();
    if (status < 0) continue;
    talus::app::WriteRunLog(status);
    return status;
  }
  return talus::app::kExitOk;
}

}  // namespace

// The verbs report their own failures; anything that still escapes (out of memory outside a run)
// is a failed run, reported on one line.
int main(int argc, char** argv) {
  // A file-size limit (ulimit -f) is a write error ("File too large", EFBIG) that the verbs report
  // like a full disk, removing their temporary files; its signal would kill the process instead.
  std::signal(SIGXFSZ, SIG_IGN);
  try {
    return Run(argc, argv);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "talus: %s\n", e.what());
    return talus::app::kExitRunFailed;
  }
}
