#pragma once
// The paper's comparison method: FPFH descriptors on keypoints + RANSAC
// (PCL's SampleConsensusPrerejective), as map-merging tools commonly use it.
// Radii scale with the grid size so that it runs on the same pairs as tomomap.
#include "core/matcher.hpp"
#include "core/types.hpp"

namespace tomomap::baseline {

struct FpfhParams {
  double grid = MatchParams{}.grid;    ///< the pair's grid size g [m]; everything below scales with it
  double keypoint_cells = 2.0;         ///< keypoints and descriptor surface: voxel centroids at this many g
  double normal_radius_cells = 4.0;    ///< normal estimation radius [g]
  double feature_radius_cells = 10.0;  ///< FPFH radius [g]
  double inlier_cells = 3.0;           ///< correspondence distance for RANSAC inliers [g]
  int max_iterations = 50000;
  int threads = 0;  ///< 0 = all cores
};

struct FpfhResult {
  bool converged = false;
  Pose4 T_target_source;  ///< 6-DoF result projected onto x, y, z, yaw
  double inlier_fraction = 0;
  size_t target_keypoints = 0, source_keypoints = 0;
  double describe_seconds = 0;  ///< normals, keypoints and FPFH of both maps
  double ransac_seconds = 0;
};

FpfhResult matchFpfhRansac(const Points& target, const Points& source, const FpfhParams& params);

}  // namespace tomomap::baseline
