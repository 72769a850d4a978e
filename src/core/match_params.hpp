#pragma once
// Every setting of the matcher, with its default and unit: the one place each
// default is stated (the daemon's [match] table and the tool override fields).
#include <functional>

#include "features.hpp"

namespace tomomap {

struct MatchParams {
  double grid = 0.05;  ///< voxel, pixel and slice size g [m]; 0.05 indoors, 0.2-0.5 outdoors
  FeatureParams features;
  double ransac_threshold_cells = 3.0;  ///< RANSAC inlier distance [grid cells]
  int ransac_iterations = 2000;         ///< upper bound per slice pair
  double ransac_confidence = 0.999;
  int min_matches = 5;                       ///< fewer mutual matches: the slice pair gives no estimate
  double consensus_translation_cells = 5.0;  ///< [grid cells]
  double consensus_yaw = radians(10.0);      ///< [rad]
  /// Descriptive slices each map needs for the features to propose a pose,
  /// and slices a dense search's best pose must hold over to answer on its
  /// second look (candidate_decision.hpp); the margin of slice pairs by which
  /// the indexed search follows a weak winner's rivals (offset_search.cpp).
  int min_support = 3;  ///< [slices]
  int threads = 0;      ///< threads one match uses; 0 = every core
  /// Match every slice pair instead of those at the height offsets a descriptor
  /// index votes for (offset_search.hpp): the same answers, at n^2 cost.
  bool exhaustive = false;
  /// A map whose z axis is farther than this from gravity is levelled (or,
  /// without `level`, refused): its slices would cut walls at a slant. Matched
  /// as it is within: the real scans' floors and roads lie 0.6-3.2 degrees off
  /// their sensors' planes, and the synthetic building tilted 3 degrees is
  /// answered either way (docs/algorithm.md, "Gravity check").
  double max_tilt = radians(3.0);  ///< [rad]
  /// Occupied cells a slice needs to be described, as a share of its raster's
  /// width + height (kSparsestSlice).
  double sparsest_slice = kSparsestSlice;
  /// Level a map tilted beyond max_tilt (turn its up onto z) where the tilt is
  /// measured better than it leans (Tilt::levelable), instead of refusing it.
  bool level = true;
  /// Refine a reliable answer in all six degrees of freedom on the maps'
  /// occupancy (six_dof_finish.hpp): the roll and pitch two imperfectly
  /// levelled maps leave between them.
  bool finish = true;
};

/// Called with (stage name, done, total) as work advances; may be empty.
using Progress = std::function<void(const char*, size_t, size_t)>;

/// The thread count `params` asks for, resolved (0 = every core OpenMP has).
int matchThreads(const MatchParams& params);

}  // namespace tomomap
