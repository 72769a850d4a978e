#include <gtest/gtest.h>
#include <octomap/OcTree.h>

#include <sstream>

#include <fstream>

#include "io/map_io.hpp"
#include "io/octomap_io.hpp"
#include "support.hpp"

using namespace tomomap;
using tomomap::test::readText;
using tomomap::test::TempDir;

static Points grid(int n) {
  Points p;
  for (int i = 0; i < n; ++i)
    p.emplace_back(0.1f * static_cast<float>(i % 20), 0.1f * static_cast<float>(i / 20), 0.01f * static_cast<float>(i));
  return p;
}

static void write(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

static std::string pcdHeader(size_t n, const std::string& data) {
  return "# .PCD v0.7\nVERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + std::to_string(n) +
         "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + std::to_string(n) + "\nDATA " + data + "\n";
}

/// Message of the InputError `f` throws, or "" if it throws none.
template <typename F>
static std::string errorOf(F f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MapIo, RoundTripsBinaryAndBinaryCompressedPcd) {
  TempDir dir;
  const Points p = grid(500);
  for (const auto& [data, name] :
       {std::pair{PcdData::binary, "DATA binary\n"}, {PcdData::binary_compressed, "DATA binary_compressed\n"}}) {
    savePcd(dir / "m.pcd", p, data);
    EXPECT_NE(readText(dir / "m.pcd").find(name), std::string::npos) << name;
    const Points q = loadMap(dir / "m.pcd");
    ASSERT_EQ(q.size(), p.size());
    EXPECT_EQ(q[123], p[123]);
  }
}

// Binary PCDs are read by the integrity check's own pass (pcd_check.hpp):
// x, y and z must come out of any record layout, floats or doubles.
TEST(MapIo, BinaryPcdsWithOtherFieldsOrDoublesReadTheirXyz) {
  TempDir dir;
  const Points p = grid(300);
  const auto header = [](const std::string& fields, const std::string& sizes, const std::string& types) {
    return "# .PCD v0.7\nVERSION 0.7\nFIELDS " + fields + "\nSIZE " + sizes + "\nTYPE " + types +
           "\nCOUNT 1 1 1 1\nWIDTH 300\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 300\nDATA binary\n";
  };
  {  // intensity first, then z, x, y: offsets from the header, not the field names' usual order
    std::ofstream out(dir / "i.pcd", std::ios::binary);
    out << header("intensity z x y", "4 4 4 4", "F F F F");
    for (const auto& q : p) {
      const float record[4] = {7.f, q.z(), q.x(), q.y()};
      out.write(reinterpret_cast<const char*>(record), sizeof record);
    }
  }
  {  // doubles, with a 1-byte label between y and z
    std::ofstream out(dir / "d.pcd", std::ios::binary);
    out << header("x y label z", "8 8 1 8", "F F U F");
    for (const auto& q : p) {
      const double x = q.x(), y = q.y(), z = q.z();
      const char label = 3;
      out.write(reinterpret_cast<const char*>(&x), 8).write(reinterpret_cast<const char*>(&y), 8);
      out.write(&label, 1).write(reinterpret_cast<const char*>(&z), 8);
    }
  }
  for (const char* f : {"i.pcd", "d.pcd"}) {
    const Points q = loadMap(dir / f);
    ASSERT_EQ(q.size(), p.size()) << f;
    for (size_t k : {size_t{0}, size_t{123}, size_t{299}}) EXPECT_EQ(q[k], p[k]) << f << " point " << k;
  }
}

TEST(MapIo, ReadsAsciiPcdPlyAndXyz) {
  TempDir dir;
  std::string pcd = pcdHeader(200, "ascii"), ply, xyz = "# x y z\n";
  ply = "ply\nformat ascii 1.0\nelement vertex 200\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  for (const auto& q : grid(200)) {
    const std::string line = std::to_string(q.x()) + " " + std::to_string(q.y()) + " " + std::to_string(q.z()) + "\n";
    pcd += line;
    ply += line;
    xyz += line;
  }
  write(dir / "a.pcd", pcd);
  write(dir / "a.ply", ply);
  write(dir / "a.xyz", xyz);
  for (const char* f : {"a.pcd", "a.ply", "a.xyz"}) {
    const Points q = loadMap(dir / f);
    ASSERT_EQ(q.size(), 200u) << f;
    EXPECT_NEAR(q[199].z(), 1.99f, 1e-5) << f;
  }
}

TEST(MapIo, MissingFileIsNamed) {
  EXPECT_NE(errorOf([] { loadMap("/nonexistent/map.pcd"); }).find("no such file"), std::string::npos);
}

TEST(MapIo, EmptyFileAndEmptyMapAreRejected) {
  TempDir dir;
  write(dir / "empty.pcd", "");
  EXPECT_NE(errorOf([&] { loadMap(dir / "empty.pcd"); }).find("empty"), std::string::npos);
  write(dir / "nopoints.pcd", pcdHeader(0, "ascii"));
  EXPECT_NE(errorOf([&] { loadMap(dir / "nopoints.pcd"); }), "");
}

TEST(MapIo, TinyMapIsRejected) {
  TempDir dir;
  savePcd(dir / "ten.pcd", grid(10));
  EXPECT_NE(errorOf([&] { loadMap(dir / "ten.pcd"); }).find("only 10 points"), std::string::npos);
}

TEST(MapIo, NonFinitePointsAreDroppedAndCounted) {
  TempDir dir;
  std::string xyz;
  for (const auto& q : grid(200))
    xyz += std::to_string(q.x()) + " " + std::to_string(q.y()) + " " + std::to_string(q.z()) + "\n";
  write(dir / "nan.xyz", xyz + "nan 1 2\ninf 0 0\n");
  size_t dropped = 0;
  EXPECT_EQ(loadMap(dir / "nan.xyz", &dropped).size(), 200u);
  EXPECT_EQ(dropped, 2u);
  Points p = grid(200);
  p[7].y() = std::numeric_limits<float>::quiet_NaN();
  savePcd(dir / "nan.pcd", p);
  const Points back = loadMap(dir / "nan.pcd", &dropped);
  EXPECT_EQ(back.size(), 199u);
  EXPECT_EQ(dropped, 1u);
  EXPECT_EQ(back[7], p[8]) << "the rest keep their order";
}

TEST(MapIo, AMapWithTooFewFinitePointsIsRefused) {
  TempDir dir;
  std::string xyz;
  for (const auto& q : grid(50))
    xyz += std::to_string(q.x()) + " " + std::to_string(q.y()) + " " + std::to_string(q.z()) + "\n";
  for (int i = 0; i < 100; ++i) xyz += "nan nan nan\n";
  write(dir / "nan.xyz", xyz);
  EXPECT_NE(errorOf([&] { loadMap(dir / "nan.xyz"); }).find("only 50 of 150 points are finite"), std::string::npos)
      << errorOf([&] { loadMap(dir / "nan.xyz"); });
}

TEST(MapIo, TruncatedAndCorruptPcdAreRejected) {
  TempDir dir;
  savePcd(dir / "good.pcd", grid(5000), PcdData::binary_compressed);  // a garbled payload shows in its LZF
  std::ifstream in(dir / "good.pcd", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), {});
  std::ofstream(dir / "cut.pcd", std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  EXPECT_NE(errorOf([&] { loadMap(dir / "cut.pcd"); }), "");

  std::string garbled = bytes;
  for (size_t i = garbled.find("DATA") + 30; i < garbled.size(); i += 7) garbled[i] = static_cast<char>(0xA5);
  std::ofstream(dir / "garbled.pcd", std::ios::binary) << garbled;
  EXPECT_NE(errorOf([&] { loadMap(dir / "garbled.pcd"); }), "");

  write(dir / "text.pcd", "this is not a point cloud\n");
  EXPECT_NE(errorOf([&] { loadMap(dir / "text.pcd"); }), "");
  write(dir / "short.pcd", pcdHeader(300, "ascii") + "1 2 3\n4 5 6\n");
  EXPECT_NE(errorOf([&] { loadMap(dir / "short.pcd"); }), "");
}

TEST(MapIo, BadXyzLineIsNamed) {
  TempDir dir;
  write(dir / "bad.xyz", "1 2 3\n4 five 6\n");
  EXPECT_NE(errorOf([&] { loadMap(dir / "bad.xyz"); }).find("bad.xyz:2"), std::string::npos);
}

TEST(MapIo, UnknownExtensionIsRejected) {
  TempDir dir;
  write(dir / "map.e57", "x");
  EXPECT_NE(errorOf([&] { loadMap(dir / "map.e57"); }).find("unknown map format"), std::string::npos);
  write(dir / "map.las", "x");
  EXPECT_NE(errorOf([&] { loadMap(dir / "map.las"); }).find("pdal translate"), std::string::npos)
      << "LAS gets a way to convert it";
}

TEST(MapIo, ACsvWithAHeaderLineLoadsAndAHeaderMidFileIsAnError) {
  TempDir dir;
  std::string csv = "//X,Y,Z\n";  // CloudCompare's header
  for (const auto& q : grid(200))
    csv += std::to_string(q.x()) + "," + std::to_string(q.y()) + "," + std::to_string(q.z()) + "\n";
  write(dir / "a.csv", csv);
  EXPECT_EQ(loadMap(dir / "a.csv").size(), 200u);
  write(dir / "b.csv", csv + "X,Y,Z\n");
  EXPECT_NE(errorOf([&] { loadMap(dir / "b.csv"); }).find("b.csv:202: expected 'x y z' numbers"), std::string::npos);
}

TEST(MapIo, AMeshPlyIsReadAsItsVerticesAndSaysSo) {
  TempDir dir;
  std::string ply =
      "ply\nformat ascii 1.0\nelement vertex 200\nproperty float x\nproperty float y\nproperty float z\n"
      "element face 1\nproperty list uchar int vertex_indices\nend_header\n";
  for (const auto& q : grid(200))
    ply += std::to_string(q.x()) + " " + std::to_string(q.y()) + " " + std::to_string(q.z()) + "\n";
  ply += "3 0 1 2\n";
  write(dir / "mesh.ply", ply);
  std::string note;
  EXPECT_EQ(loadMap(dir / "mesh.ply", nullptr, &note).size(), 200u);
  EXPECT_NE(note.find("its 200 vertices are the map, its 1 faces are not used"), std::string::npos) << note;
}

TEST(MapIo, OctomapTreesLoadAsTheirOccupiedVoxels) {
  TempDir dir;
  // A 1 m wall of 0.05 m voxels, 20 x 20 and two thick, and a free cell that must not come back.
  octomap::OcTree tree(0.05);
  for (float i = 0; i < 20; ++i)
    for (float k = 0; k < 20; ++k)
      for (const float y : {0.025f, 0.075f})
        tree.updateNode(octomap::point3d(0.025f + 0.05f * i, y, 0.025f + 0.05f * k), true);
  tree.updateNode(octomap::point3d(0.5f, 0.5f, 0.5f), false);
  tree.prune();  // 2 x 2 x 2 blocks become one leaf: they must come back voxel by voxel
  ASSERT_LT(tree.getNumLeafNodes(), 800u);
  ASSERT_TRUE(tree.writeBinary(dir / "wall.bt"));
  ASSERT_TRUE(tree.write(dir / "wall.ot"));
  for (const char* f : {"wall.bt", "wall.ot"}) {
    const Points p = loadMap(dir / f);
    EXPECT_EQ(p.size(), 800u) << f;
    for (const auto& q : p) {
      EXPECT_TRUE(std::abs(q.y() - 0.025f) < 1e-4f || std::abs(q.y() - 0.075f) < 1e-4f) << f << " " << q.y();
      EXPECT_TRUE(q.x() > 0 && q.x() < 1 && q.z() > 0 && q.z() < 1) << f;
    }
  }
  write(dir / "junk.bt", "# Octomap OcTree binary file\nres 0.05\ndata\n");
  EXPECT_NE(errorOf([&] { loadMap(dir / "junk.bt"); }).find("junk.bt"), std::string::npos);
  write(dir / "text.ot", "not a tree at all\n");
  EXPECT_NE(errorOf([&] { loadMap(dir / "text.ot"); }).find("not a readable OctoMap tree"), std::string::npos);
}

TEST(MapIo, OctomapMessagesReadAsOctomapServerWritesThemBinaryOrFull) {
  // What octomap_msgs's binaryMapToMsg / fullMapToMsg put in the message's data.
  octomap::OcTree tree(0.05);
  for (float i = 0; i < 10; ++i)
    for (float k = 0; k < 10; ++k) tree.updateNode(octomap::point3d(0.025f + 0.05f * i, 0.025f, 0.025f + 0.05f * k), true);
  tree.updateNode(octomap::point3d(0.5f, 0.5f, 0.5f), false);
  const auto bytes = [](const std::string& s) { return std::vector<uint8_t>(s.begin(), s.end()); };
  std::ostringstream binary, full;
  ASSERT_TRUE(tree.writeBinaryData(binary));
  ASSERT_TRUE(tree.writeData(full));
  EXPECT_EQ(octomapFromMessage(true, "OcTree", 0.05, bytes(binary.str())).size(), 100u);
  EXPECT_EQ(octomapFromMessage(false, "OcTree", 0.05, bytes(full.str())).size(), 100u);
  // A truncated message, a tree octomap does not know, a tree that is not occupancy: said, not read.
  const std::string cut = full.str().substr(0, full.str().size() / 2);
  EXPECT_NE(errorOf([&] { octomapFromMessage(false, "OcTree", 0.05, bytes(cut)); }).find("not a tree of type OcTree"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { octomapFromMessage(false, "NoSuchTree", 0.05, bytes(full.str())); }).find("NoSuchTree"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { octomapFromMessage(false, "ColorOcTree", 0.05, bytes(full.str())); }).find("not an OcTree"),
            std::string::npos);
  EXPECT_NE(errorOf([&] { octomapFromMessage(true, "OcTree", 0, bytes(binary.str())); }).find("resolution"),
            std::string::npos);
  // Malicious trees: every child "has children" (octomap's reader would
  // recurse 100,000 levels deep and off the end), as a message and as files.
  const std::string bomb(200'000, '\xff');
  for (const bool is_binary : {true, false}) {
    EXPECT_NE(errorOf([&] { octomapFromMessage(is_binary, "OcTree", 0.05, bytes(bomb)); }).find("below the tree's 16 levels"),
              std::string::npos);
  }
  TempDir dir;
  write(dir / "bomb.bt", "# Octomap OcTree binary file\nres 0.05\ndata\n" + bomb);
  write(dir / "bomb.ot", "# Octomap OcTree file\nid OcTree\nsize 1\nres 0.05\ndata\n" + bomb);
  EXPECT_NE(errorOf([&] { loadMap(dir / "bomb.bt"); }).find("below the tree's 16 levels"), std::string::npos);
  EXPECT_NE(errorOf([&] { loadMap(dir / "bomb.ot"); }).find("below the tree's 16 levels"), std::string::npos);
}

TEST(PoseIo, RoundTripsAndRejectsBadFiles) {
  TempDir dir;
  const Eigen::Matrix4d P = Pose4{1.5, -2, 0.3, 2.9}.matrix();
  savePoseFile(dir / "p.txt", P);
  EXPECT_TRUE(loadPoseFile(dir / "p.txt").isApprox(P, 1e-12));
  write(dir / "short.txt", "1 0 0 0 0 1 0 0 0 0 1\n");
  EXPECT_NE(errorOf([&] { loadPoseFile(dir / "short.txt"); }).find("12 numbers"), std::string::npos);
  write(dir / "word.txt", "1 0 0 0 0 1 0 0 0 0 1 x\n");
  EXPECT_NE(errorOf([&] { loadPoseFile(dir / "word.txt"); }).find("non-number"), std::string::npos);
  write(dir / "skew.txt", "2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_NE(errorOf([&] { loadPoseFile(dir / "skew.txt"); }).find("orthonormal"), std::string::npos);
}
