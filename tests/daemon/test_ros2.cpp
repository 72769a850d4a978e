// What a ROS 2 node on the robot sees: the fleet's frames on /tf_static, read
// here by a plain Fast DDS participant with ROS 2's topic and type names and
// QoS, as rclcpp's tf2 listener would.
#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <map>

#include "fleet.hpp"
#include "ros2_tfPubSubTypes.h"

using namespace tomomap;
using namespace tomomap::test;
using namespace std::chrono_literals;
using namespace eprosima::fastdds::dds;

namespace {

/// A /tf_static reader on `domain`, joined late (transient local brings it
/// what was published before), on loopback and shared memory like the daemon.
class TfStaticReader {
 public:
  explicit TfStaticReader(int domain) {
    DomainParticipantQos q;
    q.transport().use_builtin_transports = false;
    auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
    udp->interfaceWhiteList.emplace_back("127.0.0.1");
    q.transport().user_transports.push_back(udp);
    q.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
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
