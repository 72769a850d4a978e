#pragma once
// Evaluation suites: TOML files listing map pairs with ground truth, or asking
// `synth` for generated ones.
#include <string>
#include <vector>

#include "core/matcher.hpp"

namespace tomomap::cli {

struct SuitePair {
  std::string name;
  std::string target, source, gt_target, gt_source;  ///< paths (resolved against the suite's folder)
  double grid = MatchParams{}.grid;                  ///< [m]
  std::string noise = "real";                        ///< noise label for grouping: real data, or the synth level
  std::vector<std::string> methods;                  ///< methods for this pair; empty: the suite's
};

/// Generated pairs: every seed x noise level of one world type.
struct SuiteSynth {
  std::string world = "indoor";
  std::vector<int64_t> seeds{1};
  std::vector<std::string> noise{"low"};
  double scale = 1.0;
  double grid = 0;                   ///< grid size to match at [m]; 0 = the world's own
  std::vector<std::string> methods;  ///< methods for these pairs (a subset of the suite's); empty: the suite's
};

struct Suite {
  std::string name;
  std::vector<std::string> methods{"tomomap", "fpfh-ransac"};
  std::vector<SuitePair> pairs;
  std::vector<SuiteSynth> synth;
  std::vector<std::string> warnings;  ///< pairs left out (missing files), with the reason
};

/// Parses a suite. Throws InputError as "FILE:LINE:COL: problem" for syntax
/// errors, unknown keys, unknown methods or world types, and bad values. A pair
/// whose map or pose file is missing is left out with a warning, so the rest runs.
Suite loadSuite(const std::string& path);

}  // namespace tomomap::cli
