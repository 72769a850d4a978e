// What ROS 2 sees of the daemon: the fleet's frames on /tf_static, every
// placed map under the root with its pose in the fleet's frame
// (results/fleet_frame.hpp), republished whole whenever it changes; and its
// health on /diagnostics (diagnostics.hpp).
#include "agent.hpp"
#include "diagnostics.hpp"

namespace tomomap::daemon {

namespace {

/// diagnostic_updater's default period: what rqt_robot_monitor expects.
constexpr auto kDiagnosticsPeriod = std::chrono::seconds(1);

}  // namespace

void Agent::startRos2() {
  ros2_.reset();
  refreshFleetMap();
  outputs_.setTreePublisher({});
  diagnostics_published_.reset();
  if (!config_.ros2.enabled) return;
  try {
    ros2_ = std::make_unique<transport::Ros2Node>(config_.ros2.domain, config_.ros2.localhost_only);
    if (!config_.ros2.map_topic.empty()) {
      // Each message is whole (unlike a file being written), but a SLAM
      // package may publish one with every scan: the newest is described once
      // the last description is done and the first message waiting for it
      // has waited kMapSettle (agent_lifecycle.cpp).
      ros2_->subscribeMap(config_.ros2.map_topic, config_.ros2.map_type, [this](transport::MapMessage&& m) {
        post([this, m = std::make_shared<const transport::MapMessage>(std::move(m))] {
          map_message_ = m;
          if (!map_touched_) map_touched_ = Clock::now();
        });
      });
      log_.info("ROS 2: reading this robot's map from " + config_.ros2.map_topic + " (" +
                mapTypeName(config_.ros2.map_type) + ")");
    }
    outputs_.setTreePublisher([node = ros2_.get()](const auto& frames) { node->publishTfStatic(frames); });
    log_.info("ROS 2: publishing the fleet's frames on /tf_static and this daemon's health on /diagnostics (domain " +
              std::to_string(config_.ros2.domain) + ", root frame " + config_.ros2.frameOf(config_.treeRoot()) + ")");
  } catch (const std::exception& e) {
    ros2_.reset();  // half made (its map reader refused, say): none, so a map from the topic is known not to come
    outputs_.setTreePublisher({});
    log_.error(std::string("ROS 2: cannot publish /tf_static and /diagnostics (") + e.what() +
               "); transforms.json is still written");
  }
}

void Agent::publishDiagnostics(const nlohmann::json& status) {
  if (!ros2_) return;
  const auto now = Clock::now();
  if (diagnostics_published_ && now - *diagnostics_published_ < kDiagnosticsPeriod) return;
  diagnostics_published_ = now;
  ros2_->publishDiagnostics({diagnosticOf(status, outputs_.frame(), statusLine())}, wallMs());
}

}  // namespace tomomap::daemon
