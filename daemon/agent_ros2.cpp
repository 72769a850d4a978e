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

bool sameTree(const std::vector<TreeEdge>& a, const std::vector<TreeEdge>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    const Pose4 &p = a[i].T_parent_child, &q = b[i].T_parent_child;
    if (a[i].parent != b[i].parent || a[i].child != b[i].child || a[i].stamp_ms != b[i].stamp_ms || p.x != q.x ||
        p.y != q.y || p.z != q.z || p.yaw != q.yaw)
      return false;
  }
  return true;
}

}  // namespace

void Agent::startRos2() {
  ros2_.reset();
  tf_published_.reset();
  diagnostics_published_.reset();
  if (!config_.ros2.enabled) return;
  try {
    ros2_ = std::make_unique<transport::Ros2Node>(config_.ros2.domain, config_.ros2.localhost_only);
    if (!config_.ros2.map_topic.empty()) {
      // Each message is whole (unlike a file being written), but a SLAM
      // package may publish one with every scan: the newest is described once
      // the last description is done and the first message waiting for it
      // has waited kMapSettle (agent_lifecycle.cpp).
      ros2_->subscribeMap(config_.ros2.map_topic, [this](transport::CloudMessage&& m) {
        post([this, m = std::make_shared<const transport::CloudMessage>(std::move(m))] {
          cloud_ = m;
          if (!map_touched_) map_touched_ = Clock::now();
        });
      });
      log_.info("ROS 2: reading this robot's map from " + config_.ros2.map_topic + " (sensor_msgs/PointCloud2)");
    }
    log_.info("ROS 2: publishing the fleet's frames on /tf_static and this daemon's health on /diagnostics (domain " +
              std::to_string(config_.ros2.domain) + ", root frame " + config_.ros2.frameOf(config_.treeRoot()) + ")");
  } catch (const std::exception& e) {
    log_.error(std::string("ROS 2: cannot publish /tf_static and /diagnostics (") + e.what() +
               "); transforms.json is still written");
  }
}

void Agent::publishTree() {
  if (!ros2_) return;
  uint64_t stamp_ms = 0;  // the newest transform behind the frame
  for (const auto& [key, t] : board_.results())
    if (t.reliable) stamp_ms = std::max(stamp_ms, t.computed_at_ms);
  std::vector<TreeEdge> tree = treeOf(frame_, config_.treeRoot(), stamp_ms);
  // An empty tree is published too, once: a late reader then gets a sample.
  if (tf_published_ && sameTree(tree, *tf_published_)) return;
  std::vector<transport::TfFrame> frames;
  for (const auto& e : tree)
    frames.push_back({config_.ros2.frameOf(e.parent), config_.ros2.frameOf(e.child), e.T_parent_child, e.stamp_ms});
  ros2_->publishTfStatic(frames);
  log_.info("ROS 2: /tf_static holds " + std::to_string(frames.size()) + " of the fleet's " +
            std::to_string(config_.transport.peers.size()) + " other frames under " +
            config_.ros2.frameOf(config_.treeRoot()));
  tf_published_ = std::move(tree);
}

void Agent::publishDiagnostics(const nlohmann::json& status) {
  if (!ros2_) return;
  const auto now = Clock::now();
  if (diagnostics_published_ && now - *diagnostics_published_ < kDiagnosticsPeriod) return;
  diagnostics_published_ = now;
  ros2_->publishDiagnostics({diagnosticOf(status, toJson(frame_), statusLine())}, wallMs());
}

}  // namespace tomomap::daemon
