#pragma once
// tomomapd's configuration file (TOML). Its keys are declared in settings.hpp;
// docs/configuration.md lists them.
#include <optional>
#include <string>
#include <vector>

#include "core/fleet_map.hpp"
#include "core/matcher.hpp"
#include "test_faults.hpp"
#include "transport/participant.hpp"
#include "transport/ros2_node.hpp"

namespace tomomap::daemon {

enum class LogLevel { Debug, Info, Warning, Error };

/// The [ros2] table: the fleet's frames on ROS 2's /tf_static (docs/configuration.md).
struct Ros2Config {
  bool enabled = false;               ///< on when the table is present, unless `enabled = false`
  int domain = 0;                     ///< the ROS 2 nodes' ROS_DOMAIN_ID
  std::string frame = "{agent}/map";  ///< frame id of each agent's map; {agent} is replaced by its id
  std::string root;                   ///< the tree's root agent; empty: the lowest id in the fleet
  /// A frame above every map (map_merge_3d's `world`): each placed map hangs
  /// from it with its pose in the root's map, the root's the identity; empty:
  /// the root's map is the tree's root.
  std::string world;
  bool localhost_only = true;  ///< reach ROS 2 nodes on this robot only, never the robots' link
  /// A topic that carries this robot's map (its SLAM's map cloud, an
  /// OctoMap), instead of the `map` file; empty: the file.
  std::string map_topic;
  transport::MapMessageType map_type = transport::MapMessageType::PointCloud2;  ///< what map_topic carries

  std::string frameOf(const std::string& agent) const;
};

/// A map message type as the config names it ("sensor_msgs/PointCloud2": its ROS name without "msg/").
std::string mapTypeName(transport::MapMessageType type);

/// The [fleet_map] table: the fleet's map built here (docs/configuration.md).
struct FleetMapConfig {
  bool enabled = true;
  HeightBand band;          ///< the 2D grid's heights above the floor [m]
  double interval_s = 10;   ///< at most one build this often [s]
};

struct Config {
  std::string file;                      ///< where it was read from
  transport::TransportConfig transport;  ///< agent id, domain, address, ports, peers, bandwidth
  std::string map;  ///< own map file (absolute, or relative to the config file); empty with ros2.map_topic
  /// The map's up direction in its own frame where the user knows it (the
  /// SLAM's gravity estimate, an IMU's); none: estimated from the map.
  std::optional<Eigen::Vector3d> map_up;
  /// `grid` and the [match] table, MatchParams' defaults: a map leaning
  /// beyond max_tilt is levelled before it is sliced, and the fleet's
  /// transforms say each map's up (AgreedTransform).
  MatchParams match;
  std::string output_dir;  ///< transforms.json, status.json
  LogLevel log_level = LogLevel::Info;
  double claim_timeout_s = 30;    ///< a claim without a result is void after this [s]
  double request_interval_s = 1;  ///< ask again for missing slices after this much silence [s]
  double peer_memory_mb = 256;    ///< memory one peer's map may take here, checked before it is allocated [MB]
  std::string reference;          ///< the fleet frame's reference agent as configured; empty: the lowest id
  /// Faults a test asked for (test_faults.hpp): from the environment, never the file.
  TestFaults faults;
  Ros2Config ros2;
  FleetMapConfig fleet_map;

  const std::string& agent() const { return transport.agent; }
  bool isPeer(const std::string& id) const;
  /// This agent or one of its peers.
  bool inFleet(const std::string& id) const { return id == agent() || isPeer(id); }
  std::vector<std::string> peerIds() const;
  /// The agent whose map is the fleet's frame: `reference`, or the lowest id in the fleet.
  std::string frameReference() const;
  /// The root of the ROS 2 frame tree: [ros2] root, or the fleet frame's reference.
  std::string treeRoot() const;
};

/// peer_memory_mb in bytes.
inline size_t peerMemoryBytes(const Config& c) { return static_cast<size_t>(c.peer_memory_mb * 1e6); }

/// Reads and checks a config. Throws InputError "FILE:LINE:COL: key 'k': problem"
/// (or "FILE: problem" for a missing file or key).
Config loadConfig(const std::string& path);

/// The effective configuration, one "key = value" per line, as logged at start.
std::string describe(const Config& c);

}  // namespace tomomap::daemon
