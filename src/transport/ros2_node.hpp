#pragma once
// The daemon's node on the ROS 2 domain, a DDS participant of its own: the
// fleet's frames on /tf_static, published the way tf2_ros's static transform
// broadcaster does (rt/tf_static, tf2_msgs::msg::dds_::TFMessage_, reliable,
// transient local, the whole tree in the last sample), and the daemon's health
// on /diagnostics as diagnostic_updater publishes it (rt/diagnostics,
// diagnostic_msgs::msg::dds_::DiagnosticArray_, reliable, volatile), and the
// fleet's map as map servers publish theirs (/fleet_map, sensor_msgs/PointCloud2,
// and /fleet_map_grid, nav_msgs/OccupancyGrid: reliable, transient local). ROS 2
// nodes see them with no ROS 2 dependency here (docs/operations.md, "ROS 2").
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "core/fleet_map.hpp"
#include "io/point_cloud2.hpp"

namespace tomomap::transport {

struct TfFrame {
  std::string parent, child;       ///< frame ids
  Eigen::Matrix4d T_parent_child;  ///< the child frame's pose in the parent frame (rigid)
  uint64_t stamp_ms = 0;           ///< [ms since the epoch]
};

/// One diagnostic_msgs/DiagnosticStatus.
struct Diagnostic {
  enum Level : uint8_t { ok = 0, warn = 1, error = 2, stale = 3 };
  Level level = ok;
  std::string name, message, hardware_id;
  std::vector<std::pair<std::string, std::string>> values;  ///< key, value
};

/// The message types a map can come in.
enum class MapMessageType { PointCloud2, Octomap };
/// Its ROS name: "sensor_msgs/msg/PointCloud2", "octomap_msgs/msg/Octomap".
const char* rosTypeName(MapMessageType type);

/// octomap_msgs/Octomap's description of its tree.
struct OctomapTree {
  bool binary = true;  ///< occupancy only (a .bt's content); false: the full tree (a .ot's)
  std::string id;      ///< the tree's class, e.g. "OcTree"
  double resolution = 0;
};

/// One map message as it arrived, undecoded (io/point_cloud2.hpp,
/// io/octomap_io.hpp read it): decoding a large map is left to whoever has
/// time for it.
struct MapMessage {
  PointCloud2Layout layout;           ///< a PointCloud2's
  std::optional<OctomapTree> octomap; ///< an Octomap's (then `layout` is unused)
  std::vector<uint8_t> data;
  std::string frame_id;
};

/// The fleet's map as ROS 2 gets it: the merged cells and their 2D grid,
/// placed in the frame `frame_id` by `T_frame_map` (the map's frame is the
/// root's map levelled, z up).
struct FleetMapMessage {
  const FleetMap* map = nullptr;
  const FleetGrid* grid = nullptr;
  std::vector<uint32_t> colours;  ///< per robot of `map`: 0xRRGGBB
  std::string frame_id;
  Eigen::Matrix4d T_frame_map = Eigen::Matrix4d::Identity();
  uint64_t stamp_ms = 0;  ///< [ms since the epoch]
};

class Ros2Node {
 public:
  /// `localhost_only`: the participant reaches ROS 2 nodes on this host only,
  /// under any of ROS 2's local discovery settings, and nothing of it reaches
  /// the robots' thin link; otherwise the network's nodes too, by multicast
  /// (ros2_node.cpp, configureDiscovery). Throws std::runtime_error if DDS refuses.
  Ros2Node(int ros_domain, bool localhost_only);
  ~Ros2Node();
  Ros2Node(const Ros2Node&) = delete;
  Ros2Node& operator=(const Ros2Node&) = delete;

  /// Replaces what /tf_static holds with `frames` (all of them, one sample).
  void publishTfStatic(const std::vector<TfFrame>& frames);
  /// One DiagnosticArray on /diagnostics, stamped `stamp_ms` [ms since the epoch].
  void publishDiagnostics(const std::vector<Diagnostic>& statuses, uint64_t stamp_ms);
  /// Replaces the fleet's map: /fleet_map (PointCloud2: x, y, z, rgb as
  /// float32, label as uint32, a point per cell) and /fleet_map_grid
  /// (OccupancyGrid), both latched (transient local, keep last 1). Throws
  /// std::runtime_error if a map is too large for a message or DDS refuses it.
  void publishFleetMap(const FleetMapMessage& m);
  /// Reads maps of `type` (sensor_msgs/PointCloud2, octomap_msgs/Octomap)
  /// from the ROS 2 topic `topic` (e.g. /Laser_map, /octomap_binary) with the
  /// QoS SLAM packages and octomap_server publish maps with: reliable, keep
  /// last 1, volatile or transient local (a latched map that was published
  /// before this node started arrives too). Each new message goes to
  /// `on_message`, on a DDS thread. Throws std::runtime_error if DDS refuses.
  void subscribeMap(const std::string& topic, MapMessageType type, std::function<void(MapMessage&&)> on_message);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomomap::transport
