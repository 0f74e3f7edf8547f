// talus: the command-line program. Each verb is registered from its own file (commands.hpp).

#include <CLI/CLI.hpp>
#include <vector>

#include "app/commands.hpp"
#include "talus/version.hpp"

int main(int argc, char** argv) {
  CLI::App app{"Talus: rockfall simulation with non-smooth contact mechanics"};
  app.set_version_flag("--version", std::string("talus ") + talus::kVersion);
  app.require_subcommand(1);
  // Usage errors are one line on stderr, like every other failure.
  app.failure_message([](const CLI::App*, const CLI::Error& e) {
    return std::string(e.what()) + " (see --help)\n";
  });

  const std::vector<talus::app::Runner> runners = {
      talus::app::AddDemoCommand(app),
      talus::app::AddRockCommand(app),
      talus::app::AddSimulateCommand(app),
      talus::app::AddValidateCommand(app),
  };

  CLI11_PARSE(app, argc, argv);
  // A runner returns -1 when its verb was not the one chosen.
  for (const auto& run : runners) {
    const int status = run();
    if (status >= 0) return status;
  }
  return 0;
}
