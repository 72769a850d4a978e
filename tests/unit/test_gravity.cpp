// How far a map leans from gravity, and what the matcher does about it.
#include <gtest/gtest.h>

#include <random>

#include "core/gravity.hpp"
#include "core/matcher.hpp"
#include "support.hpp"

using namespace tomomap;

namespace {

/// A furnished 6 x 5 x 2.8 m room: floor, ceiling, four walls and a table top,
/// points every 3 cm with 1 cm of noise. With `leaning_walls`, each wall leans
/// 1.5-3 degrees its own way, as walls of real reconstructions do.
Points furnishedRoom(bool leaning_walls = false) {
  std::mt19937 rng(7);
  std::normal_distribution<float> noise(0.0f, 0.01f);
  Points p;
  const auto plane = [&](const Eigen::Vector3f& o, const Eigen::Vector3f& u, const Eigen::Vector3f& v) {
    const float step = 0.03f;
    for (float a = 0; a <= u.norm(); a += step)
      for (float b = 0; b <= v.norm(); b += step)
        p.push_back(o + a * u.normalized() + b * v.normalized() + Eigen::Vector3f(noise(rng), noise(rng), noise(rng)));
  };
  const Eigen::Vector3f X(6, 0, 0), Y(0, 5, 0), Z(0, 0, 2.8f);
  const auto up = [&](double deg, const Eigen::Vector3f& about) -> Eigen::Vector3f {
    if (!leaning_walls) return Z;
    return Eigen::AngleAxisf(static_cast<float>(radians(deg)), about.normalized()) * Z;
  };
  plane({0, 0, 0}, X, Y);
  plane({0, 0, 2.8f}, X, Y);
  plane({0, 0, 0}, X, up(2.5, X));
  plane({0, 5, 0}, X, up(-1.5, X));
  plane({0, 0, 0}, Y, up(-2.0, Y));
  plane({6, 0, 0}, Y, up(3.0, Y));
  plane({2, 2, 0.75f}, {1.2f, 0, 0}, {0, 0.8f, 0});
  return p;
}

/// The furnished room with `posts` upright posts across it (10 cm thick, as
/// tall as the room): the lines a hall's posts, trunks and door frames give.
Points roomWithPosts(int posts) {
  Points p = furnishedRoom();
  for (int k = 0; k < posts; ++k) {
    const Eigen::Vector2f at(1.0f + 4.0f * static_cast<float>(k % 3) / 2.0f, k < 3 ? 1.0f : 4.0f);
    for (float z = 0.03f; z < 2.8f; z += 0.03f)
      for (int a = 0; a < 8; ++a) {
        const float t = static_cast<float>(a) * 0.785398f;
        p.emplace_back(at.x() + 0.05f * std::cos(t), at.y() + 0.05f * std::sin(t), z);
      }
  }
  return p;
}

Eigen::Quaterniond lean(double deg, const Eigen::Vector3d& axis) {
  return Eigen::Quaterniond(Eigen::AngleAxisd(radians(deg), axis.normalized()));
}

}  // namespace

TEST(Gravity, ALevelRoomReadsLevel) {
  const Tilt t = estimateTilt(furnishedRoom(), 0.05);
  ASSERT_TRUE(t.measured);
  EXPECT_LT(degrees(t.angle), 0.2);
  EXPECT_GT(t.floor_patches, 20u);
  EXPECT_GT(t.wall_patches, 20u);
}

TEST(Gravity, LeaningWallsOnALevelFloorReadLevel) {
  // Real reconstructions' walls lean 1-3 degrees while their floors lie level;
  // weighed like floors, such walls read a level room 2.1-2.5 degrees tilted.
  const Tilt t = estimateTilt(furnishedRoom(true), 0.05);
  ASSERT_TRUE(t.measured);
  EXPECT_EQ(t.cue, Tilt::Cue::floors);
  EXPECT_LT(degrees(t.angle), 0.2);
  EXPECT_LT(degrees(t.uncertainty), 0.2);
}

TEST(Gravity, RealScansReadNearTheirGroundAndAreMatchedAsTheyAre) {
  // The floor of an RGB-D room and the roads under two vehicle LiDARs, 1-3
  // degrees off their sensors' planes by plane fits: a map within max_tilt
  // is neither levelled nor refused.
  const std::vector<std::pair<std::string, double>> scans = {
      {"sunrgbd-000017.pcd", 0.05}, {"nuscenes-lidar-top.pcd", 0.2}, {"kitti-000008.pcd", 0.2}};
  for (const auto& [file, grid] : scans) {
    const std::string path = test::realScans() + "/" + file;
    if (!std::filesystem::exists(path)) GTEST_SKIP() << "real scans not found at " << test::realScans();
    MatchParams params;
    params.grid = grid;
    const MapFeatures f = describeMap(loadMap(path), params);
    ASSERT_TRUE(f.tilt.measured) << file;
    EXPECT_EQ(f.tilt.cue, Tilt::Cue::floors) << file;
    EXPECT_GT(degrees(f.tilt.angle), 0.5) << file;
    EXPECT_LT(degrees(f.tilt.angle), degrees(params.max_tilt)) << file;
    // Read off the map's parts (measured where a decision reads them: here
    // by estimateTilt alone): the nuScenes sweep's halves read 1.5 and 4.0 deg.
    EXPECT_LT(degrees(estimateTilt(loadMap(path), grid).uncertainty), 3.5) << file;
    EXPECT_FALSE(f.leveled) << file;
    EXPECT_FALSE(tiltRefusal(f, "target", params)) << file;
  }
}

TEST(Gravity, ALeaningRoomReadsItsLeanAndLevellingUndoesIt) {
  for (const double deg : {1.0, 3.0, 10.0, 25.0}) {
    const Eigen::Quaterniond q = lean(deg, {1, 0.4, 0});
    const Points leaning = rotatePoints(furnishedRoom(), q);
    const Tilt t = estimateTilt(leaning, 0.05);
    ASSERT_TRUE(t.measured) << deg;
    EXPECT_NEAR(degrees(t.angle), deg, 0.2) << deg;
    // Levelled, the map's floor faces z again.
    EXPECT_LT(degrees(estimateTilt(rotatePoints(leaning, t.leveling()), 0.05).angle), 0.2) << deg;
    // The levelling rotation adds no yaw: it is the lean undone.
    EXPECT_LT(degrees((t.leveling() * q).angularDistance(Eigen::Quaterniond::Identity())), 0.3) << deg;
  }
}

TEST(Gravity, BeyondTheFloorsConeAMapIsLevelledOnlyWhereItsLinesStandAlongUp) {
  // Beyond kClassCone a map's walls may pass for floors: it is levelled where
  // its lines (here six posts) stand along the up read, refused without them.
  for (const double deg : {35.0, 42.0}) {
    const Eigen::Quaterniond q = lean(deg, {1, 0.4, 0});
    const Tilt posts = estimateTilt(rotatePoints(roomWithPosts(6), q), 0.05);
    ASSERT_TRUE(posts.measured) << deg;
    EXPECT_NEAR(degrees(posts.angle), deg, 0.3) << deg;
    EXPECT_TRUE(posts.linesStand()) << deg << ": " << posts.standing_lines << " of " << posts.lines;
    EXPECT_TRUE(posts.levelable()) << deg << ": " << leanText(posts);
    const Tilt bare = estimateTilt(rotatePoints(furnishedRoom(), q), 0.05);
    ASSERT_TRUE(bare.measured) << deg;
    EXPECT_NEAR(degrees(bare.angle), deg, 0.3) << deg;
    EXPECT_LT(bare.lines, kMinLines) << deg;
    EXPECT_FALSE(bare.levelable()) << deg << ": nothing tells its floors from its walls";
  }
  // Turned 50-55 degrees, its floors lie beyond kMaxLevelable and a wall
  // nearer z reads as them: its posts lie across that up.
  for (const double deg : {50.0, 55.0}) {
    MapFeatures f;
    f.tilt = estimateTilt(rotatePoints(roomWithPosts(6), lean(deg, {1, 0, 0})), 0.05);
    ASSERT_TRUE(f.tilt.measured) << deg;
    EXPECT_NEAR(degrees(f.tilt.angle), 90 - deg, 0.5) << deg << ": a wall read";
    EXPECT_GE(f.tilt.lines, kMinLines) << deg;
    EXPECT_FALSE(f.tilt.levelable()) << deg << ": " << f.tilt.standing_lines << " of " << f.tilt.lines;
    const auto refused = tiltRefusal(f, "target", MatchParams{});
    ASSERT_TRUE(refused) << deg;
    EXPECT_NE(refused->find("lines stand along that up"), std::string::npos) << *refused;
  }
}

TEST(Gravity, AFewScatteredPointsAreNotMeasured) {
  Points p;
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 20.0f);
  for (int i = 0; i < 2000; ++i) p.emplace_back(u(rng), u(rng), u(rng));
  EXPECT_FALSE(estimateTilt(p, 0.05).measured);
}

TEST(Matcher, ATiltNotMeasuredBetterThanItLeansIsMatchedAsItIs) {
  // A lean read no better than it is (its uncertainty: how far the map's
  // parts read from the whole) is matched as it is; a map is refused beyond
  // the levelling limit, or, with levelling off (the daemon), surely beyond
  // the tolerance.
  const auto map = [](double deg, double uncertainty_deg) {
    MapFeatures f;
    f.tilt.measured = true;
    f.tilt.angle = radians(deg);
    f.tilt.uncertainty = radians(uncertainty_deg);
    f.tilt.beyond_cone = f.tilt.angle > kClassCone;  // as estimateTilt reads it
    return f;
  };
  const MatchParams params;  // matched as it is up to 3 deg
  EXPECT_FALSE(map(4.6, 5.0).tilt.levelable());
  EXPECT_TRUE(map(7.5, 4.0).tilt.levelable()) << "levelled, it leans at most 4 deg where it leaned 7.5";
  EXPECT_FALSE(tiltRefusal(map(4.6, 5.0), "target", params)) << "not measured better than it leans: as it is";
  EXPECT_FALSE(tiltRefusal(map(25.0, 26.0), "target", params));
  const auto far = tiltRefusal(map(50, 1), "source", params);
  ASSERT_TRUE(far) << "beyond what is ever levelled";
  EXPECT_NE(far->find("too far to level (limit 45 deg)"), std::string::npos) << *far;
  // Beyond kClassCone, where a wall may pass for a floor, the map's lines tell.
  MapFeatures standing = map(40, 1), lying = map(40, 1), bare = map(40, 1);
  standing.tilt.lines = lying.tilt.lines = 30;
  standing.tilt.standing_lines = 25;
  lying.tilt.standing_lines = 3;
  bare.tilt.lines = bare.tilt.standing_lines = 5;
  EXPECT_TRUE(standing.tilt.levelable());
  standing.leveled = true;  // as describeMap levels it
  EXPECT_FALSE(tiltRefusal(standing, "source", params));
  standing.leveled = false;
  const auto side = tiltRefusal(lying, "source", params), unknown = tiltRefusal(bare, "source", params);
  ASSERT_TRUE(side && unknown) << "its walls may have been read as floors";
  EXPECT_NE(side->find("only 3 of its 30 lines stand along that up"), std::string::npos) << *side;
  EXPECT_NE(unknown->find("5 lines, too few"), std::string::npos) << *unknown;
  MapFeatures half = map(40, 1);
  half.tilt.lines = 20;
  half.tilt.standing_lines = 10;
  EXPECT_FALSE(half.tilt.linesStand()) << "half of them is not most";
  // Its lines standing but its parts reading it further apart than it
  // leans: not matched as it is, as a map within the cone would be.
  MapFeatures loose = standing;
  loose.tilt.uncertainty = radians(41);
  const auto unsure = tiltRefusal(loose, "source", params);
  ASSERT_TRUE(unsure) << "a map leaning 40 deg is not matched as it is";
  EXPECT_NE(unsure->find("not measured better than it leans"), std::string::npos) << *unsure;
  MatchParams no_level;
  no_level.level = false;
  EXPECT_TRUE(tiltRefusal(map(5.0, 0.1), "source", no_level)) << "surely tilted, levelling off";
  EXPECT_FALSE(tiltRefusal(map(4.6, 3.5), "source", no_level)) << "may lie within 3 deg";
}

TEST(Matcher, ATiltedMapIsLevelledOrWithoutLevellingRefused) {
  REQUIRE_DEMO_ROOM();
  const auto demo = test::loadDemoPair();
  const Eigen::Quaterniond q = lean(5.0, {1, 0, 0});
  const Points rolled = rotatePoints(demo.map2, q);

  MatchParams no_level;
  no_level.level = false;
  const MatchResult refused = matchMaps(demo.map1, rolled, no_level);
  EXPECT_FALSE(refused.reliable);
  EXPECT_NE(refused.reason.find("source map is tilted"), std::string::npos) << refused.reason;
  EXPECT_NEAR(degrees(refused.source_tilt), 5.0, 1.0);

  const MatchResult r = matchMaps(demo.map1, rolled, MatchParams{});  // levelled by default
  ASSERT_TRUE(r.reliable) << r.reason;
  ASSERT_TRUE(r.T_target_source_6dof.has_value());
  // p1 = T_1_2 p2 and p2 = q^-1 p_rolled: the answer must be T_1_2 q^-1.
  Eigen::Matrix4d unroll = Eigen::Matrix4d::Identity();
  unroll.topLeftCorner<3, 3>() = q.inverse().toRotationMatrix();
  const Eigen::Matrix4d expected = demo.T_1_2.matrix() * unroll, got = r.matrix();
  EXPECT_LT((got.topRightCorner<3, 1>() - expected.topRightCorner<3, 1>()).norm(), 0.1);
  EXPECT_LT(
      degrees(Eigen::AngleAxisd(Eigen::Matrix3d(got.topLeftCorner<3, 3>().transpose() * expected.topLeftCorner<3, 3>()))
                  .angle()),
      1.0);
}

TEST(Gravity, AKnownUpIsTakenAsItIsAndLevelsTheMapWhateverItLeans) {
  for (const double deg : {1.0, 12.0}) {
    const Eigen::Quaterniond q = lean(deg, {1, 0.4, 0});
    const Points leaning = rotatePoints(furnishedRoom(), q);
    const Eigen::Vector3d up = q * Eigen::Vector3d::UnitZ();
    MatchParams params;
    params.grid = 0.05;
    const MapFeatures f = describeMap(leaning, params, nullptr, nullptr, nullptr, up * 3.0);  // any length
    EXPECT_EQ(f.tilt.cue, Tilt::Cue::given) << deg;
    EXPECT_NEAR(degrees(f.tilt.angle), deg, 1e-9) << deg;
    EXPECT_EQ(f.tilt.uncertainty, 0.0) << deg;
    EXPECT_TRUE(f.leveled) << deg << ": levelled below max_tilt too: a known up has no error";
    EXPECT_LT(degrees((f.tilt.leveling() * q).angularDistance(Eigen::Quaterniond::Identity())), 1e-6) << deg;
  }
  EXPECT_THROW(givenTilt(Eigen::Vector3d::Zero()), InputError);
  EXPECT_THROW(givenTilt(Eigen::Vector3d(NAN, 0, 1)), InputError);
}
