// `tomomap`: offline map registration with tomographic features.
#include <vector>

#include "commands.hpp"
#include "run_guarded.hpp"
#include "version.hpp"

using namespace tomomap::cli;

int main(int argc, char** argv) {
  CLI::App app{"tomomap " TOMOMAP_VERSION
               ": find the 4-DoF transform (x, y, z, yaw) between two gravity-aligned 3D maps.\n"
               "Exit codes: 0 success, 1 no reliable match, 2 bad input, 3 internal error.",
               "tomomap"};
  app.set_version_flag("-V,--version", "tomomap " TOMOMAP_VERSION);
  app.require_subcommand(1, 1);
  const std::vector<Command> commands{addMatchCommand(app), addSynthCommand(app),  addEvalCommand(app),
                                      addVizCommand(app),   addStatusCommand(app), addFleetKeysCommand(app),
                                      addMergeCommand(app)};
  return parseAndRun(app, argc, argv, [&] {
    for (const auto& c : commands)
      if (c.app->parsed()) return c.run();
    return kExitInternal;
  });
}
