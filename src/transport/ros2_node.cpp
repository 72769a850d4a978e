#include "ros2_node.hpp"

#include <fastdds/rtps/transport/UDPv4TransportDescriptor.h>
#include <fastdds/rtps/transport/shared_mem/SharedMemTransportDescriptor.h>
#include <fastrtps/utils/IPLocator.h>

#include <deque>
#include <fastdds/dds/domain/DomainParticipant.hpp>
#include <fastdds/dds/domain/DomainParticipantFactory.hpp>
#include <fastdds/dds/publisher/DataWriter.hpp>
#include <fastdds/dds/publisher/Publisher.hpp>
#include <fastdds/dds/subscriber/DataReader.hpp>
#include <fastdds/dds/subscriber/DataReaderListener.hpp>
#include <fastdds/dds/subscriber/SampleInfo.hpp>
#include <fastdds/dds/subscriber/Subscriber.hpp>
#include <fastdds/dds/topic/TypeSupport.hpp>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>

#include "ros2_msgsPubSubTypes.h"
#include "ros2_type_hash.hpp"

namespace tomomap::transport {

using namespace eprosima::fastdds::dds;
namespace ros_tf = tf2_msgs::msg::dds_;
namespace ros_geometry = geometry_msgs::msg::dds_;
namespace ros_diagnostic = diagnostic_msgs::msg::dds_;
namespace ros_sensor = sensor_msgs::msg::dds_;
namespace ros_nav = nav_msgs::msg::dds_;
namespace ros_octomap = octomap_msgs::msg::dds_;

const char* rosTypeName(MapMessageType type) {
  return type == MapMessageType::Octomap ? "octomap_msgs/msg/Octomap" : "sensor_msgs/msg/PointCloud2";
}

/// ROS 2's names: topic "rt/" + the ROS topic name.
constexpr const char* kTfStaticTopic = "rt/tf_static";
constexpr const char* kDiagnosticsTopic = "rt/diagnostics";
constexpr const char* kFleetMapTopic = "rt/fleet_map";
constexpr const char* kFleetGridTopic = "rt/fleet_map_grid";

/// builtin_interfaces/Time for `ms` [ms since the epoch].
builtin_interfaces::msg::dds_::Time_ rosTime(uint64_t ms) {
  builtin_interfaces::msg::dds_::Time_ t;
  t.sec(static_cast<int32_t>(ms / 1000));
  t.nanosec(static_cast<uint32_t>(ms % 1000) * 1000000u);
  return t;
}

/// ROS 2's reliable, keep-last-1 endpoints (static transforms, diagnostics,
/// latched maps), with `durability`. Memory the size of each sample, not of
/// the largest: a map may be tens of MB.
template <class EndpointQos>
EndpointQos reliableKeepLast1(EndpointQos q, DurabilityQosPolicyKind durability) {
  q.reliability().kind = RELIABLE_RELIABILITY_QOS;
  q.durability().kind = durability;
  q.history().kind = KEEP_LAST_HISTORY_QOS;
  q.history().depth = 1;
  q.endpoint().history_memory_policy = eprosima::fastrtps::rtps::DYNAMIC_REUSABLE_MEMORY_MODE;
  return q;
}

/// geometry_msgs/Quaternion of a rotation, w >= 0 (of the two, the turn of at most half a circle).
ros_geometry::Quaternion_ rosQuaternion(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond r(R);
  if (r.w() < 0) r.coeffs() *= -1.0;
  ros_geometry::Quaternion_ q;
  q.x(r.x());
  q.y(r.y());
  q.z(r.z());
  q.w(r.w());
  return q;
}

/// sensor_msgs/PointField's FLOAT32 and UINT32 (sensor_msgs/msg/PointField.msg).
constexpr uint8_t kFloat32 = 7, kUint32 = 6;

/// A map message as it arrived, undecoded.
MapMessage mapMessageOf(ros_sensor::PointCloud2_& msg) {
  MapMessage m;
  m.layout.height = msg.height();
  m.layout.width = msg.width();
  m.layout.is_bigendian = msg.is_bigendian();
  m.layout.point_step = msg.point_step();
  m.layout.row_step = msg.row_step();
  for (const auto& f : msg.fields()) m.layout.fields.push_back({f.name(), f.offset(), f.datatype(), f.count()});
  m.data = std::move(msg.data());
  m.frame_id = msg.header().frame_id();
  return m;
}

MapMessage mapMessageOf(ros_octomap::Octomap_& msg) {
  MapMessage m;
  m.octomap = OctomapTree{msg.binary(), msg.id(), msg.resolution()};
  m.data.assign(msg.data().begin(), msg.data().end());
  m.frame_id = msg.header().frame_id();
  return m;
}

/// Takes the map messages (of ROS type `Msg`) of both readers of the map
/// topic (transient local and volatile: each matches writers the other
/// cannot) and hands each on once.
template <class Msg>
class MapListener : public DataReaderListener {
 public:
  explicit MapListener(std::function<void(MapMessage&&)> on_message) : on_message_(std::move(on_message)) {}

  void on_data_available(DataReader* reader) override {
    Msg msg;
    SampleInfo info;
    while (reader->take_next_sample(&msg, &info) == ReturnCode_t::RETCODE_OK) {
      if (!info.valid_data || seenBefore(info.sample_identity)) continue;
      on_message_(mapMessageOf(msg));
    }
  }

 private:
  /// Whether the other reader already took this sample (a transient local
  /// writer's samples reach both).
  bool seenBefore(const eprosima::fastrtps::rtps::SampleIdentity& id) {
    std::lock_guard<std::mutex> lock(mutex_);
    for (const auto& s : seen_)
      if (s == id) return true;
    seen_.push_back(id);
    if (seen_.size() > 16) seen_.pop_front();
    return false;
  }

  std::function<void(MapMessage&&)> on_message_;
  std::mutex mutex_;
  std::deque<eprosima::fastrtps::rtps::SampleIdentity> seen_;
};

struct Ros2Node::Impl {
  DomainParticipant* participant = nullptr;
  Publisher* publisher = nullptr;
  DataWriter* tf_static = nullptr;
  DataWriter* diagnostics = nullptr;
  DataWriter* fleet_map = nullptr;
  DataWriter* fleet_grid = nullptr;
  std::unique_ptr<DataReaderListener> map_listener;

  /// `topic` with its `type` registered.
  Topic* topic(TypeSupport type, const std::string& name) {
    if (type.register_type(participant) != ReturnCode_t::RETCODE_OK)
      throw std::runtime_error("cannot register " + type.get_type_name());
    Topic* t = participant->create_topic(name, type.get_type_name(), TOPIC_QOS_DEFAULT);
    if (!t) throw std::runtime_error("cannot create the topic " + name);
    return t;
  }

  /// A writer of `type` (ROS 2's `ros_type`, whose hash it carries) on `name`.
  DataWriter* writer(TypeSupport type, const std::string& ros_type, const std::string& name, DataWriterQos qos) {
    qos.user_data().data_vec(typeHashUserData(ros_type));
    DataWriter* w = publisher->create_datawriter(topic(std::move(type), name), qos);
    if (!w) throw std::runtime_error("cannot create the writer of " + name);
    return w;
  }

  ~Impl() {
    if (participant) {
      // The readers go (and their listener stops being called) before the listener does.
      participant->delete_contained_entities();
      DomainParticipantFactory::get_instance()->delete_participant(participant);
    }
  }
};

namespace {

/// Participant indices probed on this host: as many as ROS 2's
/// rmw_cyclonedds lets a host's nodes take (MaxAutoParticipantIndex 32).
constexpr uint32_t kLocalParticipantIndices = 32;

/// Where the ROS 2 participant looks for ROS 2 nodes (docs/operations.md,
/// "ROS 2"). Every ROS 2 discovery setting that reaches this host is
/// served, whichever DDS the nodes use: announcing to loopback at the
/// well-known port of each participant index finds the nodes that listen
/// only there (Jazzy's ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST, static
/// peers on this host); a node bound to loopback (Humble's
/// ROS_LOCALHOST_ONLY=1) answers to the 127.0.0.1 this participant gives.
/// `localhost_only` keeps everything on the host: no multicast at all, and
/// replies only to the addresses local nodes give, which are this host's own
/// (the kernel delivers those on loopback: nothing reaches the robots' link).
/// Otherwise Fast DDS's multicast discovery finds the nodes of the network too
/// (ROS 2's defaults), loopback besides.
void configureDiscovery(DomainParticipantQos& q, int ros_domain, bool localhost_only) {
  using eprosima::fastrtps::rtps::IPLocator;
  using eprosima::fastrtps::rtps::Locator_t;
  Locator_t loopback;
  IPLocator::setIPv4(loopback, 127, 0, 0, 1);
  auto& builtin = q.wire_protocol().builtin;
  builtin.initialPeersList.push_back(loopback);
  auto udp = std::make_shared<eprosima::fastdds::rtps::UDPv4TransportDescriptor>();
  udp->maxInitialPeersRange = kLocalParticipantIndices;
  q.transport().use_builtin_transports = false;
  q.transport().user_transports.push_back(udp);
  q.transport().user_transports.push_back(std::make_shared<eprosima::fastdds::rtps::SharedMemTransportDescriptor>());
  if (localhost_only) {
    builtin.metatrafficMulticastLocatorList.clear();
    builtin.metatrafficUnicastLocatorList.push_back(loopback);
    q.wire_protocol().default_unicast_locator_list.push_back(loopback);
  } else {
    // The initial peers replace Fast DDS's default one, its multicast group.
    Locator_t multicast;
    IPLocator::setIPv4(multicast, 239, 255, 0, 1);
    multicast.port = q.wire_protocol().port.getMulticastPort(static_cast<uint32_t>(ros_domain));
    builtin.initialPeersList.push_back(multicast);
  }
}

}  // namespace

Ros2Node::Ros2Node(int ros_domain, bool localhost_only) : impl_(std::make_unique<Impl>()) {
  DomainParticipantQos q;
  q.name("tomomapd");
  configureDiscovery(q, ros_domain, localhost_only);
  auto& i = *impl_;
  i.participant = DomainParticipantFactory::get_instance()->create_participant(ros_domain, q);
  if (!i.participant)
    throw std::runtime_error("cannot create the ROS 2 participant on domain " + std::to_string(ros_domain));
  i.publisher = i.participant->create_publisher(PUBLISHER_QOS_DEFAULT);
  if (!i.publisher) throw std::runtime_error("cannot create the ROS 2 publisher");
  // tf2_ros::StaticTransformBroadcaster's QoS: transient local.
  i.tf_static = i.writer(TypeSupport(new ros_tf::TFMessage_PubSubType()), "tf2_msgs/msg/TFMessage", kTfStaticTopic,
                         reliableKeepLast1(DATAWRITER_QOS_DEFAULT, TRANSIENT_LOCAL_DURABILITY_QOS));
  // diagnostic_updater's: volatile (a late reader waits for the next).
  i.diagnostics = i.writer(TypeSupport(new ros_diagnostic::DiagnosticArray_PubSubType()),
                           "diagnostic_msgs/msg/DiagnosticArray", kDiagnosticsTopic,
                           reliableKeepLast1(DATAWRITER_QOS_DEFAULT, VOLATILE_DURABILITY_QOS));
  // Map servers' QoS: transient local, so RViz started later gets the map.
  // Asynchronous: a map of megabytes leaves in fragments on Fast DDS's own
  // thread, not on the caller's.
  DataWriterQos latched = reliableKeepLast1(DATAWRITER_QOS_DEFAULT, TRANSIENT_LOCAL_DURABILITY_QOS);
  latched.publish_mode().kind = ASYNCHRONOUS_PUBLISH_MODE;
  i.fleet_map =
      i.writer(TypeSupport(new ros_sensor::PointCloud2_PubSubType()), "sensor_msgs/msg/PointCloud2", kFleetMapTopic, latched);
  i.fleet_grid = i.writer(TypeSupport(new ros_nav::OccupancyGrid_PubSubType()), "nav_msgs/msg/OccupancyGrid",
                          kFleetGridTopic, latched);
}

Ros2Node::~Ros2Node() = default;

void Ros2Node::publishTfStatic(const std::vector<TfFrame>& frames) {
  ros_tf::TFMessage_ msg;
  for (const auto& f : frames) {
    ros_geometry::TransformStamped_ t;
    t.header().stamp(rosTime(f.stamp_ms));
    t.header().frame_id(f.parent);
    t.child_frame_id(f.child);
    t.transform().translation().x(f.T_parent_child(0, 3));
    t.transform().translation().y(f.T_parent_child(1, 3));
    t.transform().translation().z(f.T_parent_child(2, 3));
    t.transform().rotation(rosQuaternion(f.T_parent_child.topLeftCorner<3, 3>()));
    msg.transforms().push_back(std::move(t));
  }
  impl_->tf_static->write(&msg);
}

void Ros2Node::publishDiagnostics(const std::vector<Diagnostic>& statuses, uint64_t stamp_ms) {
  ros_diagnostic::DiagnosticArray_ msg;
  msg.header().stamp(rosTime(stamp_ms));
  for (const auto& d : statuses) {
    ros_diagnostic::DiagnosticStatus_ s;
    s.level(static_cast<uint8_t>(d.level));
    s.name(d.name);
    s.message(d.message);
    s.hardware_id(d.hardware_id);
    for (const auto& [key, value] : d.values) {
      ros_diagnostic::KeyValue_ kv;
      kv.key(key);
      kv.value(value);
      s.values().push_back(std::move(kv));
    }
    msg.status().push_back(std::move(s));
  }
  impl_->diagnostics->write(&msg);
}

void Ros2Node::publishFleetMap(const FleetMapMessage& m) {
  const FleetMap& map = *m.map;
  const Eigen::Matrix3f R = m.T_frame_map.topLeftCorner<3, 3>().cast<float>();
  const Eigen::Vector3f t = m.T_frame_map.topRightCorner<3, 1>().cast<float>();

  ros_sensor::PointCloud2_ cloud;
  cloud.header().stamp(rosTime(m.stamp_ms));
  cloud.header().frame_id(m.frame_id);
  // PCL's PointXYZRGBL as pcl_conversions lays it out: RViz colours by rgb.
  uint32_t offset = 0;
  for (const char* name : {"x", "y", "z", "rgb", "label"}) {
    ros_sensor::PointField_ f;
    f.name(name);
    f.offset(offset);
    f.datatype(std::string(name) == "label" ? kUint32 : kFloat32);
    f.count(1);
    cloud.fields().push_back(std::move(f));
    offset += 4;
  }
  constexpr uint32_t kStep = 20;
  // A message's sizes are 32-bit: 214 M cells (4 GB) at most.
  if (map.points.size() > std::numeric_limits<uint32_t>::max() / kStep)
    throw std::runtime_error("a fleet map of " + std::to_string(map.points.size()) + " cells is too large for a PointCloud2");
  cloud.height(1);
  cloud.width(static_cast<uint32_t>(map.points.size()));
  cloud.is_bigendian(false);
  cloud.point_step(kStep);
  cloud.row_step(kStep * cloud.width());
  cloud.is_dense(true);
  std::vector<uint8_t>& data = cloud.data();
  data.resize(static_cast<size_t>(kStep) * map.points.size());
  for (size_t i = 0; i < map.points.size(); ++i) {
    const Eigen::Vector3f p = R * map.points[i] + t;
    const uint32_t label = map.robot[i], rgb = m.colours.at(label);
    uint8_t* out = data.data() + i * kStep;
    std::memcpy(out, p.data(), 12);  // little-endian hosts: is_bigendian false
    std::memcpy(out + 12, &rgb, 4);
    std::memcpy(out + 16, &label, 4);
  }
  if (!impl_->fleet_map->write(&cloud)) throw std::runtime_error("DDS refused the PointCloud2 of the fleet's map");

  const OccupancyGrid2D& g = m.grid->grid;
  ros_nav::OccupancyGrid_ grid;
  grid.header().stamp(rosTime(m.stamp_ms));
  grid.header().frame_id(m.frame_id);
  grid.info().map_load_time(rosTime(m.stamp_ms));
  grid.info().resolution(static_cast<float>(g.resolution));
  grid.info().width(static_cast<uint32_t>(g.width));
  grid.info().height(static_cast<uint32_t>(g.height));
  // The grid lies at the floor's height, turned with the map into the frame.
  const Eigen::Vector3d corner =
      m.T_frame_map.topLeftCorner<3, 3>() * Eigen::Vector3d(g.x_min, g.y_min, std::isfinite(m.grid->floor) ? m.grid->floor : 0) +
      m.T_frame_map.topRightCorner<3, 1>();
  grid.info().origin().position().x(corner.x());
  grid.info().origin().position().y(corner.y());
  grid.info().origin().position().z(corner.z());
  grid.info().origin().orientation(rosQuaternion(m.T_frame_map.topLeftCorner<3, 3>()));
  grid.data().assign(g.cells.begin(), g.cells.end());
  if (!impl_->fleet_grid->write(&grid)) throw std::runtime_error("DDS refused the OccupancyGrid of the fleet's map");
}

void Ros2Node::subscribeMap(const std::string& topic, MapMessageType type,
                            std::function<void(MapMessage&&)> on_message) {
  auto& i = *impl_;
  const bool cloud = type == MapMessageType::PointCloud2;
  // ROS 2's names: "rt" + the topic's absolute name.
  Topic* t = i.topic(cloud ? TypeSupport(new ros_sensor::PointCloud2_PubSubType())
                           : TypeSupport(new ros_octomap::Octomap_PubSubType()),
                     "rt" + (topic.rfind('/', 0) == 0 ? topic : "/" + topic));
  Subscriber* subscriber = i.participant->create_subscriber(SUBSCRIBER_QOS_DEFAULT);
  if (!subscriber) throw std::runtime_error("cannot subscribe to " + topic);
  if (cloud)
    i.map_listener = std::make_unique<MapListener<ros_sensor::PointCloud2_>>(std::move(on_message));
  else
    i.map_listener = std::make_unique<MapListener<ros_octomap::Octomap_>>(std::move(on_message));
  for (const DurabilityQosPolicyKind durability : {TRANSIENT_LOCAL_DURABILITY_QOS, VOLATILE_DURABILITY_QOS}) {
    DataReaderQos q = reliableKeepLast1(DATAREADER_QOS_DEFAULT, durability);
    q.user_data().data_vec(typeHashUserData(rosTypeName(type)));
    if (!subscriber->create_datareader(t, q, i.map_listener.get()))
      throw std::runtime_error("cannot create the reader of " + topic);
  }
}

}  // namespace tomomap::transport
