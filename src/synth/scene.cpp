#include "scene.hpp"

#include <random>

#include "core/matcher.hpp"

namespace tomomap::synth {
namespace {

using V3 = Eigen::Vector3d;
using Rng = std::mt19937_64;

double uniform(Rng& rng, double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(rng); }

/// Splits [0, length] into pieces of random width in [lo, hi]; returns the cut positions including both ends.
std::vector<double> partition(Rng& rng, double length, double lo, double hi) {
  std::vector<double> cuts{0.0};
  while (length - cuts.back() > hi) cuts.push_back(cuts.back() + uniform(rng, lo, hi));
  cuts.push_back(length);
  return cuts;
}

/// Samples a polyline every `step` metres; yaw follows the direction of travel.
void samplePath(const std::vector<Eigen::Vector2d>& path, double z, double step, std::vector<Pose4>& out) {
  for (size_t i = 0; i + 1 < path.size(); ++i) {
    const Eigen::Vector2d d = path[i + 1] - path[i];
    const double len = d.norm();
    if (len < 1e-6) continue;
    const double yaw = std::atan2(d.y(), d.x());
    for (double s = 0; s < len; s += step) {
      const Eigen::Vector2d p = path[i] + d * (s / len);
      out.push_back({p.x(), p.y(), z, yaw});
    }
  }
}

// ---------------------------------------------------------------- indoor
constexpr double kFloorHeight = 3.0, kSlab = 0.2, kWall = 0.15, kDoor = 1.0, kDoorHeight = 2.1;

struct Room {
  double x0, x1, y0, y1;  // interior bounds
  double door_x;          // door centre on the corridor wall
};

/// A wall along x at y = [y0, y1] from x0 to x1, with door gaps (centre x) cut out.
void wallAlongX(World& w, double x0, double x1, double y0, double y1, double z0, std::vector<double> doors) {
  std::sort(doors.begin(), doors.end());
  double x = x0;
  for (double d : doors) {
    w.boxes.push_back({V3(x, y0, z0), V3(d - kDoor / 2, y1, z0 + kFloorHeight)});
    w.boxes.push_back({V3(d - kDoor / 2, y0, z0 + kDoorHeight), V3(d + kDoor / 2, y1, z0 + kFloorHeight)});
    x = d + kDoor / 2;
  }
  w.boxes.push_back({V3(x, y0, z0), V3(x1, y1, z0 + kFloorHeight)});
}

void furnish(World& w, Rng& rng, const Room& r, double z0) {
  const int items = std::uniform_int_distribution<int>(2, 4)(rng);
  for (int i = 0; i < items; ++i) {
    const int kind = std::uniform_int_distribution<int>(0, 3)(rng);
    const double cx = uniform(rng, r.x0 + 0.8, r.x1 - 0.8), cy = uniform(rng, r.y0 + 0.8, r.y1 - 0.8);
    if (kind == 0) {  // table
      const double hx = uniform(rng, 0.4, 0.8), hy = uniform(rng, 0.3, 0.5);
      w.boxes.push_back({V3(cx - hx, cy - hy, z0), V3(cx + hx, cy + hy, z0 + 0.75)});
    } else if (kind == 1) {  // shelf against the far wall (the one away from the door)
      const double len = uniform(rng, 0.8, 1.8), h = uniform(rng, 1.4, 2.2);
      const bool north = r.y0 > 0 && std::abs(r.y1 - cy) < std::abs(cy - r.y0);
      const double y0 = north ? r.y1 - 0.4 : r.y0, y1 = north ? r.y1 : r.y0 + 0.4;
      w.boxes.push_back({V3(cx - len / 2, y0, z0), V3(cx + len / 2, y1, z0 + h)});
    } else if (kind == 2) {  // cabinet
      const double s = uniform(rng, 0.25, 0.45);
      w.boxes.push_back({V3(cx - s, cy - s, z0), V3(cx + s, cy + s, z0 + uniform(rng, 0.8, 1.3))});
    } else {  // round table or plant pot
      w.cylinders.push_back({Eigen::Vector2d(cx, cy), uniform(rng, 0.2, 0.5), z0, z0 + uniform(rng, 0.5, 1.1)});
    }
  }
}

Scene indoorScene(const SceneParams& p) {
  Rng rng(p.seed * 7919 + 17);
  Scene s;
  s.grid = MatchParams{}.grid;  // the matcher's default is the indoor grid
  s.map_resolution = 0.03;
  s.sensor = {24, -0.75, 0.75, 240, 9.0};
  const double W = 24.0 * p.scale, D = 14.0, yc0 = D / 2 - 1.0, yc1 = D / 2 + 1.0;
  World& w = s.world;
  std::vector<std::vector<Room>> floors(2);

  for (int f = 0; f < 2; ++f) {
    const double z0 = f * kFloorHeight;
    w.boxes.push_back({V3(-kWall, -kWall, z0 - kSlab), V3(W + kWall, D + kWall, z0)});  // floor slab
    w.boxes.push_back({V3(-kWall, -kWall, 0), V3(0, D + kWall, 2 * kFloorHeight)});     // west wall
    w.boxes.push_back({V3(W, -kWall, 0), V3(W + kWall, D + kWall, 2 * kFloorHeight)});  // east wall
    w.boxes.push_back({V3(0, -kWall, z0), V3(W, 0, z0 + kFloorHeight)});                // south wall
    w.boxes.push_back({V3(0, D, z0), V3(W, D + kWall, z0 + kFloorHeight)});             // north wall
    for (int side = 0; side < 2; ++side) {  // 0: south rooms, 1: north rooms
      const std::vector<double> cuts = partition(rng, W, 3.0, 5.5);
      std::vector<double> doors;
      for (size_t i = 0; i + 1 < cuts.size(); ++i) {
        Room r{cuts[i] + kWall, cuts[i + 1] - kWall / 2, side ? yc1 + kWall : 0.0, side ? D : yc0 - kWall, 0};
        r.door_x = uniform(rng, r.x0 + kDoor / 2 + 0.2, r.x1 - kDoor / 2 - 0.2);
        doors.push_back(r.door_x);
        if (i > 0) {  // partition wall between rooms
          const double y0 = side ? yc1 : 0.0, y1 = side ? D : yc0;
          w.boxes.push_back({V3(cuts[i] - kWall / 2, y0, z0), V3(cuts[i] + kWall / 2, y1, z0 + kFloorHeight)});
        }
        furnish(w, rng, r, z0);
        floors[static_cast<size_t>(f)].push_back(r);
      }
      if (side == 0)
        wallAlongX(w, 0, W, yc0 - kWall, yc0, z0, doors);
      else
        wallAlongX(w, 0, W, yc1, yc1 + kWall, z0, doors);
    }
    // A few columns in the corridor break its symmetry.
    for (double x = uniform(rng, 2, 6); x < W - 1; x += uniform(rng, 5, 9))
      w.cylinders.push_back({Eigen::Vector2d(x, rng() % 2 ? yc0 + 0.25 : yc1 - 0.25), 0.15, z0, z0 + kFloorHeight});
  }
  w.boxes.push_back({V3(-kWall, -kWall, 2 * kFloorHeight), V3(W + kWall, D + kWall, 2 * kFloorHeight + kSlab)});

  // Map k walks the corridor over its own stretch on both floors, visiting each room it passes.
  const double span = 0.65 * W, yc = (yc0 + yc1) / 2;
  for (int k = 0; k < p.maps; ++k) {
    const double xa = 0.8 + (p.maps > 1 ? k * (W - 1.6 - span) / (p.maps - 1) : 0.0), xb = xa + span;
    std::vector<Pose4> traj;
    for (int f = 0; f < 2; ++f) {
      std::vector<Eigen::Vector2d> path{{xa, yc}};
      std::vector<Room> rooms;
      for (const Room& r : floors[static_cast<size_t>(f)])
        if (r.door_x > xa && r.door_x < xb) rooms.push_back(r);
      std::sort(rooms.begin(), rooms.end(), [](const Room& a, const Room& b) { return a.door_x < b.door_x; });
      for (const Room& r : rooms) {
        path.emplace_back(r.door_x, yc);
        path.emplace_back(r.door_x, (r.y0 + r.y1) / 2);
        path.emplace_back(r.door_x, yc);
      }
      path.emplace_back(xb, yc);
      samplePath(path, f * kFloorHeight + 1.0, 0.4, traj);
    }
    s.trajectories.push_back(std::move(traj));
  }
  return s;
}

// ---------------------------------------------------------------- outdoor
Scene outdoorScene(const SceneParams& p) {
  Rng rng(p.seed * 104729 + 3);
  Scene s;
  s.grid = 0.2;
  s.map_resolution = 0.1;
  s.sensor = {32, -0.44, 0.27, 720, 50.0};
  World& w = s.world;
  const double L = 120.0 * p.scale, half_street = 6.0, sidewalk = 2.5;
  w.ground = {true,
              uniform(rng, 0.2, 0.5),
              uniform(rng, 8, 14),
              uniform(rng, 0.1, 0.3),
              uniform(rng, 6, 10),
              uniform(rng, -0.02, 0.02)};
  const Ground& g = w.ground;

  for (int side = -1; side <= 1; side += 2) {
    // Facades: blocks of varied width, depth, height and setback, with occasional alleys.
    for (double x = -20; x < L + 20;) {
      const double width = uniform(rng, 8, 20);
      if (uniform(rng, 0, 1) < 0.15) {
        x += uniform(rng, 3, 6);
        continue;
      }
      const double setback = uniform(rng, 0, 2.0), depth = uniform(rng, 8, 15), height = uniform(rng, 6, 25);
      const double y_near = side * (half_street + sidewalk + setback), y_far = y_near + side * depth;
      const double base = g.height(x + width / 2, y_near) - 3.0;
      w.boxes.push_back(
          {V3(x, std::min(y_near, y_far), base), V3(x + width - 0.3, std::max(y_near, y_far), base + 3 + height)});
      // A ground-floor canopy or balcony row on some facades.
      if (uniform(rng, 0, 1) < 0.4) {
        const double zc = base + 3 + uniform(rng, 3, 5);
        w.boxes.push_back({V3(x + 1, std::min(y_near, y_near - side * 1.2), zc),
                           V3(x + width - 1.3, std::max(y_near, y_near - side * 1.2), zc + 0.3)});
      }
      x += width;
    }
    // Trees, poles and parked cars along the sidewalk and kerb.
    const double y_walk = side * (half_street + sidewalk * 0.5);
    for (double x = uniform(rng, 0, 8); x < L; x += uniform(rng, 7, 15)) {
      const double z = g.height(x, y_walk);
      if (uniform(rng, 0, 1) < 0.65) {
        const double trunk = uniform(rng, 2.0, 3.5), crown = uniform(rng, 1.2, 2.5);
        w.cylinders.push_back({Eigen::Vector2d(x, y_walk), uniform(rng, 0.12, 0.3), z - 1, z + trunk + crown});
        w.spheres.push_back({V3(x, y_walk, z + trunk + crown), crown});
      } else {
        w.cylinders.push_back({Eigen::Vector2d(x, y_walk), 0.1, z - 1, z + uniform(rng, 5, 8)});
      }
    }
    const double y_car = side * (half_street - 1.2);
    for (double x = uniform(rng, 0, 10); x < L; x += uniform(rng, 6, 25)) {
      const double z = g.height(x, y_car);
      w.boxes.push_back({V3(x, y_car - 0.9, z - 0.5), V3(x + 4.5, y_car + 0.9, z + uniform(rng, 1.4, 1.9))});
    }
  }

  // Map k drives its own stretch of the street, weaving slightly.
  const double span = 0.6 * L;
  for (int k = 0; k < p.maps; ++k) {
    const double xa = 5 + (p.maps > 1 ? k * (L - 10 - span) / (p.maps - 1) : 0.0);
    std::vector<Eigen::Vector2d> path;
    for (double x = xa; x <= xa + span; x += 10) path.emplace_back(x, uniform(rng, -2.5, 2.5));
    std::vector<Pose4> traj;
    samplePath(path, 0, 1.5, traj);
    for (auto& pose : traj) pose.z = g.height(pose.x, pose.y) + 1.8;
    s.trajectories.push_back(std::move(traj));
  }
  return s;
}

// ---------------------------------------------------------------- room
/// What hangs on a lived-in room's walls at every height (shelves, cabinets,
/// radiators, frames): without it the slices above the furniture are bare
/// rectangles, alike at every height and under a half turn.
void hangOnWalls(World& w, Rng& rng, const Room& r, double height) {
  const int items = std::uniform_int_distribution<int>(3, 6)(rng);
  for (int i = 0; i < items; ++i) {
    const double len = uniform(rng, 0.3, 1.2), depth = uniform(rng, 0.08, 0.35);
    const double z0 = uniform(rng, 0.1, height - 0.6), z1 = z0 + uniform(rng, 0.15, 0.6);
    const int wall = std::uniform_int_distribution<int>(0, 3)(rng);  // west, east, south, north
    if (wall < 2) {
      const double y = uniform(rng, r.y0 + len / 2, r.y1 - len / 2), x = wall == 0 ? r.x0 : r.x1 - depth;
      w.boxes.push_back({V3(x, y - len / 2, z0), V3(x + depth, y + len / 2, z1)});
    } else {
      const double x = uniform(rng, r.x0 + len / 2, r.x1 - len / 2), y = wall == 2 ? r.y0 : r.y1 - depth;
      w.boxes.push_back({V3(x - len / 2, y, z0), V3(x + len / 2, y + depth, z1)});
    }
  }
}

/// One furnished room of about 5 x 4.5 x 2.8 m with a partition across about
/// half its depth: each map is scanned from its own side and sees the other
/// side past the partition's end (partial overlap, other viewpoints), as a
/// handheld or small-robot scan of a single room would. Matched at g = 0.1:
/// under 32 slices.
Scene roomScene(const SceneParams& p) {
  Rng rng(p.seed * 6151 + 11);
  Scene s;
  s.grid = 0.1;
  s.map_resolution = 0.02;
  s.sensor = {32, -0.8, 0.8, 360, 8.0};
  World& w = s.world;
  const double W = uniform(rng, 4.5, 6.0) * std::min(p.scale, 2.0), D = uniform(rng, 4.0, 5.0),
               H = uniform(rng, 2.5, 3.0);
  w.boxes.push_back({V3(-kWall, -kWall, -kSlab), V3(W + kWall, D + kWall, 0)});     // floor
  w.boxes.push_back({V3(-kWall, -kWall, H), V3(W + kWall, D + kWall, H + kSlab)});  // ceiling
  w.boxes.push_back({V3(-kWall, -kWall, 0), V3(0, D + kWall, H)});
  w.boxes.push_back({V3(W, -kWall, 0), V3(W + kWall, D + kWall, H)});
  wallAlongX(w, 0, W, -kWall, 0, 0, {uniform(rng, 0.8, W - 0.8)});  // with the room's door
  w.boxes.push_back({V3(0, D, 0), V3(W, D + kWall, H)});
  // The partition: along y, leaving 45-60 % of the depth open at one end.
  const double xp = W * uniform(rng, 0.45, 0.55), opening = uniform(rng, 0.45, 0.6) * D;
  const bool open_north = rng() % 2;
  w.boxes.push_back(
      {V3(xp - kWall / 2, open_north ? 0.0 : opening, 0), V3(xp + kWall / 2, open_north ? D - opening : D, H)});
  const std::vector<Room> halves{{0.0, xp - kWall / 2, 0.0, D, 0}, {xp + kWall / 2, W, 0.0, D, 0}};
  for (const Room& r : halves) {
    furnish(w, rng, r, 0);
    furnish(w, rng, r, 0);
    hangOnWalls(w, rng, r, H);
  }
  // Map k walks 2 m across its half, away from the partition, at hand height.
  for (int k = 0; k < p.maps; ++k) {
    const Room& r = halves[static_cast<size_t>(k % 2)];
    const double x = (r.x0 + r.x1) / 2 + uniform(rng, -0.4, 0.4);
    const double y0 = D / 2 - 1.0 + 0.3 * (k / 2), y1 = y0 + 2.0;
    std::vector<Pose4> traj;
    samplePath({{x, y0}, {x, y1}}, uniform(rng, 1.0, 1.5), 0.2, traj);
    s.trajectories.push_back(std::move(traj));
  }
  return s;
}

}  // namespace

WorldType parseWorldType(const std::string& name) {
  if (name == "indoor") return WorldType::Indoor;
  if (name == "outdoor") return WorldType::Outdoor;
  if (name == "room") return WorldType::Room;
  throw InputError("unknown world type '" + name + "' (use indoor, outdoor or room)");
}

std::string toString(WorldType type) {
  switch (type) {
    case WorldType::Indoor:
      return "indoor";
    case WorldType::Outdoor:
      return "outdoor";
    case WorldType::Room:
      return "room";
  }
  return "?";
}

Scene makeScene(const SceneParams& params) {
  if (params.maps < 1 || params.maps > 64) throw InputError("map count must be between 1 and 64");
  if (!(params.scale >= 0.5 && params.scale <= 20)) throw InputError("world scale must be between 0.5 and 20");
  switch (params.type) {
    case WorldType::Indoor:
      return indoorScene(params);
    case WorldType::Outdoor:
      return outdoorScene(params);
    case WorldType::Room:
      return roomScene(params);
  }
  throw InputError("unknown world type");
}

}  // namespace tomomap::synth
