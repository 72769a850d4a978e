#pragma once
// Generating a synthetic world to files: used by `synth` and by `eval` suites.
#include <functional>
#include <string>
#include <vector>

#include "synth/scan_pairs.hpp"
#include "synth/sequence_pairs.hpp"
#include "synth/synth.hpp"

namespace tomomap::cli {

struct GeneratedWorld {
  double grid = 0;                 ///< grid size to match the maps at [m]
  std::vector<std::string> maps;   ///< DIR/map_N.pcd
  std::vector<std::string> poses;  ///< DIR/map_N-gtpose.txt
  std::vector<size_t> points;      ///< points per map
};

/// Scans the scene and writes map_N.pcd, map_N-gtpose.txt and scene.json into `dir`.
GeneratedWorld writeSynthWorld(const synth::SceneParams& params, const synth::NoiseModel& noise, const std::string& dir,
                               const std::function<void(size_t, size_t)>& progress = {});

/// Cuts the scan in `scan_file` into a pair (synth::makeScanPair) and writes
/// map_0.pcd (target), map_1.pcd (source), their poses and pair.json into `dir`;
/// `name` is set to what the pair is (synth::describe).
GeneratedWorld writeScanPair(const std::string& scan_file, const synth::ScanPairParams& params, const std::string& dir,
                             std::string* name = nullptr);

/// Cuts two robots' maps from a posed sequence (synth::makeSequencePair; `up`
/// from synth::sequenceUp) and writes map_0.pcd (target), map_1.pcd (source),
/// their poses and pair.json into `dir`; `name` is set to what the pair is.
GeneratedWorld writeSequencePair(const std::vector<PosedScan>& scans, const Eigen::Vector3d& up,
                                 const synth::SequencePairParams& params, const std::string& dir,
                                 std::string* name = nullptr);

}  // namespace tomomap::cli
