// Where a map really is: stray returns left out, real structure kept.
#include <gtest/gtest.h>

#include "core/map_bounds.hpp"

using namespace tomomap;

namespace {

/// A 10 x 8 x 3 m box of points every 10 cm on its floor and walls.
Points room() {
  Points p;
  const auto at = [](int i) { return 0.1f * static_cast<float>(i); };
  for (int x = 0; x <= 100; ++x)
    for (int y = 0; y <= 80; ++y) p.emplace_back(at(x), at(y), 0);
  for (int x = 0; x <= 100; ++x)
    for (int z = 0; z <= 30; ++z) {
      p.emplace_back(at(x), 0, at(z));
      p.emplace_back(at(x), 8, at(z));
    }
  return p;
}

}  // namespace

TEST(MapBounds, AStrayPointFarAwayIsLeftOutAndCounted) {
  Points p = room();
  p.emplace_back(110, 4, 1);
  p.emplace_back(5, -60, 1);
  const MapBounds b = robustBounds(p);
  EXPECT_EQ(b.outside, 2u);
  EXPECT_NEAR(b.hi.x(), 10, 1e-4);
  EXPECT_NEAR(b.lo.y(), 0, 1e-4);
  EXPECT_FALSE(b.contains(p.back()));
}

TEST(MapBounds, ACleanMapKeepsItsFullBox) {
  const MapBounds b = robustBounds(room());
  EXPECT_EQ(b.outside, 0u);
  EXPECT_NEAR(b.lo.x(), 0, 1e-4);
  EXPECT_NEAR(b.hi.x(), 10, 1e-4);
  EXPECT_NEAR(b.hi.z(), 3, 1e-4);
}

TEST(MapBounds, AFarStructureWithRealSupportStays) {
  // A second building 30 m away: far, but thousands of points, not strays.
  Points p = room();
  const Points other = room();
  for (const auto& q : other) p.emplace_back(q + Eigen::Vector3f(40, 0, 0));
  const MapBounds b = robustBounds(p);
  EXPECT_EQ(b.outside, 0u);
  EXPECT_NEAR(b.hi.x(), 50, 1e-3);
}

TEST(MapBounds, ANearbyReturnIsNotAStray) {
  Points p = room();
  p.emplace_back(13, 4, 1);  // 3 m out: within kStrayGap
  EXPECT_EQ(robustBounds(p).outside, 0u);
}
