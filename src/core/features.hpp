#pragma once
// ORB features per slice: the compact description of a map that crosses the network.
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>

#include "gravity.hpp"
#include "rigid2d.hpp"
#include "slices.hpp"

namespace tomomap {

struct FeatureParams {
  int max_features = 1000;  ///< best-K ORB keypoints kept per slice
  int fast_threshold = 20;  ///< FAST corner threshold on the 0/255 images
  int pad = 32;  ///< empty border around each slice image [pixels]: >= ORB's edge threshold (31) and its patch and blur
                 ///< reach (about 25)
  bool operator==(const FeatureParams& o) const {
    return max_features == o.max_features && fast_threshold == o.fast_threshold && pad == o.pad;
  }
};

struct SliceFeatures {
  int index = 0;                           ///< slice index within its map (0 = lowest kept slice)
  std::vector<Eigen::Vector2f> keypoints;  ///< map-frame x, y [m]
  cv::Mat descriptors;                     ///< N x 32 CV_8U, 256-bit ORB descriptors
};

/// Everything the matcher needs of one map.
struct MapFeatures {
  double grid = 0;   ///< slice spacing = grid size [m]
  double z_min = 0;  ///< height of slice 0 [m]
  int slice_count = 0;
  std::vector<SliceFeatures> slices;  ///< only slices with features, by increasing index
  /// The slices' occupied cells, when available (always offline; over the network
  /// when the sender ships them). Lets the matcher refine densely; may be empty.
  SliceStack occupancy;
  /// How the map was found to lean before slicing, and whether it was levelled
  /// (turned by tilt.leveling()) first. Where the map was described, as
  /// measured or given; a peer's map has the up it was levelled by (its
  /// announcement's), given.
  Tilt tilt;
  bool leveled = false;
  /// Where the voxel filter's cubes start (voxelFilter's corner), and how many
  /// slices kept an earlier description's features (extractFeatures). Local, not sent.
  Eigen::Vector3f voxel_corner{NAN, NAN, NAN};
  int kept_slices = 0;

  double sliceHeight(int k) const { return z_min + k * grid; }
  /// The up direction, in the map's own frame, its slices are level to: z
  /// where it was sliced as it is.
  Eigen::Vector3d slicedUp() const { return leveled ? tilt.up : Eigen::Vector3d::UnitZ(); }
  size_t featureCount() const;
  Eigen::Vector2d centre() const;  ///< mean x, y of the keypoints [m]
};

/// The z of T_target_source that lays source slice k on target slice k + `offset` [m].
inline double heightShift(const MapFeatures& target, const MapFeatures& source, int offset) {
  return target.sliceHeight(offset) - source.z_min;
}

/// T_target_source of a planar pose `T` at height offset `offset` [slices].
inline Pose4 poseAt(const Rigid2D& T, int offset, const MapFeatures& target, const MapFeatures& source) {
  return {T.t.x(), T.t.y(), heightShift(target, source, offset), wrapAngle(T.yaw)};
}

/// The ORB detector for one slice image: a single level, as the images are
/// metric and there is no scale to search over. Not thread-safe to share.
cv::Ptr<cv::ORB> sliceDetector(const FeatureParams& params);

/// Detects ORB on every non-empty slice, in parallel over slices on `threads`
/// threads (0: every core). The stack moves into the result's `occupancy`
/// (pass a copy to keep your own). With `previous` (described with the same
/// `params`), a slice whose raster and cells are its slice's there takes that
/// slice's features instead: ORB would find the very same.
MapFeatures extractFeatures(SliceStack stack, const FeatureParams& params = {}, int threads = 0,
                            const MapFeatures* previous = nullptr);

}  // namespace tomomap
