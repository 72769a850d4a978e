#pragma once
// Pairs cut from one real scan, the way two robots would see one place: two
// crops that share part of the scan, one of them sparser or noisier (another
// sensor), the source moved by a random 4-DoF transform. The expected answer is
// that transform. Real scans carry what generated worlds lack (surfaces that
// lean, sloping ground, clutter, rings and shadows); this makes them pairs.
#include <cstdint>
#include <string>

#include "synth.hpp"

namespace tomomap::synth {

struct ScanPairParams {
  uint64_t seed = 1;
  /// Share of each crop that the other crop holds too, drawn per seed from
  /// [min_overlap, max_overlap].
  double min_overlap = 0.2, max_overlap = 0.6;
  /// The degraded crop keeps one point in 3-10 (a sparser sensor), or (every
  /// other seed) all its points with this much Gaussian noise per axis [m].
  int min_thinning = 3, max_thinning = 10;
  double noise = 0.02;
  /// The source's move: x and y within +-move_xy, z within +-move_z [m], any yaw.
  double move_xy = 20, move_z = 2;
};

/// What one pair is, for its name and the record beside the maps.
struct ScanPairInfo {
  double overlap = 0;  ///< share of each crop's extent along the cut that the other crop covers too
  double cut_yaw = 0;  ///< direction the scan was cut along [rad]
  int thinning = 1;    ///< 1 in `thinning` points kept in the degraded crop (1: noise instead)
  double noise = 0;    ///< noise added to the degraded crop [m]
  bool target_degraded = false;
  Pose4 move;  ///< applied to the source: p_source = move(p_scan)
};

struct ScanPair {
  SynthMap target, source;  ///< poses in synth's convention: T_target_source = pose_target * pose_source^-1
  ScanPairInfo info;
};

/// Fewer points than this in a cut map is no map to match.
constexpr size_t kMinPointsPerCrop = 1000;

/// A seed whose cut leaves a crop too small to be a map (the scan itself is
/// fine: other seeds cut it). `tomomap eval` skips such a seed and says so.
struct SmallCrop : InputError {
  using InputError::InputError;
};

/// Cuts `scan` (finite points, z up) into an overlapping pair. Deterministic
/// from params.seed. Throws InputError when the scan has too few points to cut,
/// SmallCrop when this seed's cut leaves a crop of too few.
ScanPair makeScanPair(const Points& scan, const ScanPairParams& params);

/// "o35-thin6-src" style: what a reader needs to tell pairs of one scan apart.
std::string describe(const ScanPairInfo& info);

}  // namespace tomomap::synth
