#pragma once
// Pictures of one match: both maps from above after alignment, and the slice
// pairs that carried the winning height offset with their inlier matches.
#include "canvas.hpp"
#include "core/matcher.hpp"

namespace tomomap::viz {

/// Top-down view of both maps' vertical structure (cells occupied in 3+ slices), the source moved by
/// `T_target_source` (x, y, yaw): target blue, source orange, both dark.
/// `caption` lines go above the picture. Axes in metres of the target frame.
cv::Mat drawOverlay(const SliceStack& target, const SliceStack& source, const Pose4& T_target_source,
                    const std::vector<std::string>& caption);

/// The `count` supporting slice pairs with the most inliers, target left and
/// source right, each mutual descriptor match drawn: green if `T_target_source`
/// maps it within `inlier_cells` grid cells, else not drawn (keypoint grey).
cv::Mat drawSlicePairs(const MapFeatures& target, const MapFeatures& source, const MatchResult& result, int count = 3,
                       double inlier_cells = 3.0);

}  // namespace tomomap::viz
