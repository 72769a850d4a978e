#pragma once
// A map as ROS 2 carries it: sensor_msgs/PointCloud2's layout (fields at
// offsets within a point, points in rows), read into points. Plain data in,
// so that it is tested without DDS (transport/ros2_node.cpp hands it over).
#include <cstdint>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace tomomap {

/// The parts of a sensor_msgs/PointCloud2 that place its bytes.
struct PointCloud2Layout {
  struct Field {
    std::string name;
    uint32_t offset = 0;
    uint8_t datatype = 0;  ///< sensor_msgs/PointField: FLOAT32 = 7, FLOAT64 = 8 (others are not coordinates)
    uint32_t count = 1;
  };
  uint32_t height = 1, width = 0;  ///< height 1: unorganised
  std::vector<Field> fields;
  bool is_bigendian = false;
  uint32_t point_step = 0, row_step = 0;  ///< [bytes]
};

/// sensor_msgs/PointField's datatypes of coordinates.
constexpr uint8_t kPointFieldFloat32 = 7, kPointFieldFloat64 = 8;

/// The x, y, z of every point of `data` laid out as `layout` says (any other
/// fields, padding and row padding skipped; organised or not). Points with a
/// NaN or infinite coordinate (an organised cloud's holes) are dropped and
/// counted in `nonfinite`. Throws InputError, saying why, for a big-endian
/// cloud, x, y or z missing or not float32 / float64, or data shorter than the
/// layout needs.
Points pointsFromCloud2(const PointCloud2Layout& layout, const uint8_t* data, size_t size, size_t* nonfinite = nullptr);

}  // namespace tomomap
