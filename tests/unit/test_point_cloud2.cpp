// A map as ROS 2's sensor_msgs/PointCloud2 carries it, read into points.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>

#include "io/point_cloud2.hpp"

using namespace tomomap;

namespace {

/// A cloud of `points` laid out with x, y, z of `datatype` at offsets
/// `first`, `first + w`, `first + 2w`, `point_step` bytes a point, in `rows`
/// rows each padded by `row_pad` bytes.
std::pair<PointCloud2Layout, std::vector<uint8_t>> cloud(const std::vector<Eigen::Vector3d>& points, uint8_t datatype,
                                                         uint32_t first, uint32_t point_step, uint32_t rows,
                                                         uint32_t row_pad) {
  PointCloud2Layout l;
  const uint32_t w = datatype == kPointFieldFloat32 ? 4 : 8;
  l.fields = {{"intensity", 0, kPointFieldFloat32, 1},
              {"x", first, datatype, 1},
              {"y", first + w, datatype, 1},
              {"z", first + 2 * w, datatype, 1}};
  l.height = rows;
  l.width = static_cast<uint32_t>(points.size()) / rows;
  l.point_step = point_step;
  l.row_step = l.width * point_step + row_pad;
  std::vector<uint8_t> data(static_cast<size_t>(l.height) * l.row_step, 0xAB);
  for (size_t i = 0; i < points.size(); ++i) {
    uint8_t* p = data.data() + (i / l.width) * l.row_step + (i % l.width) * point_step + first;
    for (int k = 0; k < 3; ++k) {
      if (datatype == kPointFieldFloat32) {
        const float v = static_cast<float>(points[i][k]);
        std::memcpy(p + 4 * k, &v, 4);
      } else {
        const double v = points[i][k];
        std::memcpy(p + 8 * k, &v, 8);
      }
    }
  }
  return {l, data};
}

const std::vector<Eigen::Vector3d> kPoints{{1, 2, 3}, {-4.5, 5.25, 0.125}, {7, NAN, 9}, {1e3, -1e3, 2}};

}  // namespace

TEST(PointCloud2, EveryLayoutOfFloatCoordinatesIsRead) {
  // float32 after an intensity field; float64 in two organised rows with padding.
  for (const auto& [datatype, first, step, rows, pad] :
       {std::tuple{kPointFieldFloat32, 4u, 16u, 1u, 0u}, {kPointFieldFloat64, 8u, 40u, 2u, 12u}}) {
    SCOPED_TRACE(static_cast<int>(datatype));
    const auto [layout, data] = cloud(kPoints, datatype, first, step, rows, pad);
    size_t nonfinite = 0;
    const Points p = pointsFromCloud2(layout, data.data(), data.size(), &nonfinite);
    ASSERT_EQ(p.size(), 3u) << "the hole (NaN) dropped";
    EXPECT_EQ(nonfinite, 1u);
    EXPECT_EQ(p[0], Eigen::Vector3f(1, 2, 3));
    EXPECT_EQ(p[1], Eigen::Vector3f(-4.5f, 5.25f, 0.125f));
    EXPECT_EQ(p[2], Eigen::Vector3f(1e3f, -1e3f, 2));
  }
}

TEST(PointCloud2, WhatCannotBeAMapIsRefusedWithTheReason) {
  const auto [good, data] = cloud(kPoints, kPointFieldFloat32, 4, 16, 1, 0);
  const auto why = [&](const PointCloud2Layout& l, size_t size) -> std::string {
    try {
      pointsFromCloud2(l, data.data(), size);
    } catch (const InputError& e) {
      return e.what();
    }
    return "(read)";
  };
  PointCloud2Layout l = good;
  l.is_bigendian = true;
  EXPECT_NE(why(l, data.size()).find("big-endian"), std::string::npos);
  l = good;
  l.fields.pop_back();
  EXPECT_NE(why(l, data.size()).find("no field z"), std::string::npos);
  l = good;
  l.fields[1].datatype = 5;  // INT32
  EXPECT_NE(why(l, data.size()).find("must be FLOAT32 (7) or FLOAT64 (8)"), std::string::npos);
  l = good;
  l.fields[3].offset = 14;
  EXPECT_NE(why(l, data.size()).find("beyond its point_step"), std::string::npos);
  EXPECT_NE(why(good, data.size() - 1).find("needs 64"), std::string::npos) << why(good, data.size() - 1);
  l = good;
  l.row_step = 10;
  EXPECT_NE(why(l, data.size()).find("row_step"), std::string::npos);
}
