#pragma once
// Evaluation suites: TOML files listing map pairs with ground truth, or asking
// `synth` for generated ones.
#include <string>
#include <vector>

#include "core/matcher.hpp"
#include "synth/scan_pairs.hpp"
#include "synth/sequence_pairs.hpp"

namespace tomomap::cli {

struct SuitePair {
  std::string name;
  std::string target, source, gt_target, gt_source;  ///< paths (resolved against the suite's folder)
  double grid = MatchParams{}.grid;                  ///< [m]
  std::string noise = "real";                        ///< noise label for grouping: real data, or the synth level
  std::string family;                                ///< what the pair stands for in the right/refused/wrong table
  std::vector<std::string> methods;                  ///< methods for this pair; empty: the suite's
};

/// Generated pairs: every seed x noise level of one world type.
struct SuiteSynth {
  std::string world = "indoor";
  std::vector<int64_t> seeds{1};
  std::vector<std::string> noise{"low"};
  double scale = 1.0;
  double tilt_deg = 0;               ///< the source map rolled this much (synth --tilt) [deg]
  double grid = 0;                   ///< grid size to match at [m]; 0 = the world's own
  std::vector<std::string> methods;  ///< methods for these pairs (a subset of the suite's); empty: the suite's
};

/// Pairs cut from one real scan (synth/scan_pairs.hpp), one per seed.
struct SuiteScan {
  std::string file;  ///< the scan (resolved against the suite's folder)
  std::string name;  ///< family name; default: the file's stem
  std::vector<int64_t> seeds{1};
  double grid = MatchParams{}.grid;  ///< [m]
  /// The source's largest x, y move [m] (ScanPairParams::move_xy).
  double move = synth::ScanPairParams{}.move_xy;
  std::vector<std::string> methods;  ///< as for [[synth]]
};

/// Two robots' maps cut from one posed SLAM sequence (synth/sequence_pairs.hpp), one pair per seed.
struct SuiteSequence {
  std::string scans;  ///< the folder of keyframe scans (resolved against the suite's folder)
  std::string poses;  ///< their pose file: KITTI, TUM or FAST-LIO's (io/pose_sequence.hpp)
  std::string name;   ///< family name; default: sequenceName(scans)
  std::vector<int64_t> seeds{1};
  double grid = MatchParams{}.grid;  ///< [m]
  bool level = false;                ///< each map levelled instead of leaning as its SLAM saved it
  double turn = 0;  ///< each map levelled, then turned this far [deg] (synth::SequencePairParams::turn_deg)
  double range = synth::SequencePairParams{}.max_range;  ///< each scan's points kept within [m]
  double move = synth::SequencePairParams{}.move_xy;     ///< the source's largest x, y move [m]
  std::vector<std::string> methods;                      ///< as for [[synth]]
};

/// A sequence's name from its scans' folder: the folder's, or its parent's
/// where it is called `scans` (SLAM packages' `NAME/scans` layout).
std::string sequenceName(const std::string& scans);

/// Every method a suite may name: tomomap, and the baselines it is measured
/// against (tomomap-baseline --method).
inline const std::vector<std::string> kEvalMethods{"tomomap", "fpfh-ransac", "paper-consensus"};

struct Suite {
  std::string name;
  std::vector<std::string> methods{"tomomap", "fpfh-ransac"};
  std::vector<SuitePair> pairs;
  std::vector<SuiteSynth> synth;
  std::vector<SuiteScan> scans;
  std::vector<SuiteSequence> sequences;
  std::vector<std::string> warnings;  ///< pairs left out (missing files), with the reason
};

/// Parses a suite. Throws InputError as "FILE:LINE:COL: problem" for syntax
/// errors, unknown keys, unknown methods or world types, and bad values. A pair
/// whose map or pose file (or a scan whose file) is missing is left out with a
/// warning, so the rest runs: real data lives beside the repository, not in it.
Suite loadSuite(const std::string& path);

}  // namespace tomomap::cli
