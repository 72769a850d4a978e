#pragma once
// The check of a --grid option, shared by tomomap and tomomap-baseline.
#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

#include "core/match_settings.hpp"

namespace tomomap::cli {

/// A number of metres in the grid setting's range (match_settings.hpp); the
/// refusal says what is expected.
inline CLI::Validator gridSize() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        const MatchSetting& grid = matchSetting("grid");
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v) || !grid.inRange(v))
          return "grid size must be a number of metres from " + settingText(grid.lo) + " to " + settingText(grid.hi) +
                 " (0.05 indoors, 0.2-0.5 outdoors), not " + text;
        return {};
      },
      "METRES");
}

}  // namespace tomomap::cli
