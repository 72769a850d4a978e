#include "world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace tomomap::synth {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double hitBox(const Box& b, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  double t0 = 0, t1 = kInf;
  for (int a = 0; a < 3; ++a) {
    if (std::abs(d[a]) < 1e-12) {
      if (o[a] < b.lo[a] || o[a] > b.hi[a]) return kInf;
      continue;
    }
    double ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
    if (t0 > t1) return kInf;
  }
  return t0 > 1e-9 ? t0 : kInf;  // a sensor inside a solid sees nothing of it
}

double hitCylinder(const Cylinder& c, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const double ox = o.x() - c.centre.x(), oy = o.y() - c.centre.y();
  const double a = d.x() * d.x() + d.y() * d.y();
  if (a < 1e-12) return kInf;
  const double b = ox * d.x() + oy * d.y(), cc = ox * ox + oy * oy - c.radius * c.radius;
  const double disc = b * b - a * cc;
  if (disc < 0) return kInf;
  const double t = (-b - std::sqrt(disc)) / a;
  if (t <= 1e-9) return kInf;
  const double z = o.z() + t * d.z();
  return (z >= c.z0 && z <= c.z1) ? t : kInf;
}

double hitSphere(const Sphere& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  const Eigen::Vector3d oc = o - s.centre;
  const double b = oc.dot(d), c = oc.squaredNorm() - s.radius * s.radius;
  const double disc = b * b - c;
  if (disc < 0) return kInf;
  const double t = -b - std::sqrt(disc);
  return t > 1e-9 ? t : kInf;
}

// Sphere tracing against a heightfield with bounded slope: each step is the
// vertical clearance divided by how fast the ray can close it.
double hitGround(const Ground& g, const Eigen::Vector3d& o, const Eigen::Vector3d& d, double max_range) {
  const double horizontal = std::hypot(d.x(), d.y());
  const double closing = std::max(1e-3, -d.z() + g.maxSlope() * horizontal);
  double t = 0;
  for (int i = 0; i < 200 && t < max_range; ++i) {
    const Eigen::Vector3d p = o + t * d;
    const double gap = p.z() - g.height(p.x(), p.y());
    if (gap < 1e-3) return t;
    t += std::max(gap / closing, 1e-3);
  }
  return kInf;
}

}  // namespace

double Ground::height(double x, double y) const { return a1 * std::sin(x / l1) + a2 * std::cos(y / l2) + slope * x; }

double Ground::maxSlope() const { return std::abs(a1 / l1) + std::abs(a2 / l2) + std::abs(slope); }

NearbySolids solidsNear(const World& world, const Eigen::Vector3d& origin, double range) {
  NearbySolids n;
  const Eigen::Vector2d o = origin.head<2>();
  for (const auto& b : world.boxes) {
    const Eigen::Vector2d closest = o.cwiseMax(b.lo.head<2>()).cwiseMin(b.hi.head<2>());
    if ((closest - o).norm() <= range) n.boxes.push_back(&b);
  }
  for (const auto& c : world.cylinders)
    if ((c.centre - o).norm() - c.radius <= range) n.cylinders.push_back(&c);
  for (const auto& s : world.spheres)
    if ((s.centre.head<2>() - o).norm() - s.radius <= range) n.spheres.push_back(&s);
  return n;
}

double castRay(const World& world, const NearbySolids& near, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
               double max_range) {
  double best = max_range;
  for (const Box* b : near.boxes) best = std::min(best, hitBox(*b, origin, dir));
  for (const Cylinder* c : near.cylinders) best = std::min(best, hitCylinder(*c, origin, dir));
  for (const Sphere* s : near.spheres) best = std::min(best, hitSphere(*s, origin, dir));
  if (world.ground.enabled) best = std::min(best, hitGround(world.ground, origin, dir, best));
  return best < max_range ? best : kInf;
}

}  // namespace tomomap::synth
