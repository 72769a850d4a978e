// Which height offset wins, and what counts as another answer against it.
#include <gtest/gtest.h>

#include "core/height_offsets.hpp"

using namespace tomomap;

namespace {

/// A consensus of `support` slice pairs on `T` at `offset`.
OffsetScore score(int offset, size_t support, const Rigid2D& T) {
  OffsetScore s;
  s.offset = offset;
  s.consensus.mean = T;
  for (size_t i = 0; i < support; ++i) s.consensus.supporters.push_back(i);
  s.inlier_sum = 10.0 * static_cast<double>(support);
  return s;
}

const Rigid2D kRight{0.3, {2.0, 1.0}};
const Rigid2D kWrong{0.3 + kPi / 2, {-1.0, 3.0}};

}  // namespace

TEST(HeightOffsets, TheSameTransformAFewSlicesAwayIsTheWinnerSmearedNotAnotherAnswer) {
  const std::vector<OffsetScore> scores{score(0, 30, kRight), score(3, 25, kRight), score(-6, 20, kRight)};
  const OffsetChoice c = pickOffset(scores, MatchParams{}, Eigen::Vector2d::Zero());
  ASSERT_NE(c.best, nullptr);
  EXPECT_EQ(c.best->offset, 0);
  EXPECT_EQ(c.runner_up_support, 0);
}

TEST(HeightOffsets, AnotherTransformAFewSlicesAwayIsAnotherAnswer) {
  // A wrong hypothesis repeated over a few similar slices (small rooms).
  const std::vector<OffsetScore> scores{score(0, 3, kRight), score(1, 3, kWrong), score(4, 2, kWrong)};
  const OffsetChoice c = pickOffset(scores, MatchParams{}, Eigen::Vector2d::Zero());
  ASSERT_NE(c.best, nullptr);
  EXPECT_EQ(c.runner_up_support, 2) << "the next offset is the winner's own neighbour; 4 slices away is not";
  EXPECT_EQ(c.runner_up_offset, 4);
}

TEST(HeightOffsets, FarAwayEvenTheSameTransformIsAnotherAnswer) {
  // Two identical floors: the same x, y and yaw, another height.
  const std::vector<OffsetScore> scores{score(0, 30, kRight), score(80, 29, kRight)};
  const OffsetChoice c = pickOffset(scores, MatchParams{}, Eigen::Vector2d::Zero());
  EXPECT_EQ(c.runner_up_support, 29);
  EXPECT_EQ(c.runner_up_offset, 80);
}

TEST(HeightOffsets, TransformsAreComparedWhereTheSourceIs) {
  // 50 m from the origin a 2 degree yaw difference moves the translation by
  // 1.7 m, yet both put the source within a cell of each other.
  const Eigen::Vector2d centre(50.0, 0.0);
  const Rigid2D a{0.0, {0.0, 0.0}};
  Rigid2D b{radians(2.0), {0.0, 0.0}};
  b.t = a.apply(centre) - b.apply(centre) + b.t;
  const std::vector<OffsetScore> scores{score(0, 10, a), score(4, 8, b)};
  EXPECT_EQ(pickOffset(scores, MatchParams{}, centre).runner_up_support, 0);
  EXPECT_EQ(pickOffset(scores, MatchParams{}, Eigen::Vector2d::Zero()).runner_up_support, 8)
      << "compared at the origin they would look like two answers";
}
