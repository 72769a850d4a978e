#pragma once
// The check of a --grid option, shared by tomomap and tomomap-baseline.
#include <CLI/CLI.hpp>
#include <cmath>
#include <string>

namespace tomomap::cli {

/// A positive, finite number of metres; the refusal says what is expected
/// (CLI11's own PositiveNumber prints its range up to the largest double).
inline CLI::Validator gridSize() {
  return CLI::Validator(
      [](std::string& text) -> std::string {
        double v = 0;
        if (!CLI::detail::lexical_cast(text, v) || !(v > 0) || !std::isfinite(v))
          return "grid size must be a positive number of metres (0.05 indoors, 0.2-0.5 outdoors), not " + text;
        return {};
      },
      "METRES");
}

}  // namespace tomomap::cli
