#include "point_cloud2.hpp"

#include <cmath>
#include <cstring>

#include "core/map_check.hpp"

namespace tomomap {
namespace {

/// Reads one coordinate at `p` (host byte order: little-endian here).
double read(const uint8_t* p, uint8_t datatype) {
  if (datatype == kPointFieldFloat32) {
    float v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  double v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

const PointCloud2Layout::Field& coordinate(const PointCloud2Layout& layout, const char* name) {
  for (const auto& f : layout.fields)
    if (f.name == name) {
      if (f.datatype != kPointFieldFloat32 && f.datatype != kPointFieldFloat64)
        throw InputError(std::string("PointCloud2 field ") + name + " has datatype " + std::to_string(f.datatype) +
                         "; coordinates must be FLOAT32 (7) or FLOAT64 (8)");
      return f;
    }
  throw InputError(std::string("PointCloud2 has no field ") + name + " (a map needs x, y and z)");
}

}  // namespace

Points pointsFromCloud2(const PointCloud2Layout& layout, const uint8_t* data, size_t size, size_t* nonfinite) {
  if (layout.is_bigendian) throw InputError("PointCloud2 is big-endian; only little-endian clouds are read");
  const PointCloud2Layout::Field *fx = &coordinate(layout, "x"), *fy = &coordinate(layout, "y"),
                                 *fz = &coordinate(layout, "z");
  for (const auto* f : {fx, fy, fz}) {
    const size_t bytes = f->datatype == kPointFieldFloat32 ? 4 : 8;
    if (f->offset + bytes > layout.point_step)
      throw InputError("PointCloud2 field " + f->name + " at offset " + std::to_string(f->offset) +
                       " lies beyond its point_step of " + std::to_string(layout.point_step) + " bytes");
  }
  const uint64_t row_bytes = static_cast<uint64_t>(layout.width) * layout.point_step;
  if (layout.height > 0 && layout.width > 0 && layout.row_step < row_bytes)
    throw InputError("PointCloud2 row_step " + std::to_string(layout.row_step) +
                     " is shorter than width x point_step (" + std::to_string(row_bytes) + ")");
  const uint64_t needed =
      layout.height == 0 ? 0 : static_cast<uint64_t>(layout.height - 1) * layout.row_step + row_bytes;
  if (needed > size)
    throw InputError("PointCloud2 holds " + std::to_string(size) + " bytes of data; its layout (" +
                     std::to_string(layout.height) + " x " + std::to_string(layout.width) + " points of " +
                     std::to_string(layout.point_step) + " bytes) needs " + std::to_string(needed));
  Points points;
  points.reserve(static_cast<size_t>(layout.height) * layout.width);
  for (uint32_t row = 0; row < layout.height; ++row) {
    const uint8_t* p = data + static_cast<size_t>(row) * layout.row_step;
    for (uint32_t i = 0; i < layout.width; ++i, p += layout.point_step) {
      points.emplace_back(static_cast<float>(read(p + fx->offset, fx->datatype)),
                          static_cast<float>(read(p + fy->offset, fy->datatype)),
                          static_cast<float>(read(p + fz->offset, fz->datatype)));
    }
  }
  // A float64 beyond float's range becomes infinite here, and is dropped with the holes.
  const size_t dropped = dropNonFinite(points);
  if (nonfinite) *nonfinite = dropped;
  return points;
}

}  // namespace tomomap
