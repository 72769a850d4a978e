#pragma once
// Turns exceptions into the documented exit codes, in one place for every binary.
#include <CLI/CLI.hpp>
#include <functional>
#include <iostream>

#include "core/types.hpp"
#include "exit_codes.hpp"

namespace tomomap::cli {

/// Parses the command line, then runs `action`: usage errors and InputError
/// give kExitBadInput with one line on stderr, anything else kExitInternal.
inline int parseAndRun(CLI::App& app, int argc, char** argv, const std::function<int()>& action) {
  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    app.exit(e);  // prints the message and a usage hint
    return kExitBadInput;
  }
  try {
    return action();
  } catch (const InputError& e) {
    std::cerr << app.get_name() << ": error: " << e.what() << "\n";
    return kExitBadInput;
  } catch (const std::exception& e) {
    std::cerr << app.get_name() << ": internal error: " << e.what() << "\n";
    return kExitInternal;
  }
}

}  // namespace tomomap::cli
