#pragma once
// Loading, describing and matching two map files: what `match` and `viz` share.
#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/matcher.hpp"
#include "report.hpp"

namespace tomomap::cli {

struct MatchFilesOptions {
  std::string target, source, gt_target, gt_source;
  std::string json;  ///< where to write the result as JSON ("-": stdout)
  MatchParams params;
  double max_tilt_deg = degrees(MatchParams{}.max_tilt);
  /// Each map's up direction where the user knows it (x, y, z in the map's frame; empty: estimated).
  std::vector<double> up_target, up_source;
  bool progress = false, quiet = false;
  bool candidates = false;  ///< list every candidate pose (--candidates)
};

struct MatchedFiles {
  MapFeatures target, source;
  MatchResult result;
  std::optional<GroundTruth> truth;  ///< when given
  nlohmann::json inputs;             ///< for the JSON: each map's path, points, points dropped, stray voxels
};

/// Reads the ground truth first (so a bad pose file fails before minutes of
/// work), then both maps at once, each on one thread, where params ask for
/// two threads or more; with one, each map in turn (its raw points dropped
/// once described: half the peak memory on large maps). Then matches.
MatchedFiles matchFiles(MatchFilesOptions o);

/// Adds --grid, --json, --gt-target, --gt-source, --features, -j, --max-tilt, --level, --up-target, --up-source,
/// --candidates, --exhaustive, --progress, -q.
void addMatchOptions(CLI::App& sub, MatchFilesOptions& o);

}  // namespace tomomap::cli
