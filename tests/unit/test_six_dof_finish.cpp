#include <gtest/gtest.h>

#include <random>

#include "core/six_dof_finish.hpp"
#include "core/voxel_filter.hpp"

using namespace tomomap;

// Named, so that the unity build's other test files' helpers (kGrid, stackOf, moved) do not clash.
namespace six_dof_finish_test {
namespace {

constexpr double kGrid = 0.1;
constexpr double kSpacing = 0.03;  ///< surface sampling [m]: about ten points a cell face

Points moved(const Points& in, const Eigen::Matrix4d& T) {
  Points out;
  out.reserve(in.size());
  for (const auto& q : in) out.push_back((T * q.cast<double>().homogeneous()).head<3>().cast<float>());
  return out;
}

Eigen::Matrix4d rigid(double roll, double pitch, double yaw, const Eigen::Vector3d& t) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  T.topRightCorner<3, 1>() = t;
  return T;
}

/// Samples the parallelogram origin + a * e1 + b * e2 (a, b in [0, 1]) every
/// kSpacing, jittered by a fixed seed so that the samples do not line up with the cells.
void addPatch(Points& out, const Eigen::Vector3d& origin, const Eigen::Vector3d& e1, const Eigen::Vector3d& e2,
              std::mt19937& rng) {
  std::uniform_real_distribution<double> jitter(-0.5 * kSpacing, 0.5 * kSpacing);
  const int n1 = static_cast<int>(std::ceil(e1.norm() / kSpacing)),
            n2 = static_cast<int>(std::ceil(e2.norm() / kSpacing));
  for (int i = 0; i <= n1; ++i)
    for (int j = 0; j <= n2; ++j) {
      const double a = std::clamp((i + jitter(rng) / kSpacing) / n1, 0.0, 1.0);
      const double b = std::clamp((j + jitter(rng) / kSpacing) / n2, 0.0, 1.0);
      out.push_back((origin + a * e1 + b * e2).cast<float>());
    }
}

/// A box's four sides and its top (a box stands on the floor, or floats as a shelf).
void addBox(Points& out, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, std::mt19937& rng) {
  const Eigen::Vector3d d = hi - lo;
  const Eigen::Vector3d X(d.x(), 0, 0), Y(0, d.y(), 0), Z(0, 0, d.z());
  addPatch(out, lo, X, Z, rng);
  addPatch(out, lo + Y, X, Z, rng);
  addPatch(out, lo, Y, Z, rng);
  addPatch(out, lo + X, Y, Z, rng);
  addPatch(out, lo + Z, X, Y, rng);
}

/// Two rooms side by side (14 x 8 m, walls 3 m high, no ceiling, as a scan
/// sees them), joined by a door, with boxes, pillars, a shelf and a ramp at
/// different heights, so that every degree of freedom is fixed by some surface.
Points twoRooms() {
  std::mt19937 rng(7);
  Points p;
  const double h = 3.0;
  addPatch(p, {0, 0, 0}, {14, 0, 0}, {0, 8, 0}, rng);  // floor
  addPatch(p, {0, 0, 0}, {14, 0, 0}, {0, 0, h}, rng);  // outer walls
  addPatch(p, {0, 8, 0}, {14, 0, 0}, {0, 0, h}, rng);
  addPatch(p, {0, 0, 0}, {0, 8, 0}, {0, 0, h}, rng);
  addPatch(p, {14, 0, 0}, {0, 8, 0}, {0, 0, h}, rng);
  addPatch(p, {8, 0, 0}, {0, 3, 0}, {0, 0, h}, rng);  // the wall between, with a door at y 3-4.2, up to 2.2 m
  addPatch(p, {8, 4.2, 0}, {0, 3.8, 0}, {0, 0, h}, rng);
  addPatch(p, {8, 3, 2.2}, {0, 1.2, 0}, {0, 0, h - 2.2}, rng);
  addBox(p, {1, 1, 0}, {2, 1.8, 0.8}, rng);
  addBox(p, {5, 5, 0}, {6.5, 7, 1.2}, rng);
  addBox(p, {3, 5, 0}, {3.4, 5.4, h}, rng);  // pillars
  addBox(p, {12, 1, 0}, {12.3, 1.3, h}, rng);
  addBox(p, {10, 2, 0}, {11, 3.5, 0.5}, rng);
  addBox(p, {11, 6, 1.5}, {12.5, 7.5, 2.0}, rng);             // a shelf
  addPatch(p, {9, 5.5, 0}, {1.5, 0, 0.6}, {0, 1.5, 0}, rng);  // a ramp
  // Walls along the raster's axes would each sit at one phase of the cells, and
  // a cell's centre up to half a cell off its wall; turned, each wall crosses
  // the cells at every phase, as in most maps.
  return moved(p, rigid(0, 0, radians(17), {0.37, -0.21, 0.04}));
}

/// Something else: one long hall with a row of pillars and a low platform.
Points hall() {
  std::mt19937 rng(11);
  Points p;
  addPatch(p, {0, 0, 0}, {20, 0, 0}, {0, 5, 0}, rng);
  addPatch(p, {0, 0, 0}, {20, 0, 0}, {0, 0, 4}, rng);
  addPatch(p, {0, 5, 0}, {20, 0, 0}, {0, 0, 4}, rng);
  for (double x = 1.5; x < 20; x += 2.7) addBox(p, {x, 1.2, 0}, {x + 0.5, 1.7, 4}, rng);
  addBox(p, {4, 3, 0}, {9, 4.5, 0.35}, rng);
  return p;
}

SliceStack stackOf(const Points& p) { return makeSlices(voxelFilter(p, kGrid), kGrid, 1); }

/// The truth the tests move the source by (p_target = T * p_source): a lean of
/// 2.5 degrees the 4-DoF answer cannot take up, plus a yaw and a shift.
const Eigen::Matrix4d kTruth = rigid(radians(2.0), radians(-1.5), radians(25), {1.3, -0.7, 0.25});

/// Where the 4-DoF matcher would leave it: the truth's yaw and shift, 2 cells and a degree off.
Eigen::Matrix4d fourDofStart(const Eigen::Matrix4d& truth) {
  Pose4 p = Pose4::fromMatrix(truth);
  p.x += 0.16;
  p.y -= 0.12;
  p.yaw += radians(1.0);
  return p.matrix();
}

/// The farthest a corner of the source points' bounding box lands from where the truth puts it [m].
double cornerError(const Points& source, const Eigen::Matrix4d& estimate, const Eigen::Matrix4d& truth) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (const auto& q : source) {
    lo = lo.cwiseMin(q.cast<double>());
    hi = hi.cwiseMax(q.cast<double>());
  }
  double worst = 0;
  for (int c = 0; c < 8; ++c) {
    const Eigen::Vector3d corner((c & 1) ? hi.x() : lo.x(), (c & 2) ? hi.y() : lo.y(), (c & 4) ? hi.z() : lo.z());
    worst = std::max(worst, ((estimate - truth) * corner.homogeneous()).norm());
  }
  return worst;
}

double turnError(const Eigen::Matrix4d& a, const Eigen::Matrix4d& b) {
  return Eigen::AngleAxisd(a.topLeftCorner<3, 3>().transpose() * b.topLeftCorner<3, 3>()).angle();
}

/// The angle the truth leans the source's z axis by.
double leanOf(const Eigen::Matrix4d& T) {
  return std::acos(std::clamp((T.topLeftCorner<3, 3>() * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0));
}

void report(const char* what, const SixDofFinish& f) {
  std::cout << what << ": held " << f.held << " (" << f.why_not << "), moved " << f.moved << " m, lean "
            << degrees(f.roll_pitch_corrected) << " deg, inliers " << f.inliers_before << " -> " << f.inliers_after
            << " of " << f.points << ", rms " << f.rms_before / kGrid << " -> " << f.rms_after / kGrid
            << " cells, seen found " << f.seen_found_before << " -> " << f.seen_found_after << ", " << f.iterations
            << " iterations\n";
}

struct Scene {
  Points target_points, source_points;
  SliceStack target, source;
};

/// The two rooms as the target, and as a source moved by kTruth's inverse.
const Scene& rooms() {
  static const Scene s = [] {
    Scene r;
    r.target_points = twoRooms();
    r.source_points = moved(r.target_points, kTruth.inverse());
    r.target = stackOf(r.target_points);
    r.source = stackOf(r.source_points);
    return r;
  }();
  return s;
}

}  // namespace

// The 4-DoF answer 2 cells and a degree off, and 2.5 degrees of lean it cannot
// take up: 0.35 m at the rooms' far corners. The finish lands within half a
// cell everywhere and reads the lean it corrected.
TEST(SixDofFinish, TakesUpTheLeanAFourDofAnswerLeaves) {
  const Scene& s = rooms();
  const Eigen::Matrix4d start = fourDofStart(kTruth);
  const double start_error = cornerError(s.source_points, start, kTruth);
  const SixDofFinish f = finishSixDof(s.target, s.source, start);
  report("rooms", f);
  std::cout << "corner error " << start_error << " -> " << cornerError(s.source_points, f.T_target_source, kTruth)
            << " m, turn error " << degrees(turnError(start, kTruth)) << " -> "
            << degrees(turnError(f.T_target_source, kTruth)) << " deg\n";
  ASSERT_GT(start_error, 3 * kGrid);  // the test starts where the finish has work to do
  ASSERT_TRUE(f.held) << f.why_not;
  EXPECT_LT(cornerError(s.source_points, f.T_target_source, kTruth), 0.5 * kGrid);
  EXPECT_LT(turnError(f.T_target_source, kTruth), radians(0.2));
  EXPECT_NEAR(f.roll_pitch_corrected, leanOf(kTruth), radians(0.2));
  EXPECT_GT(f.inliers_after, f.inliers_before);
  EXPECT_GT(f.moved, 2 * kGrid);
}

// The roles swapped: the target refined onto the source from the start's inverse.
TEST(SixDofFinish, WorksWithTheRolesSwapped) {
  const Scene& s = rooms();
  const Eigen::Matrix4d truth = kTruth.inverse();
  const SixDofFinish f = finishSixDof(s.source, s.target, fourDofStart(kTruth).inverse());
  report("swapped", f);
  ASSERT_TRUE(f.held) << f.why_not;
  EXPECT_LT(cornerError(s.target_points, f.T_target_source, truth), 0.5 * kGrid);
  EXPECT_LT(turnError(f.T_target_source, truth), radians(0.2));
  EXPECT_NEAR(f.roll_pitch_corrected, leanOf(kTruth), radians(0.2));
}

// A source that holds only the first room and the door of the second (x < 9.5
// m): a part of the target, as a peer that has not seen all of it would send.
TEST(SixDofFinish, FinishesAPartlyOverlappingCrop) {
  const Scene& s = rooms();
  Points crop;
  for (const auto& q : s.target_points)
    if (q.x() < 9.5) crop.push_back(q);
  const Eigen::Matrix4d truth = rigid(radians(-1.0), radians(2.5), radians(-40), {-2.0, 1.5, -0.3});
  const Points source_points = moved(crop, truth.inverse());
  const SixDofFinish f = finishSixDof(s.target, stackOf(source_points), fourDofStart(truth));
  report("crop", f);
  ASSERT_TRUE(f.held) << f.why_not;
  EXPECT_LT(cornerError(source_points, f.T_target_source, truth), 0.5 * kGrid);
  EXPECT_LT(turnError(f.T_target_source, truth), radians(0.2));
  EXPECT_NEAR(f.roll_pitch_corrected, leanOf(truth), radians(0.2));
}

TEST(SixDofFinish, RefusesEmptyStacksWithAReason) {
  const Scene& s = rooms();
  const Eigen::Matrix4d start = fourDofStart(kTruth);
  SliceStack hollow = s.source;  // a raster, every slice empty
  for (auto& c : hollow.cells) c.clear();
  using Pair = std::pair<const SliceStack*, const SliceStack*>;
  for (const auto& [target, source] : {Pair{&s.target, &hollow}, Pair{&hollow, &s.target}}) {
    const SixDofFinish f = finishSixDof(*target, *source, start);
    EXPECT_FALSE(f.held);
    EXPECT_FALSE(f.why_not.empty());
    EXPECT_EQ(f.T_target_source, start);
  }
  const SixDofFinish none = finishSixDof(SliceStack{}, SliceStack{}, start);
  EXPECT_FALSE(none.held);
  EXPECT_NE(none.why_not.find("overlap"), std::string::npos) << none.why_not;
  EXPECT_EQ(none.T_target_source, start);
}

/// A finish of a wrong start is no search: it keeps the start, or moves it
/// no farther than a finish may (the decision judged the start, not where a
/// search would have gone), and says why where it keeps it.
void expectStaysNear(const SixDofFinish& f, const Eigen::Matrix4d& start) {
  const SixDofFinishParams bounds;
  EXPECT_LE(f.moved, bounds.max_move_cells * kGrid);
  EXPECT_LE(degrees(turnError(f.T_target_source, start)), degrees(bounds.max_turn));
  if (!f.held) {
    EXPECT_FALSE(f.why_not.empty());
    EXPECT_EQ(f.T_target_source, start);
  }
}

// A wrong 4-DoF answer, 3 m off.
TEST(SixDofFinish, StaysNearAStartThreeMetresOff) {
  const Scene& s = rooms();
  Eigen::Matrix4d start = fourDofStart(kTruth);
  start(0, 3) += 2.4;
  start(1, 3) += 1.8;
  const SixDofFinish f = finishSixDof(s.target, s.source, start);
  report("3 m off", f);
  expectStaysNear(f, start);
  EXPECT_GT(cornerError(s.source_points, f.T_target_source, kTruth), 2.0) << "a 3 m error is not finished away";
}

// Another building entirely (a hall of pillars), set on the rooms' floor where
// a wrong answer would put it: floors alone fit, the rest fits nothing.
TEST(SixDofFinish, StaysNearTheStartOnAnUnrelatedScene) {
  const Scene& s = rooms();
  const Eigen::Matrix4d truth = rigid(radians(1.5), radians(1.0), radians(10), {-2.0, 1.0, 0.0});
  const Eigen::Matrix4d start = fourDofStart(truth);
  const SixDofFinish f = finishSixDof(s.target, stackOf(moved(hall(), truth.inverse())), start);
  report("unrelated", f);
  expectStaysNear(f, start);
}

// The same good start, with a finish allowed to move the cells one cell at
// most: the 0.35 m it needs is past that, so it keeps the start and says why.
TEST(SixDofFinish, KeepsTheStartWhereTheFinishWouldMoveTooFar) {
  const Scene& s = rooms();
  SixDofFinishParams tight;
  tight.max_move_cells = 1.0;
  const Eigen::Matrix4d start = fourDofStart(kTruth);
  const SixDofFinish f = finishSixDof(s.target, s.source, start, tight);
  EXPECT_FALSE(f.held);
  EXPECT_NE(f.why_not.find("moved the cells"), std::string::npos) << f.why_not;
  EXPECT_GT(f.moved, 2 * kGrid);
  EXPECT_EQ(f.T_target_source, start);
}

TEST(SixDofFinish, GivesTheSameAnswerOnOneThreadOrTwo) {
  const Scene& s = rooms();
  SixDofFinishParams serial, threaded;
  threaded.threads = 2;
  const SixDofFinish a = finishSixDof(s.target, s.source, fourDofStart(kTruth), serial);
  const SixDofFinish b = finishSixDof(s.target, s.source, fourDofStart(kTruth), threaded);
  ASSERT_TRUE(a.held) << a.why_not;
  EXPECT_EQ(a.T_target_source, b.T_target_source);
  EXPECT_EQ(a.inliers_after, b.inliers_after);
  EXPECT_EQ(a.iterations, b.iterations);
}

}  // namespace six_dof_finish_test
