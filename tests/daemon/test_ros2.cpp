// What a ROS 2 node on the robot sees: the fleet's frames on /tf_static, read
// here by a plain Fast DDS participant with ROS 2's topic and type names and
// QoS, as rclcpp's tf2 listener would.
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

#include "cyclone_reader.hpp"
#include "fleet.hpp"
#include "io/map_io.hpp"
#include "ros2_msgsPubSubTypes.h"

using namespace tomomap;
using namespace tomomap::test;
using namespace std::chrono_literals;
using namespace eprosima::fastdds::dds;

namespace {

/// The ROS 2 discovery settings as rmw_fastrtps_cpp configures Fast DDS for them.
enum class FastDdsRos2 {
  humble_localhost_only,     ///< ROS_LOCALHOST_ONLY=1: UDP on loopback, and shared memory
  jazzy_localhost,           ///< ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST
  jazzy_subnet_static_peer,  ///< SUBNET with ROS_STATIC_PEERS=127.0.0.1
  defaults,                  ///< nothing set (Humble; Jazzy's SUBNET): Fast DDS's defaults
};

/// rmw_fastrtps_cpp's participant settings for `setting`.
DomainParticipantQos fastDdsQos(FastDdsRos2 setting) {
  using eprosima::fastrtps::rtps::IPLocator;
  using eprosima::fastrtps::rtps::Locator_t;
  DomainParticipantQos q;
  Locator_t localhost, multicast;
  IPLocator::setIPv4(localhost, 127, 0, 0, 1);
  IPLocator::setIPv4(multicast, 239, 255, 0, 1);
  auto& builtin = q.wire_protocol().builtin;
  switch (setting) {
    case FastDdsRos2::humble_localhost_only: {
      q.transport().use_builtin_transports = false;
      auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
      udp->interfaceWhiteList.emplace_back("127.0.0.1");
      q.transport().user_transports.push_back(udp);
      q.transport().user_transports.push_back(
          std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
      break;
    }
    case FastDdsRos2::jazzy_localhost: {
      builtin.metatrafficMulticastLocatorList.clear();
      builtin.metatrafficUnicastLocatorList.push_back(Locator_t());
      q.transport().use_builtin_transports = false;
      q.transport().user_transports.push_back(
          std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
      auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
      udp->maxInitialPeersRange = 32;
      q.transport().user_transports.push_back(udp);
      builtin.initialPeersList.push_back(localhost);
      break;
    }
    case FastDdsRos2::jazzy_subnet_static_peer:
      builtin.initialPeersList.push_back(localhost);
      builtin.initialPeersList.push_back(multicast);
      break;
    case FastDdsRos2::defaults:
      break;
  }
  return q;
}

/// A /tf_static reader on `domain` as a ROS 2 node with `setting` reads it,
/// joined late (transient local brings it what was published before).
class TfStaticReader {
 public:
  explicit TfStaticReader(int domain, FastDdsRos2 setting = FastDdsRos2::humble_localhost_only) {
    const DomainParticipantQos q = fastDdsQos(setting);
    participant_ = DomainParticipantFactory::get_instance()->create_participant(domain, q);
    TypeSupport type(new tf2_msgs::msg::dds_::TFMessage_PubSubType());
    type.register_type(participant_);
    EXPECT_EQ(type.get_type_name(), "tf2_msgs::msg::dds_::TFMessage_") << "the name ROS 2 nodes look for";
    Topic* topic = participant_->create_topic("rt/tf_static", type.get_type_name(), TOPIC_QOS_DEFAULT);
    DataReaderQos rq = DATAREADER_QOS_DEFAULT;
    rq.reliability().kind = RELIABLE_RELIABILITY_QOS;
    rq.durability().kind = TRANSIENT_LOCAL_DURABILITY_QOS;
    rq.history().kind = KEEP_LAST_HISTORY_QOS;
    rq.history().depth = 10;
    reader_ = participant_->create_subscriber(SUBSCRIBER_QOS_DEFAULT)->create_datareader(topic, rq);
  }
  ~TfStaticReader() {
    participant_->delete_contained_entities();
    DomainParticipantFactory::get_instance()->delete_participant(participant_);
  }

  /// Takes what arrived; returns the latest message of each publisher.
  const std::map<InstanceHandle_t, tf2_msgs::msg::dds_::TFMessage_>& latest() {
    tf2_msgs::msg::dds_::TFMessage_ msg;
    SampleInfo info;
    while (reader_->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK)
      if (info.valid_data) latest_[info.publication_handle] = msg;
    return latest_;
  }

 private:
  DomainParticipant* participant_ = nullptr;
  DataReader* reader_ = nullptr;
  std::map<InstanceHandle_t, tf2_msgs::msg::dds_::TFMessage_> latest_;
};

}  // namespace

TEST(Ros2, TheFleetsFramesAreOneTreeOnTfStatic) {
  TempDir dir;
  const auto gen = runTomomap("synth -o " + (dir / "world") + " -n 3 --noise low -s 4 --scale 0.5");
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  // A domain of this test's own: the ROS 2 participants find each other by multicast on loopback.
  const int domain = 100 + static_cast<int>(::getpid() % 100);
  Fleet fleet(dir);
  std::vector<AgentSpec> agents;
  for (const char* id : {"alpha", "bravo", "charlie"}) {
    agents.push_back({id, dir / ("world/map_" + std::to_string(agents.size()) + ".pcd")});
    agents.back().extra = "[ros2]\ndomain = " + std::to_string(domain) + "\nframe = \"{agent}_map\"\n";
  }
  for (const auto& a : agents) fleet.start(a, agents);
  const std::vector<std::string> ids{"alpha", "bravo", "charlie"};
  ASSERT_TRUE(fleet.waitForTransforms(ids, 3, 300s)) << fleet.log("alpha") << fleet.log("charlie");
  const auto agreed = fleet.transforms("alpha");
  int reliable = 0;
  for (const auto& [name, t] : agreed) reliable += t["reliable"].get<bool>();
  ASSERT_GE(reliable, 2) << "two reliable links tie three maps into one tree";

  TfStaticReader reader(domain);
  // Every daemon publishes the same tree: wait until each has, as a tree of
  // two links under alpha (the lowest id, the default root).
  ASSERT_TRUE(Fleet::waitFor(
      [&] {
        const auto& got = reader.latest();
        if (got.size() < 3) return false;
        for (const auto& [writer, msg] : got)
          if (msg.transforms().size() != 2) return false;
        return true;
      },
      120s))
      << reader.latest().size() << " publishers heard\n"
      << fleet.log("alpha");

  // The links are the fleet's frame: each map's pose in alpha's (frame.json).
  std::map<std::string, Pose4> placed;
  const auto frame = fleet.readJson("alpha", "frame.json");
  for (const auto& a : frame["agents"]) {
    const auto& T = a["T_reference_agent"];
    placed[a["agent"].get<std::string>() + "_map"] = {T["x"].get<double>(), T["y"].get<double>(), T["z"].get<double>(),
                                                      T["yaw"].get<double>()};
  }
  ASSERT_EQ(placed.size(), 3u) << frame.dump(2);
  for (const auto& [writer, msg] : reader.latest()) {
    std::map<std::string, std::string> parent_of;
    for (const auto& t : msg.transforms()) {
      const std::string parent = t.header().frame_id(), child = t.child_frame_id();
      EXPECT_TRUE(parent_of.emplace(child, parent).second) << child << " has one parent";
      EXPECT_EQ(parent, "alpha_map") << "every map hangs from the root";
      ASSERT_TRUE(placed.count(child)) << child;
      const Pose4& T = placed.at(child);
      const auto& tr = t.transform().translation();
      const auto& q = t.transform().rotation();
      EXPECT_NEAR(tr.x(), T.x, 1e-6);
      EXPECT_NEAR(tr.y(), T.y, 1e-6);
      EXPECT_NEAR(tr.z(), T.z, 1e-6);
      EXPECT_NEAR(q.x(), 0.0, 1e-12);
      EXPECT_NEAR(q.y(), 0.0, 1e-12);
      EXPECT_NEAR(2 * std::atan2(q.z(), q.w()), T.yaw, 1e-6) << "a rotation about z by the yaw";
      EXPECT_NEAR(q.z() * q.z() + q.w() * q.w(), 1.0, 1e-12);
      EXPECT_GT(t.header().stamp().sec(), 1'600'000'000) << "stamped with the wall clock";
    }
    EXPECT_EQ(parent_of.size(), 2u);
  }
  EXPECT_NE(fleet.log("bravo").find("ROS 2: /tf_static holds 2"), std::string::npos) << fleet.log("bravo");
  stopAll(fleet, ids);
}


// The check no one here wrote the other half of: Eclipse Cyclone DDS, the DDS
// of ROS 2's rmw_cyclonedds, with ROS 2's message types from their .msg files,
// configured as rmw_cyclonedds configures it for each discovery setting (and
// Fast DDS as rmw_fastrtps configures it). One
// daemon with `localhost_only = true` (the default) must serve every setting
// that keeps ROS 2 on the robot, the other (`false`) ROS 2's network defaults.
TEST(Ros2, CycloneAndFastDdsNodesReadTfStaticUnderEachDiscoverySettingAndDiagnostics) {
  TempDir dir;
  const auto gen = runTomomap("synth -o " + (dir / "world") + " -n 2 --noise low -s 4 --scale 0.5");
  ASSERT_EQ(gen.exit_code, 0) << gen.output;
  // ROS 2 domains of this test's own (their ports stay below 65536 up to 232).
  const int local_domain = 150 + static_cast<int>(::getpid() % 40), network_domain = local_domain + 40;
  Fleet fleet(dir);
  std::vector<AgentSpec> agents{{"alpha", dir / "world/map_0.pcd"}, {"bravo", dir / "world/map_1.pcd"}};
  agents[0].extra = "[ros2]\ndomain = " + std::to_string(local_domain) + "\nframe = \"{agent}_map\"\n";
  agents[1].extra =
      "[ros2]\ndomain = " + std::to_string(network_domain) + "\nframe = \"{agent}_map\"\nlocalhost_only = false\n";
  for (const auto& a : agents) fleet.start(a, agents);
  const std::vector<std::string> ids{"alpha", "bravo"};
  ASSERT_TRUE(fleet.waitForTransforms(ids, 1, 300s)) << fleet.log("alpha") << fleet.log("bravo");
  const nlohmann::json frame = fleet.readJson("alpha", "frame.json");
  Pose4 bravo;
  bool placed = false;
  for (const auto& a : frame["agents"])
    if (a["agent"] == "bravo")
      bravo = {a["T_reference_agent"]["x"].get<double>(), a["T_reference_agent"]["y"].get<double>(),
               a["T_reference_agent"]["z"].get<double>(), a["T_reference_agent"]["yaw"].get<double>()},
      placed = true;
  ASSERT_TRUE(placed) << frame.dump(2);

  const std::vector<std::pair<Ros2Setting, int>> cases{{kHumbleLocalhostOnly, local_domain},
                                                       {kJazzyLocalhost, local_domain},
                                                       {kJazzySubnetStaticPeer, local_domain},
                                                       {kDefaults, network_domain},
                                                       {kJazzyLocalhost, network_domain}};
  for (const auto& [setting, domain] : cases) {
    SCOPED_TRACE(setting.name + (domain == local_domain ? ", localhost_only = true" : ", localhost_only = false"));
    std::string output;
    const nlohmann::json got = readWithCyclone(setting, "tf_static", domain, "1", output);
    ASSERT_FALSE(got.is_null()) << "nothing on rt/tf_static\n" << output;
    ASSERT_EQ(got["transforms"].size(), 1u) << got.dump();
    const auto& t = got["transforms"][0];
    EXPECT_EQ(t["parent"], "alpha_map");
    EXPECT_EQ(t["child"], "bravo_map");
    EXPECT_NEAR(t["x"].get<double>(), bravo.x, 1e-9);
    EXPECT_NEAR(t["y"].get<double>(), bravo.y, 1e-9);
    EXPECT_NEAR(t["z"].get<double>(), bravo.z, 1e-9);
    EXPECT_NEAR(2 * std::atan2(t["qz"].get<double>(), t["qw"].get<double>()), bravo.yaw, 1e-9);
    EXPECT_EQ(t["qx"].get<double>(), 0.0);
    EXPECT_EQ(t["qy"].get<double>(), 0.0);
    EXPECT_GT(t["sec"].get<int64_t>(), 1'600'000'000) << "stamped with the wall clock";
    // The type hash Jazzy's nodes carry (`ros2 topic info -v /tf_static`): rmw warns on endpoints without it.
    EXPECT_EQ(got["user_data"], "typehash=RIHS01_e369d0f05a23ae52508854b66f6aa0437f3449d652e8cbf22d5abe85d020f087;");
  }

  {
    // OFF cuts a ROS 2 node off from every other process (rmw ignores static
    // peers then): nothing arrives, as for any other publisher; documented.
    SCOPED_TRACE(kJazzyOff.name);
    std::string output;
    EXPECT_TRUE(readWithCyclone(kJazzyOff, "tf_static", local_domain, "1", output, 5).is_null()) << output;
  }

  // The same with Fast DDS on the ROS 2 side, configured as rmw_fastrtps
  // configures it for each setting.
  const std::vector<std::tuple<FastDdsRos2, std::string, int>> fast{
      {FastDdsRos2::humble_localhost_only, kHumbleLocalhostOnly.name, local_domain},
      {FastDdsRos2::jazzy_localhost, kJazzyLocalhost.name, local_domain},
      {FastDdsRos2::jazzy_subnet_static_peer, kJazzySubnetStaticPeer.name, local_domain},
      {FastDdsRos2::defaults, kDefaults.name, network_domain},
      {FastDdsRos2::jazzy_localhost, kJazzyLocalhost.name, network_domain}};
  for (const auto& [setting, name, domain] : fast) {
    SCOPED_TRACE("Fast DDS, " + name +
                 (domain == local_domain ? ", localhost_only = true" : ", localhost_only = false"));
    TfStaticReader reader(domain, setting);
    ASSERT_TRUE(Fleet::waitFor([&] { return !reader.latest().empty(); }, 120s)) << "nothing on rt/tf_static";
    const auto& msg = reader.latest().begin()->second;
    ASSERT_EQ(msg.transforms().size(), 1u);
    const auto& t = msg.transforms()[0];
    EXPECT_EQ(t.child_frame_id(), "bravo_map");
    EXPECT_NEAR(t.transform().translation().x(), bravo.x, 1e-9);
    EXPECT_NEAR(t.transform().translation().y(), bravo.y, 1e-9);
    EXPECT_NEAR(2 * std::atan2(t.transform().rotation().z(), t.transform().rotation().w()), bravo.yaw, 1e-9);
  }

  // /diagnostics, as rqt_robot_monitor reads it: each daemon's health, OK
  // once its peer is up and their pair agreed.
  for (const auto& [id, domain] : {std::pair<std::string, int>{"alpha", local_domain}, {"bravo", network_domain}}) {
    SCOPED_TRACE(id);
    std::string output;
    const nlohmann::json got = readWithCyclone(kJazzyLocalhost, "diagnostics", domain, "pairs agreed=1", output);
    ASSERT_FALSE(got.is_null()) << "no /diagnostics with the pair agreed\n" << output;
    ASSERT_EQ(got["status"].size(), 1u) << got.dump();
    const auto& d = got["status"][0];
    EXPECT_EQ(d["name"], "tomomapd: " + id);
    EXPECT_EQ(d["hardware_id"], id);
    EXPECT_EQ(d["level"], 0) << "OK: " << d.dump();
    EXPECT_EQ(d["values"]["peers up"], "1/1") << d.dump();
    EXPECT_EQ(d["values"]["pair alpha<-bravo"].get<std::string>().rfind("agreed", 0), 0u) << d.dump();
    EXPECT_EQ(d["values"]["inconsistent pairs"], "none");
    EXPECT_EQ(d["values"]["write error"], "none");
    EXPECT_TRUE(d["values"].contains("map tilt [deg]")) << d.dump();
    EXPECT_GT(got["sec"].get<int64_t>(), 1'600'000'000) << "stamped with the wall clock";
  }

  // A peer gone: its daemon's health turns WARN and says why.
  stopAll(fleet, {"bravo"});
  std::string output;
  const nlohmann::json warned = readWithCyclone(kJazzyLocalhost, "diagnostics", local_domain, "peers up=0/1", output);
  ASSERT_FALSE(warned.is_null()) << "alpha never said bravo is down\n" << output;
  EXPECT_EQ(warned["status"][0]["level"], 1) << warned.dump();
  EXPECT_NE(warned["status"][0]["message"].get<std::string>().find("bravo is down"), std::string::npos)
      << warned.dump();
  stopAll(fleet, {"alpha"});
}

namespace {

/// `points` as float32 x, y, z triples in `path`, for cyclone_cloud_publisher.
void writeRawPoints(const std::string& path, const Points& points) {
  std::ofstream out(path, std::ios::binary);
  for (const auto& p : points) out.write(reinterpret_cast<const char*>(p.data()), 3 * sizeof(float));
}

/// Publishes the points in `raw` on `topic` from a Cyclone DDS node kept on
/// this host (Jazzy's LOCALHOST range), as a SLAM package publishes its map;
/// returns once the daemon's readers acknowledged it.
CommandResult publishCloud(int domain, const std::string& topic, const std::string& raw, const char* layout) {
  return runBinary("env", "CYCLONEDDS_URI='" + kJazzyLocalhost.cyclonedds_uri + "' " CYCLONE_CLOUD_PUBLISHER_BIN " " +
                              std::to_string(domain) + " " + topic + " " + raw + " " + layout + " bravo_odom 120");
}

}  // namespace

// A robot whose SLAM publishes its map as sensor_msgs/PointCloud2 (as
// LIO-SAM, FAST-LIO, RTAB-Map do) needs no file: bravo's daemon reads the
// topic, published by a Cyclone DDS node with ROS 2's types, agrees with
// alpha, which reads a file, and after a second message (another layout,
// float64 in two padded rows) agrees again, sending only changed slices.
TEST(Ros2, AMapFromAPointCloud2TopicIsAgreedAndUpdatedLikeAMapFile) {
  REQUIRE_DEMO_ROOM();
  TempDir dir;
  const std::string d = demoRoom() + "/";
  const int domain = 150 + static_cast<int>(::getpid() % 40);
  const std::string topic = "/bravo/slam/map";
  Fleet fleet(dir);
  std::vector<AgentSpec> agents{{"alpha", d + "demo-pcd1.pcd"}, {"bravo", ""}};
  agents[1].extra = "[ros2]\ndomain = " + std::to_string(domain) + "\nmap_topic = \"" + topic + "\"\n";
  for (const auto& a : agents) fleet.start(a, agents);
  ASSERT_TRUE(Fleet::waitFor([&] { return fleet.log("bravo").find("ready:") != std::string::npos; }, 60s))
      << fleet.log("bravo");
  EXPECT_NE(fleet.log("bravo").find("waiting for map ROS 2 topic " + topic), std::string::npos) << fleet.log("bravo");

  const Points original = loadMap(d + "demo-pcd2.pcd");
  writeRawPoints(dir / "v1.xyz32", original);
  const auto first = publishCloud(domain, topic, dir / "v1.xyz32", "xyzi32");
  ASSERT_EQ(first.exit_code, 0) << first.output << fleet.log("bravo");
  ASSERT_TRUE(fleet.waitForTransforms({"alpha", "bravo"}, 1, 120s)) << fleet.log("alpha") << fleet.log("bravo");
  const Pose4 gt = groundTruth(d + "demo-pcd1-gtpose.txt", d + "demo-pcd2-gtpose.txt");
  const auto t1 = fleet.transforms("alpha").at("alpha<-bravo");
  ASSERT_TRUE(t1["reliable"].get<bool>()) << t1.dump(2);
  const PoseError e1 = poseError(poseOf(t1), gt);
  EXPECT_LT(e1.translation, 0.05);
  const auto status = fleet.readJson("bravo", "status.json");
  EXPECT_EQ(status["map"]["path"], "ROS 2 topic " + topic);
  EXPECT_EQ(status["map"]["frame_id"], "bravo_odom");
  const std::string v1 = status["map"]["version"];
  const size_t sent_first = status["sent"]["bytes"];

  // The robot maps a cabinet; its SLAM publishes the map again.
  writeRawPoints(dir / "v2.xyz32", withCabinet(original));
  const auto second = publishCloud(domain, topic, dir / "v2.xyz32", "xyz64");
  ASSERT_EQ(second.exit_code, 0) << second.output << fleet.log("bravo");
  const std::string v2 = waitForReagreement(fleet, {"alpha", "bravo"}, "alpha<-bravo", "bravo", v1, 120s);
  ASSERT_FALSE(v2.empty()) << fleet.log("alpha") << fleet.log("bravo");
  const auto t2 = fleet.transforms("alpha").at("alpha<-bravo");
  ASSERT_TRUE(t2["reliable"].get<bool>()) << t2.dump(2);
  const PoseError e2 = poseError(poseOf(t2), gt);
  EXPECT_LT(e2.translation, 0.05);
  const auto s = fleet.readJson("alpha", "status.json");
  const auto& transfers = s["peers"]["bravo"]["transfers"];
  ASSERT_EQ(transfers.size(), 2u) << s.dump(2);
  EXPECT_GT(transfers[1]["slices_reused"].get<int>(), 0);
  EXPECT_LT(transfers[1]["bytes"].get<size_t>(), transfers[0]["bytes"].get<size_t>()) << transfers.dump(2);
  const size_t sent_total = fleet.readJson("bravo", "status.json")["sent"]["bytes"];
  std::printf(
      "map from %s: first agreed %.4f m, %.5f rad from the truth; after the update %.4f m, %.5f rad; "
      "first transfer %zu B (%d slices), then %zu B (%d of %d slices reused); bravo sent %zu then %zu B\n",
      topic.c_str(), e1.translation, e1.yaw, e2.translation, e2.yaw, transfers[0]["bytes"].get<size_t>(),
      transfers[0]["slices"].get<int>(), transfers[1]["bytes"].get<size_t>(), transfers[1]["slices_reused"].get<int>(),
      transfers[1]["slices"].get<int>(), sent_first, sent_total - sent_first);
  stopAll(fleet, {"alpha", "bravo"});
}
