#pragma once
// Mutual nearest neighbours between two sets of 256-bit binary descriptors.
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

namespace tomomap {

/// Pairs (index in a, index in b) that are each other's nearest neighbour in
/// Hamming distance; ties go to the lower index. Both Mats are N x 32 CV_8U.
/// One pass over the distance matrix gives both directions, where OpenCV's
/// cross-checking BFMatcher runs two full searches: this is the matcher's
/// innermost loop (n_target x n_source slice pairs), so the factor matters.
std::vector<std::pair<int, int>> mutualNearest(const cv::Mat& a, const cv::Mat& b);

}  // namespace tomomap
