// Two robots' maps cut from a posed sequence: the ground truth puts every
// point back where the world had it, a leaning map leans as its first
// keyframe did, a levelled one lies level; pose files read as SLAM saves them.
#include <gtest/gtest.h>

#include <fstream>

#include "io/pose_sequence.hpp"
#include "support.hpp"
#include "synth/sequence_pairs.hpp"

using namespace tomomap;
using namespace tomomap::synth;
using tomomap::test::TempDir;

namespace {

/// A floor (z = 0) and two walls (y = +-4), 40 m long, sampled every 5 cm.
Points hall() {
  Points world;
  for (float x = 0; x < 40; x += 0.05f)
    for (float a = -4; a <= 4; a += 0.05f) {
      world.emplace_back(x, a, 0.0f);
      if (a + 4 < 3) {
        world.emplace_back(x, -4.0f, a + 4);
        world.emplace_back(x, 4.0f, a + 4);
      }
    }
  return world;
}

/// A body frame 1.5 m above the floor at x, leaning `lean` about x and turned by `yaw`.
Eigen::Matrix4d keyframe(double x, double lean, double yaw) {
  Eigen::Matrix4d T = Eigen::Matrix4d::Identity();
  T.topLeftCorner<3, 3>() =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(lean, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  T.topRightCorner<3, 1>() = Eigen::Vector3d(x, 0.0, 1.5);
  return T;
}

/// A walk along the hall, each scan the world's points within 12 m seen from its keyframe.
std::vector<PosedScan> walk(double lean) {
  const Points world = hall();
  std::vector<PosedScan> scans;
  for (int k = 0; k < 30; ++k) {
    PosedScan s;
    s.T_world_body = keyframe(1.0 + k, lean, 0.1 * std::sin(k));
    const Eigen::Matrix4d body_world = s.T_world_body.inverse();
    for (const auto& p : world)
      if ((p.cast<double>() - s.T_world_body.topRightCorner<3, 1>()).norm() < 12)
        s.points.push_back((body_world * p.cast<double>().homogeneous()).head<3>().cast<float>());
    scans.push_back(std::move(s));
  }
  return scans;
}

/// Largest distance of a map's points, taken back to the world by its pose, from the hall's surfaces.
double offTheHall(const SynthMap& map) {
  const Eigen::Matrix4d map_world = map.pose.inverse();
  double worst = 0;
  for (const auto& p : map.points) {
    const Eigen::Vector3d w = (map_world * p.cast<double>().homogeneous()).head<3>();
    worst = std::max(worst, std::min(std::abs(w.z()), std::abs(std::abs(w.y()) - 4.0)));
  }
  return worst;
}

}  // namespace

TEST(SequencePairs, TheGroundTruthPutsEveryPointBackAndMapsLeanAsTheirFirstKeyframe) {
  const double lean = radians(6.0);
  const auto scans = walk(lean);
  SequencePairParams params;
  params.max_range = 10;
  const Eigen::Vector3d up = sequenceUp(scans, params);
  EXPECT_LT(degrees(std::acos(up.z())), 0.2) << "the hall's floor is level in the world";
  for (bool level : {false, true})
    for (uint64_t seed : {1, 2, 3}) {
      params.seed = seed;
      params.level = level;
      const SequencePair pair = makeSequencePair(scans, up, params);
      const auto& i = pair.info;
      SCOPED_TRACE(describe(i));
      EXPECT_LE(i.target_first, i.target_last);
      EXPECT_LE(i.source_first, i.source_last);
      EXPECT_LT(i.target_last, scans.size());
      EXPECT_GT(i.overlap(), 0.0);
      EXPECT_LE(i.overlap(), 1.0);
      // A voxel's centre lies within half a cube's diagonal of the surface.
      EXPECT_LT(offTheHall(pair.target), 0.05);
      EXPECT_LT(offTheHall(pair.source), 0.05);
      // Each map's frame is its first keyframe's: as saved (leaning), or at its
      // place and yaw with z up (levelled).
      const Eigen::Matrix4d first = pair.target.pose * scans[i.target_first].T_world_body;
      const Eigen::Matrix4d source_first = scans[i.source_first].T_world_body;
      EXPECT_LT((first.topRightCorner<3, 1>().norm()), 1e-9) << "the first keyframe sits at the map's origin";
      if (!level) {
        EXPECT_TRUE(first.isIdentity(1e-9)) << first;
      }
      const Eigen::Vector3d up_in_map = pair.target.pose.topLeftCorner<3, 3>() * up;
      if (level) {
        EXPECT_NEAR(up_in_map.z(), 1.0, 1e-9);
      }
      // The source: its first keyframe at the move's translation, turned by its yaw.
      const Eigen::Matrix4d moved = pair.source.pose * source_first;
      EXPECT_NEAR(moved(0, 3), i.move.x, 1e-9);
      EXPECT_NEAR(moved(1, 3), i.move.y, 1e-9);
      EXPECT_NEAR(moved(2, 3), i.move.z, 1e-9);
      EXPECT_NEAR(degrees(i.target_lean), level ? 0.0 : 6.0, 0.3);
      EXPECT_NEAR(degrees(i.source_lean), level ? 0.0 : 6.0, 0.3);
      if (level) {  // the floor lies at one height in a levelled map: its lowest points span a voxel (the walls' feet
                    // add a few)
        float lowest = INFINITY;
        for (const auto& p : pair.target.points) lowest = std::min(lowest, p.z());
        size_t floor = 0, near_floor = 0;
        for (const auto& p : pair.target.points) {
          floor += p.z() < lowest + 0.06f;
          near_floor += p.z() < lowest + 0.5f;
        }
        EXPECT_GT(static_cast<double>(floor), 0.9 * static_cast<double>(near_floor));
      }
    }
}

TEST(SequencePairs, ATurnedPairIsTheSamePairWithEachMapLeaningAsTurned) {
  const auto scans = walk(radians(6.0));
  SequencePairParams params;
  params.max_range = 10;
  const Eigen::Vector3d up = sequenceUp(scans, params);
  params.level = true;
  const SequencePair level = makeSequencePair(scans, up, params);
  params.level = false;
  params.turn_deg = 40;
  const SequencePair turned = makeSequencePair(scans, up, params);
  const auto& i = turned.info;
  SCOPED_TRACE(describe(i));
  EXPECT_NE(describe(i).find("-turned40"), std::string::npos);
  EXPECT_EQ(i.target_first, level.info.target_first);
  EXPECT_EQ(i.source_last, level.info.source_last);
  EXPECT_EQ(i.move.yaw, level.info.move.yaw) << "the same pair, turned";
  EXPECT_NEAR(degrees(i.target_lean), 40.0, 1e-6);
  EXPECT_NEAR(degrees(i.source_lean), 40.0, 1e-6);
  EXPECT_LT(offTheHall(turned.target), 0.05) << "the ground truth still puts every point back";
  EXPECT_LT(offTheHall(turned.source), 0.05);
}

TEST(SequencePairs, IsDeterministicFromItsSeedAndRefusesATooShortSequence) {
  const auto scans = walk(0.0);
  SequencePairParams params;
  params.seed = 4;
  const auto a = makeSequencePair(scans, Eigen::Vector3d::UnitZ(), params);
  const auto b = makeSequencePair(scans, Eigen::Vector3d::UnitZ(), params);
  EXPECT_EQ(describe(a.info), describe(b.info));
  EXPECT_EQ(a.source.points.size(), b.source.points.size());
  EXPECT_TRUE(a.source.pose.isApprox(b.source.pose));
  const std::vector<PosedScan> few(scans.begin(), scans.begin() + 5);
  EXPECT_THROW(makeSequencePair(few, Eigen::Vector3d::UnitZ(), params), InputError);
}

TEST(PoseSequence, ReadsKittiAndTumLinesAndNamesTheBadLine) {
  TempDir dir;
  const std::string kitti = dir / "kitti.txt", tum = dir / "tum.txt", bad = dir / "bad.txt";
  std::ofstream(kitti) << "# comment\n1 0 0 1 0 1 0 2 0 0 1 3\n\n0 -1 0 4 1 0 0 5 0 0 1 6\n";
  const auto k = loadPoseSequence(kitti);
  ASSERT_EQ(k.size(), 2u);
  EXPECT_TRUE((k[0].topRightCorner<3, 1>().isApprox(Eigen::Vector3d(1, 2, 3))));
  EXPECT_NEAR(k[1](1, 0), 1.0, 1e-12);
  // TUM: time x y z qx qy qz qw; a quarter turn about z.
  std::ofstream(tum) << "0.5 1 2 3 0 0 0.7071067811865476 0.7071067811865476\n";
  const auto t = loadPoseSequence(tum);
  ASSERT_EQ(t.size(), 1u);
  EXPECT_TRUE((t[0].topRightCorner<3, 1>().isApprox(Eigen::Vector3d(1, 2, 3))));
  EXPECT_NEAR(t[0](1, 0), 1.0, 1e-9);
  std::ofstream(bad) << "1 0 0 1 0 1 0 2 0 0 1 3\n1 0 0 1 0 1 0 2 0 0 1\n";
  try {
    loadPoseSequence(bad);
    FAIL() << "a line of 11 numbers was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.txt:2:"), std::string::npos) << e.what();
  }
  std::ofstream(bad) << "1 0 0 1 0 2 0 2 0 0 1 3\n";
  EXPECT_THROW(loadPoseSequence(bad), InputError) << "a rotation that stretches";
  std::ofstream(bad) << "";
  EXPECT_THROW(loadPoseSequence(bad), InputError) << "no poses";
  EXPECT_THROW(loadPoseSequence(dir / "missing.txt"), InputError);
}
