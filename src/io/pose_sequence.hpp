#pragma once
// SLAM output as saved to disk: pose files (one keyframe's pose a line) and
// a folder of keyframe scans posed by one.
#include <string>
#include <vector>

#include "core/types.hpp"

namespace tomomap {

/// Reads a pose file as SLAM packages save them, one keyframe a line, told
/// apart by the number of fields: KITTI (12: the 3x4 row-major T_world_body),
/// TUM or FAST-LIO's (8: time x y z qx qy qz qw) and the same without the time
/// (7). Blank lines and lines starting with '#' are skipped. Throws InputError
/// naming the file and line for anything else.
std::vector<Eigen::Matrix4d> loadPoseSequence(const std::string& path);

/// The keyframe scans of `scans_dir` (every .pcd, .ply or .xyz file, in name
/// order with numbers as numbers: SLAM packages number them, padded or not),
/// posed by `pose_file` (one pose a scan, T_world_scan for the scan's own
/// frame: KITTI's published poses are the left camera's, not the LiDAR's).
/// Throws InputError when the counts differ or a scan cannot be read.
std::vector<PosedScan> loadPosedScans(const std::string& scans_dir, const std::string& pose_file);

}  // namespace tomomap
