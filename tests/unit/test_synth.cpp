#include <gtest/gtest.h>

#include <limits>
#include <random>
#include <set>
#include <tuple>

#include "synth/synth.hpp"

using namespace tomomap;
using namespace tomomap::synth;

TEST(World, RayHitsTheNearestSolid) {
  World w;
  w.boxes.push_back({{5, -1, -1}, {6, 1, 1}});
  w.boxes.push_back({{3, -1, -1}, {3.5, 1, 1}});
  w.cylinders.push_back({{0, 8}, 0.5, -1, 1});
  const Eigen::Vector3d o(0, 0, 0);
  const auto near = solidsNear(w, o, 20);
  EXPECT_NEAR(castRay(w, near, o, {1, 0, 0}, 20), 3.0, 1e-9);
  EXPECT_NEAR(castRay(w, near, o, {0, 1, 0}, 20), 7.5, 1e-9);
  EXPECT_TRUE(std::isinf(castRay(w, near, o, {-1, 0, 0}, 20)));
  EXPECT_TRUE(std::isinf(castRay(w, near, o, {1, 0, 0}, 2.0)));  // beyond max range
}

TEST(World, ARayTestingOnlyItsSectorsSolidsFindsTheFirstHitOfAll) {
  // Random boxes, trunks and crowns around sensors inside, beside and on the
  // edge of them: the first hit is the one that testing every solid finds,
  // to the bit.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> at(-6, 6), size(0.05, 3), unit(-1, 1);
  World w;
  for (int k = 0; k < 40; ++k) {
    const Eigen::Vector3d lo(at(rng), at(rng), at(rng) / 3);
    w.boxes.push_back({lo, lo + Eigen::Vector3d(size(rng), size(rng), size(rng))});
  }
  for (int k = 0; k < 10; ++k) w.cylinders.push_back({{at(rng), at(rng)}, size(rng) / 4, -2, 2});
  for (int k = 0; k < 10; ++k) w.spheres.push_back({{at(rng), at(rng), at(rng) / 3}, size(rng) / 2});
  // Every solid under every sector: what a ray tested before the sectors.
  const auto everySolidEverywhere = [&](const Eigen::Vector3d& o) {
    NearbySolids near = solidsNear(w, o, 30);
    NearbySolids::Sector all;
    for (const Box& b : w.boxes) all.boxes.push_back(&b);
    for (const Cylinder& c : w.cylinders) all.cylinders.push_back(&c);
    for (const Sphere& s : w.spheres) all.spheres.push_back(&s);
    near.sectors.assign(near.sectors.size(), all);
    return near;
  };
  std::vector<Eigen::Vector3d> origins{
      w.boxes[0].lo, 0.5 * (w.boxes[1].lo + w.boxes[1].hi),
      Eigen::Vector3d(w.cylinders[0].centre.x() + w.cylinders[0].radius, w.cylinders[0].centre.y(), 0)};
  for (int k = 0; k < 20; ++k) origins.emplace_back(at(rng), at(rng), at(rng) / 3);
  int hits = 0;
  for (const Eigen::Vector3d& o : origins) {
    const NearbySolids near = solidsNear(w, o, 30), all = everySolidEverywhere(o);
    std::vector<Eigen::Vector3d> rays;
    for (int k = 0; k < 400; ++k) {
      Eigen::Vector3d d(unit(rng), unit(rng), unit(rng) / 2);
      if (k % 50 == 0) d = Eigen::Vector3d(0, 0, k % 100 == 0 ? 1 : -1);  // straight up or down
      rays.push_back(d);
    }
    // Rays just inside a solid's outline, near where its span of azimuths
    // ends: by a box's corners and a trunk's sides, half way up.
    for (const Box& b : w.boxes) {
      const Eigen::Vector2d mid = 0.5 * (b.lo + b.hi).head<2>();
      for (const Eigen::Vector2d& corner : {Eigen::Vector2d(b.lo.head<2>()), Eigen::Vector2d(b.hi.head<2>()),
                                            Eigen::Vector2d(b.lo.x(), b.hi.y()), Eigen::Vector2d(b.hi.x(), b.lo.y())}) {
        const Eigen::Vector2d inside = corner + 0.02 * (mid - corner) - o.head<2>();
        rays.emplace_back(inside.x(), inside.y(), 0.5 * (b.lo.z() + b.hi.z()) - o.z());
      }
    }
    for (const Cylinder& c : w.cylinders) {
      const Eigen::Vector2d to = c.centre - o.head<2>();
      if (to.norm() <= c.radius) continue;
      const double side = 0.98 * std::asin(c.radius / to.norm()), along = std::atan2(to.y(), to.x());
      for (const double a : {along - side, along + side})
        rays.emplace_back(std::cos(a), std::sin(a), -o.z() / to.norm());
    }
    for (Eigen::Vector3d d : rays) {
      d.normalize();
      const double t = castRay(w, near, o, d, 30);
      ASSERT_EQ(t, castRay(w, all, o, d, 30)) << "from " << o.transpose() << " along " << d.transpose();
      hits += std::isfinite(t);
    }
  }
  EXPECT_GT(hits, 4000);  // most rays hit something: the comparison is not of misses
}

TEST(World, RayFindsUnevenGround) {
  World w;
  w.ground = {true, 0.3, 5, 0.2, 4, 0.01};
  const Eigen::Vector3d o(0, 0, 2), d = Eigen::Vector3d(1, 0.5, -0.5).normalized();
  const double t = castRay(w, solidsNear(w, o, 50), o, d, 50);
  ASSERT_TRUE(std::isfinite(t));
  const Eigen::Vector3d p = o + t * d;
  EXPECT_NEAR(p.z(), w.ground.height(p.x(), p.y()), 2e-3);
}

static std::set<std::tuple<int, int, int>> cells(const Points& pts, double leaf) {
  std::set<std::tuple<int, int, int>> s;
  for (const auto& p : pts)
    s.insert({static_cast<int>(std::floor(p.x() / leaf)), static_cast<int>(std::floor(p.y() / leaf)),
              static_cast<int>(std::floor(p.z() / leaf))});
  return s;
}

namespace tomomap::synth {
void PrintTo(WorldType t, std::ostream* os) { *os << toString(t); }
}  // namespace tomomap::synth

class SynthWorld : public ::testing::TestWithParam<WorldType> {};

TEST_P(SynthWorld, SameSeedSameMapsAndGroundTruthAlignsThem) {
  SceneParams sp;
  sp.type = GetParam();
  sp.seed = 4;
  const Scene scene = makeScene(sp);
  const auto a = scanScene(scene, noiseLevel("low"), 4);
  const auto b = scanScene(makeScene(sp), noiseLevel("low"), 4);
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(a[1].points.size(), b[1].points.size());
  EXPECT_EQ(a[1].points[1000], b[1].points[1000]);
  EXPECT_TRUE(a[0].pose.isApprox(b[0].pose));
  EXPECT_GT(a[0].points.size(), 50000u);

  // Moved by the ground truth, a good share of the source falls on target cells;
  // moved by the inverse (the classic convention slip), far less does.
  const Pose4 T = Pose4::fromMatrix(a[0].pose * a[1].pose.inverse());
  const double leaf = 2 * scene.grid;
  const auto target = cells(a[0].points, leaf);
  auto overlap = [&](const Pose4& M) {
    size_t hit = 0;
    for (const auto& c : cells(transformPoints(a[1].points, M), leaf)) hit += target.count(c);
    return static_cast<double>(hit) / static_cast<double>(target.size());
  };
  EXPECT_GT(overlap(T), 0.2);
  EXPECT_GT(overlap(T), 2 * overlap(T.inverse()));
}

TEST_P(SynthWorld, OtherSeedOtherWorld) {
  SceneParams a, b;
  a.type = b.type = GetParam();
  a.seed = 1;
  b.seed = 2;
  const Scene sa = makeScene(a), sb = makeScene(b);
  EXPECT_FALSE(sa.world.boxes.back().lo.isApprox(sb.world.boxes.back().lo) &&
               sa.world.boxes.size() == sb.world.boxes.size());
  EXPECT_TRUE(makeScene(a).world.boxes.back().lo.isApprox(sa.world.boxes.back().lo));
}

INSTANTIATE_TEST_SUITE_P(Types, SynthWorld, ::testing::Values(WorldType::Indoor, WorldType::Outdoor, WorldType::Room),
                         [](const auto& p) { return toString(p.param); });

TEST(Synth, BadNamesAreInputErrors) {
  EXPECT_THROW(parseWorldType("forest"), InputError);
  EXPECT_THROW(noiseLevel("extreme"), InputError);
  SceneParams sp;
  sp.maps = 0;
  EXPECT_THROW(makeScene(sp), InputError);
}
