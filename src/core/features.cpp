#include "features.hpp"

#include <opencv2/features2d.hpp>
#include <utility>

namespace tomomap {

size_t MapFeatures::featureCount() const {
  size_t n = 0;
  for (const auto& s : slices) n += s.keypoints.size();
  return n;
}

Eigen::Vector2d MapFeatures::centre() const {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  for (const auto& s : slices)
    for (const auto& k : s.keypoints) sum += k.cast<double>();
  const size_t n = featureCount();
  return n ? Eigen::Vector2d(sum / static_cast<double>(n)) : sum;
}

MapFeatures extractFeatures(SliceStack stack, const FeatureParams& params) {
  MapFeatures out;
  out.grid = stack.grid.cell;
  out.z_min = stack.grid.z_min;
  out.slice_count = stack.size();
  std::vector<SliceFeatures> per_slice(static_cast<size_t>(stack.size()));

#pragma omp parallel for schedule(dynamic)
  for (int k = 0; k < stack.size(); ++k) {
    if (stack.cells[static_cast<size_t>(k)].empty()) continue;
    // One single-level detector per slice: the images are metric, so there is no
    // scale to search over, and the detector is not thread-safe to share.
    auto orb =
        cv::ORB::create(params.max_features, 1.2f, 1, 31, 0, 2, cv::ORB::HARRIS_SCORE, 31, params.fast_threshold);
    const cv::Mat img = stack.image(k, params.pad);
    std::vector<cv::KeyPoint> kps;
    cv::Mat desc;
    orb->detectAndCompute(img, cv::noArray(), kps, desc);
    if (kps.empty()) continue;
    SliceFeatures& sf = per_slice[static_cast<size_t>(k)];
    sf.index = k;
    sf.descriptors = desc;
    sf.keypoints.reserve(kps.size());
    for (const auto& kp : kps)
      sf.keypoints.push_back(
          stack.grid.toMetres(kp.pt.x - static_cast<float>(params.pad), kp.pt.y - static_cast<float>(params.pad)));
  }
  out.occupancy = std::move(stack);
  for (auto& sf : per_slice)
    if (!sf.keypoints.empty()) out.slices.push_back(std::move(sf));
  return out;
}

}  // namespace tomomap
