#include <gtest/gtest.h>

#include <random>

#include "core/features.hpp"

using namespace tomomap;

namespace {

/// A slice stack on a 10 x 10 m raster at 0.05 m whose two slices each hold
/// random wall segments in one corner only, so each slice's occupied area is
/// a small part of the raster.
SliceStack cornerWalls() {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> at(0.f, 3.f);
  Points p{{0, 0, 0}, {10, 10, 0.05f}};  // the raster's extent
  for (int k = 0; k < 2; ++k)
    for (int wall = 0; wall < 80; ++wall) {
      const Eigen::Vector2f a(at(rng), at(rng)), b(at(rng), at(rng));
      const Eigen::Vector2f offset = k == 0 ? Eigen::Vector2f(0.5f, 0.5f) : Eigen::Vector2f(6.5f, 6.0f);
      for (float t = 0; t <= 1.f; t += 0.005f) {
        const Eigen::Vector2f q = offset + a + t * (b - a);
        p.emplace_back(q.x(), q.y(), 0.05f * static_cast<float>(k));
      }
    }
  SliceStack s = makeSlices(p, 0.05);
  s.cells.resize(2);
  return s;
}

}  // namespace

TEST(Features, TheOccupiedAreaGivesTheWholeRastersKeypointsAndDescriptors) {
  const SliceStack stack = cornerWalls();
  FeatureParams params;
  params.max_features = 30;  // fewer than the corners found (54): which are kept matters too
  const MapFeatures f = extractFeatures(stack, params);
  ASSERT_EQ(f.slices.size(), 2u);
  for (const SliceFeatures& s : f.slices) {
    const cv::Rect area = stack.occupiedArea(s.index);
    EXPECT_LT(area.area(), stack.grid.width * stack.grid.height / 4) << "the test needs slices smaller than the raster";
    // The reference: ORB on the whole raster, as every slice was described before.
    std::vector<cv::KeyPoint> kps;
    cv::Mat desc;
    sliceDetector(params)->detectAndCompute(stack.image(s.index, params.pad), cv::noArray(), kps, desc);
    ASSERT_EQ(kps.size(), 30u);
    ASSERT_EQ(s.keypoints.size(), kps.size());
    EXPECT_EQ(cv::norm(s.descriptors, desc, cv::NORM_HAMMING), 0.0);
    for (size_t i = 0; i < kps.size(); ++i) {
      const Eigen::Vector2f expected = stack.grid.toMetres(kps[i].pt.x - static_cast<float>(params.pad),
                                                           kps[i].pt.y - static_cast<float>(params.pad));
      ASSERT_EQ(s.keypoints[i], expected) << "keypoint " << i << " of slice " << s.index;
    }
  }
}

TEST(Features, AnAreaOfTheRasterRendersThatAreaPadded) {
  const SliceStack stack = cornerWalls();
  const cv::Rect area = stack.occupiedArea(1);
  const cv::Mat whole = stack.image(1, 4), part = stack.image(1, area, 4);
  EXPECT_EQ(part.size(), cv::Size(area.width + 8, area.height + 8));
  EXPECT_EQ(cv::countNonZero(part), static_cast<int>(stack.cells[1].size()));
  EXPECT_EQ(cv::norm(part, whole(cv::Rect(area.x, area.y, area.width + 8, area.height + 8)), cv::NORM_L1), 0.0);
}
