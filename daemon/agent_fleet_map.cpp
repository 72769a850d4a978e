// The fleet's map as the agent keeps it (fleet_map_builder.hpp): which maps
// it is made of now, and when to build it again.
#include "agent.hpp"
#include "core/gravity.hpp"
#include "core/text.hpp"
#include "viz/fleet_map_picture.hpp"

namespace tomomap::daemon {

namespace {

/// Intervals after which a fleet map whose parts keep changing is built anyway.
constexpr int kFleetMapOverdue = 6;

}  // namespace

FleetMapJob Agent::fleetMapJob() const {
  FleetMapJob job;
  const std::string root = config_.treeRoot();
  const FleetFrame& frame = outputs_.frame();
  const AgentPose* root_pose = frame.pose(root);
  if (!root_pose) return job;  // the root is not placed: there is no frame to build in
  if (auto m = featuresOf(root)) job.parts.push_back({root, std::move(m), Pose4{}});
  for (const auto& edge : treeOf(frame, root, 0))
    if (auto m = featuresOf(edge.child)) job.parts.push_back({edge.child, std::move(m), edge.T_parent_child});
  job.grid = config_.match.grid;
  job.band = config_.fleet_map.band;
  job.dir = config_.output_dir;
  job.where = root + "'s frame, levelled";
  return job;
}

void Agent::publishFleetMap(const FleetMapBuilt& built) {
  const std::string root = config_.treeRoot();
  const AgentPose* root_pose = outputs_.frame().pose(root);
  if (!ros2_ || !built.map || !root_pose) return;
  // Under a world frame the map is where the world is (the root's map
  // levelled); else in the root's map frame, the levelling undone.
  const bool world = !config_.ros2.world.empty();
  transport::FleetMapMessage m{built.map.get(), built.grid.get(), viz::robotRgbs(built.map->agents.size()),
                               world ? config_.ros2.world : config_.ros2.frameOf(root),
                               world ? Eigen::Matrix4d::Identity()
                                     : Eigen::Matrix4d(levelingMatrix(root_pose->up).inverse()),
                               wallMs()};
  try {
    ros2_->publishFleetMap(m);
    fleet_map_status_["published"] = {"/fleet_map", "/fleet_map_grid"};
  } catch (const std::exception& e) {
    fleet_map_status_["publish_error"] = e.what();
    log_.warning(std::string("ROS 2: cannot publish the fleet's map: ") + e.what());
  }
}

nlohmann::json Agent::fleetMapStatus() const {
  if (fleet_map_status_.is_null()) return fleet_map_status_;
  nlohmann::json s = fleet_map_status_;
  // Made of what the map is made of now: no build is running or due.
  s["current"] = fleet_map_.idle() && fleetMapJob().parts == fleet_map_parts_;
  return s;
}

void Agent::followFleetMap() {
  if (fleet_map_.ready()) {
    const FleetMapBuilt built = fleet_map_.take();
    fleet_map_status_ = built.status;
    if (!built.map) {
      log_.warning("cannot build the fleet's map (trying again in " + fixed(config_.fleet_map.interval_s, 0) +
                   " s): " + fleet_map_status_["error"].get<std::string>());
      refreshFleetMap();
    } else {
      publishFleetMap(built);
      std::string robots;
      for (const auto& r : fleet_map_status_["robots"])
        robots += (robots.empty() ? "" : ", ") + r["agent"].get<std::string>() + " " + std::to_string(r["cells"].get<size_t>());
      log_.info("fleet map: " + std::to_string(fleet_map_status_["cells"].get<size_t>()) + " cells (" + robots +
                ") in " + fleet_map_status_["frame"].get<std::string>() + ": " +
                fleet_map_status_["files"].get<std::string>() +
                (fleet_map_status_.contains("published") ? ", /fleet_map and /fleet_map_grid" : ""));
    }
  }
  if (!config_.fleet_map.enabled || !fleet_map_.idle()) return;
  const auto now = Clock::now();
  FleetMapJob job = fleetMapJob();
  if (job.parts != fleet_map_seen_) {
    fleet_map_seen_ = job.parts;
    fleet_map_seen_since_ = now;
  }
  // One map alone is no fleet's map: it is the robot's own, already in its file.
  if (job.parts.size() < 2 || job.parts == fleet_map_parts_) return;
  // At most one build an interval; and what the map is made of settles
  // first: while pairs land one after another (a fleet agreeing, a SLAM map
  // published with every scan) each build would be outdated by the next. A
  // map that never settles is built every kFleetMapOverdue intervals.
  const auto interval = fromSeconds(config_.fleet_map.interval_s);
  const auto last = fleet_map_started_.value_or(started_);
  if (fleet_map_started_ && now - last < interval) return;
  if (now - fleet_map_seen_since_ < interval && now - last < kFleetMapOverdue * interval) return;
  fleet_map_parts_ = job.parts;
  fleet_map_started_ = now;
  fleet_map_.start(std::move(job));
}

}  // namespace tomomap::daemon
