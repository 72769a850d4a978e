#pragma once
// Checks of the options that are matcher settings (--grid, --features,
// --threads, --max-tilt), shared by tomomap and tomomap-baseline: the
// settings' own ranges (core/match_settings.hpp), as in the daemon's config.
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

/// The range of the matcher setting `key` ("threads", "max_features", ...).
inline CLI::Range settingRange(const char* key) {
  const MatchSetting& s = matchSetting(key);
  if (s.kind == SettingKind::Integer) return CLI::Range(static_cast<int>(s.lo), static_cast<int>(s.hi));
  return CLI::Range(s.lo, s.hi);
}

}  // namespace tomomap::cli
