// `tomomap`: offline map registration with tomographic features.
#include <iostream>
#include <vector>

#include "commands.hpp"
#include "core/types.hpp"
#include "exit_codes.hpp"
#include "version.hpp"

using namespace tomomap::cli;

int main(int argc, char** argv) {
  CLI::App app{"tomomap " TOMOMAP_VERSION
               ": find the 4-DoF transform (x, y, z, yaw) between two gravity-aligned 3D maps.\n"
               "Exit codes: 0 success, 1 no reliable match, 2 bad input, 3 internal error."};
  app.set_version_flag("-V,--version", "tomomap " TOMOMAP_VERSION);
  app.require_subcommand(1, 1);
  const std::vector<Command> commands{addMatchCommand(app), addSynthCommand(app)};

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);  // prints the message and a usage hint
    return kExitBadInput;
  }
  try {
    for (const auto& c : commands)
      if (c.app->parsed()) return c.run();
  } catch (const tomomap::InputError& e) {
    std::cerr << "tomomap: error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << "tomomap: internal error: " << e.what() << "\n";
    return kExitInternal;
  }
  return kExitInternal;
}
