#pragma once
// Each verb of the talus program lives in its own file and registers itself on the CLI11 app.
// Add<Verb>Command adds the subcommand and returns a function that runs it when it was chosen.

#include <CLI/CLI.hpp>
#include <functional>

namespace talus::app {

using Runner = std::function<int()>;

Runner AddDemoCommand(CLI::App& app);
Runner AddRockCommand(CLI::App& app);
Runner AddSimulateCommand(CLI::App& app);
Runner AddValidateCommand(CLI::App& app);

}  // namespace talus::app
