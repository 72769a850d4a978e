#include "world.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/types.hpp"

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

namespace {

/// Sectors of azimuth around a sensor: a degree each, so that a room's wall
/// seen from inside it spans few of them, and a ray tests a few solids.
constexpr int kSectors = 360;
constexpr double kSectorWidth = 2 * kPi / kSectors;  // [rad]
/// A solid's outline within this of the sensor (seen from above) surrounds
/// it for every ray [m]; its span is widened by kPad [rad] each way. Both far
/// beyond rounding: the sectors only ever hold more solids than can be hit.
constexpr double kTouching = 1e-6, kPad = 1e-7;

/// The sector an azimuth [rad] (any turn) falls in, as an unwrapped count.
long sectorCount(double azimuth) { return std::lround(std::floor(azimuth / kSectorWidth)); }
size_t wrapSector(long k) { return static_cast<size_t>(((k % kSectors) + kSectors) % kSectors); }

/// Files `solid` under every sector that azimuths [from, to] (to >= from) touch.
template <class T>
void fileUnder(std::vector<NearbySolids::Sector>& sectors, std::vector<const T*> NearbySolids::Sector::*list,
               const T* solid, double from, double to) {
  const long first = sectorCount(from - kPad), last = std::min(sectorCount(to + kPad), first + kSectors - 1);
  for (long k = first; k <= last; ++k) (sectors[wrapSector(k)].*list).push_back(solid);
}

/// Files a solid whose outline seen from above is the disc at `centre` of
/// `radius`, seen from `o`: every sector if the disc holds o.
template <class T>
void fileDisc(std::vector<NearbySolids::Sector>& sectors, std::vector<const T*> NearbySolids::Sector::*list,
              const T* solid, const Eigen::Vector2d& centre, double radius, const Eigen::Vector2d& o) {
  const Eigen::Vector2d to = centre - o;
  const double distance = to.norm();
  if (distance <= radius + kTouching) return fileUnder(sectors, list, solid, 0.0, 2 * kPi);
  const double middle = std::atan2(to.y(), to.x()), half = std::asin(radius / distance);
  fileUnder(sectors, list, solid, middle - half, middle + half);
}

}  // namespace

const NearbySolids::Sector& NearbySolids::along(const Eigen::Vector3d& dir) const {
  return sectors[wrapSector(sectorCount(std::atan2(dir.y(), dir.x())))];
}

NearbySolids solidsNear(const World& world, const Eigen::Vector3d& origin, double range) {
  NearbySolids n;
  n.sectors.resize(kSectors);
  const Eigen::Vector2d o = origin.head<2>();
  for (const auto& b : world.boxes) {
    const Eigen::Vector2d lo = b.lo.head<2>(), hi = b.hi.head<2>();
    const Eigen::Vector2d closest = o.cwiseMax(lo).cwiseMin(hi);
    if ((closest - o).norm() > range) continue;
    if ((closest - o).cwiseAbs().maxCoeff() <= kTouching) {
      fileUnder(n.sectors, &NearbySolids::Sector::boxes, &b, 0.0, 2 * kPi);
      continue;
    }
    // Seen from outside, a rectangle spans less than a half turn, and its
    // centre's direction lies within that span: its corners' bearings from
    // that direction bound it.
    const Eigen::Vector2d mid = 0.5 * (lo + hi) - o;
    const double middle = std::atan2(mid.y(), mid.x());
    double from = 0, to = 0;
    for (const Eigen::Vector2d& corner : {lo, hi, Eigen::Vector2d(lo.x(), hi.y()), Eigen::Vector2d(hi.x(), lo.y())}) {
      const Eigen::Vector2d c = corner - o;
      const double off = std::remainder(std::atan2(c.y(), c.x()) - middle, 2 * kPi);
      from = std::min(from, off), to = std::max(to, off);
    }
    fileUnder(n.sectors, &NearbySolids::Sector::boxes, &b, middle + from, middle + to);
  }
  for (const auto& c : world.cylinders)
    if ((c.centre - o).norm() - c.radius <= range)
      fileDisc(n.sectors, &NearbySolids::Sector::cylinders, &c, c.centre, c.radius, o);
  for (const auto& s : world.spheres)
    if ((s.centre.head<2>() - o).norm() - s.radius <= range)
      fileDisc(n.sectors, &NearbySolids::Sector::spheres, &s, Eigen::Vector2d(s.centre.head<2>()), s.radius, o);
  return n;
}

double castRay(const World& world, const NearbySolids& near, const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
               double max_range) {
  double best = max_range;
  const NearbySolids::Sector& sector = near.along(dir);
  for (const Box* b : sector.boxes) best = std::min(best, hitBox(*b, origin, dir));
  for (const Cylinder* c : sector.cylinders) best = std::min(best, hitCylinder(*c, origin, dir));
  for (const Sphere* s : sector.spheres) best = std::min(best, hitSphere(*s, origin, dir));
  if (world.ground.enabled) best = std::min(best, hitGround(world.ground, origin, dir, best));
  return best < max_range ? best : kInf;
}

}  // namespace tomomap::synth
