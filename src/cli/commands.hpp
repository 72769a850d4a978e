#pragma once
// Each subcommand registers itself and its options on the app and returns the
// action to run once the command line parsed.
#include <CLI/CLI.hpp>
#include <functional>

namespace tomomap::cli {

struct Command {
  CLI::App* app = nullptr;
  std::function<int()> run;
};

Command addMatchCommand(CLI::App& app);
Command addSynthCommand(CLI::App& app);
Command addEvalCommand(CLI::App& app);
Command addVizCommand(CLI::App& app);
Command addStatusCommand(CLI::App& app);
Command addFleetKeysCommand(CLI::App& app);
Command addMergeCommand(CLI::App& app);

}  // namespace tomomap::cli
