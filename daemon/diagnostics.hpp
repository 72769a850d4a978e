#pragma once
// The daemon's health as ROS 2's /diagnostics carries it (diagnostic_msgs/
// DiagnosticStatus: a level, a message, key-value pairs), read off what it
// tells its operator anyway: status.json and the fleet's frame. Pure: no DDS here.
#include <nlohmann/json.hpp>
#include <string>

#include "results/fleet_frame.hpp"
#include "transport/ros2_node.hpp"

namespace tomomap::daemon {

/// One status named "tomomapd: <agent>": ERROR while transforms.json cannot
/// be written; WARN while a peer is down or incompatible, the own map is
/// waiting or its update refused, a pair is refused (no reliable match) or
/// inconsistent with the fleet's other transforms; OK otherwise. The message
/// says why (or, when OK, gives `summary`); the values list the map, each peer,
/// each pair and the counters an operator checks.
transport::Diagnostic diagnosticOf(const nlohmann::json& status, const FleetFrame& frame, const std::string& summary);

}  // namespace tomomap::daemon
