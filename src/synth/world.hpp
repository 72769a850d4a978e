#pragma once
// A procedural world made of simple solids, and ray casting into it.
#include <Eigen/Core>
#include <vector>

namespace tomomap::synth {

struct Box {  ///< axis-aligned solid [m]
  Eigen::Vector3d lo, hi;
};
struct Cylinder {  ///< vertical solid: trunks, poles, columns [m]
  Eigen::Vector2d centre;
  double radius, z0, z1;
};
struct Sphere {  ///< tree crowns [m]
  Eigen::Vector3d centre;
  double radius;
};

/// Smooth uneven ground z = a1 sin(x / l1) + a2 cos(y / l2) + slope * x; absent when a1 = a2 = slope = 0
/// and `enabled` is false (indoor floors are boxes).
struct Ground {
  bool enabled = false;
  double a1 = 0, l1 = 1, a2 = 0, l2 = 1, slope = 0;
  double height(double x, double y) const;
  /// Upper bound of |grad height|, for safe ray marching.
  double maxSlope() const;
};

struct World {
  std::vector<Box> boxes;
  std::vector<Cylinder> cylinders;
  std::vector<Sphere> spheres;
  Ground ground;
};

/// The solids near one sensor position, so a scan tests only what it can
/// reach, each filed under every sector of azimuth it spans from there: a ray
/// can only hit a solid whose outline seen from above it points into, so it
/// tests only its own sector's (the same first hit as testing them all).
struct NearbySolids {
  struct Sector {
    std::vector<const Box*> boxes;
    std::vector<const Cylinder*> cylinders;
    std::vector<const Sphere*> spheres;
  };
  std::vector<Sector> sectors;  ///< kSectors, counter-clockwise from +x
  /// The sector a ray along `dir` points into.
  const Sector& along(const Eigen::Vector3d& dir) const;
};

NearbySolids solidsNear(const World& world, const Eigen::Vector3d& origin, double range);

/// Distance along the unit direction `dir` to the first surface, or +inf if
/// nothing is hit within `max_range`.
double castRay(const World& world, const NearbySolids& near, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
               double max_range);

}  // namespace tomomap::synth
