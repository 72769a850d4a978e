#pragma once
// Turns exceptions into the documented exit codes, in one place for every binary.
#include <CLI/CLI.hpp>
#include <algorithm>
#include <functional>
#include <iostream>
#include <string>
#include <vector>

#include "core/types.hpp"
#include "exit_codes.hpp"

namespace tomomap::cli {

/// Edit distance (insertions, deletions, substitutions; a swap counts two).
inline size_t editDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t up = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = up;
    }
  }
  return row[b.size()];
}

/// For a first word that names no command: the message, with the nearest
/// command when one is close. Empty when the word is a command or an option.
inline std::string unknownCommand(const CLI::App& app, int argc, char** argv) {
  const auto subs = app.get_subcommands({});
  if (argc < 2 || subs.empty() || argv[1][0] == '-') return {};
  const std::string word = argv[1];
  std::string nearest, names;
  size_t best = 3;  // more edits than this is a different word
  for (const auto* sub : subs) {
    if (sub->get_name() == word) return {};
    names += (names.empty() ? "" : ", ") + sub->get_name();
    if (const size_t d = editDistance(word, sub->get_name()); d < best) {
      best = d;
      nearest = sub->get_name();
    }
  }
  return "unknown command '" + word + "'" + (nearest.empty() ? "" : "; did you mean '" + nearest + "'?") +
         " (commands: " + names + ")";
}

/// Parses the command line, then runs `action`: usage errors and InputError
/// give kExitBadInput with one line on stderr, anything else kExitInternal.
inline int parseAndRun(CLI::App& app, int argc, char** argv, const std::function<int()>& action) {
  if (const std::string why = unknownCommand(app, argc, argv); !why.empty()) {
    std::cerr << app.get_name() << ": " << why << "\n";
    return kExitBadInput;
  }
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
