#include "fleet_outputs.hpp"

#include <filesystem>

#include "core/text.hpp"
#include "results/json_schema.hpp"
#include "state_files.hpp"

namespace tomomap::daemon {
namespace {

bool sameTree(const std::vector<TreeEdge>& a, const std::vector<TreeEdge>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    const Pose4 &p = a[i].T_parent_child, &q = b[i].T_parent_child;
    if (a[i].parent != b[i].parent || a[i].child != b[i].child || a[i].stamp_ms != b[i].stamp_ms || p.x != q.x ||
        p.y != q.y || p.z != q.z || p.yaw != q.yaw || a[i].parent_up != b[i].parent_up ||
        a[i].child_up != b[i].child_up)
      return false;
  }
  return true;
}

}  // namespace

void FleetOutputs::setTreePublisher(TreePublisher publish) {
  publish_ = std::move(publish);
  published_.reset();
}

void FleetOutputs::update(std::vector<AgreedTransform> agreed, const Config& config) {
  agreed_ = std::move(agreed);
  rebuildFrame(config);
  handTree(config);
  write(config);
}

void FleetOutputs::retry(const Config& config) {
  if (unwritten_) write(config);
}

void FleetOutputs::rebuildFrame(const Config& config) {
  std::vector<std::string> agents = config.peerIds();
  agents.push_back(config.agent());
  // "Consistent" means what "agree" means to the matcher: its consensus limits.
  const CycleLimits limits{config.match.consensus_translation_cells * config.match.grid, config.match.consensus_yaw};
  FleetFrame next = buildFleetFrame(agreed_, agents, config.frameReference(), limits);
  for (const auto& v : next.pairs) {
    const PairVerdict* before = frame_.verdict(v.pair);
    if (v.verdict != Consistency::Inconsistent || (before && before->verdict == Consistency::Inconsistent)) continue;
    log_.warning(pairText(v.pair) + " is inconsistent with the fleet's other transforms: the loop " +
                 chainText(v.cycle, /*closed=*/true) + " misses by " + fixed(v.cycle_translation, 2) + " m and " +
                 fixed(degrees(v.cycle_yaw), 1) + " deg; left out of the fleet's frame");
  }
  frame_ = std::move(next);
}

void FleetOutputs::handTree(const Config& config) {
  if (!publish_) return;
  uint64_t stamp_ms = 0;  // the newest transform behind the frame
  for (const auto& t : agreed_)
    if (t.reliable) stamp_ms = std::max(stamp_ms, t.computed_at_ms);
  std::vector<TreeEdge> tree = treeOf(frame_, config.treeRoot(), stamp_ms);
  if (published_ && sameTree(tree, *published_)) return;
  std::vector<transport::TfFrame> frames;
  const std::string& world = config.ros2.world;
  // Under a world frame the root's map is one child among the others, where
  // the root is; the world is the root's map levelled (z up, even where the
  // root's map leans).
  Eigen::Matrix4d level = Eigen::Matrix4d::Identity();
  const AgentPose* root = frame_.pose(config.treeRoot());
  if (!world.empty() && root) {
    level = levelingMatrix(root->up);
    frames.push_back({world, config.ros2.frameOf(config.treeRoot()), level, stamp_ms});
  }
  for (const auto& e : tree)
    frames.push_back({world.empty() ? config.ros2.frameOf(e.parent) : world, config.ros2.frameOf(e.child),
                      level * e.ownFrames(), e.stamp_ms});
  publish_(frames);
  log_.info("ROS 2: /tf_static holds " + std::to_string(tree.size()) + " of the fleet's " +
            std::to_string(config.transport.peers.size()) + " other frames under " +
            config.ros2.frameOf(config.treeRoot()) + (world.empty() ? "" : ", every map under " + world));
  published_ = std::move(tree);
}

void FleetOutputs::write(const Config& config) {
  const std::filesystem::path dir(config.output_dir);
  try {
    // The frame first: whoever sees a transform in transforms.json then finds
    // the frame built from it (a test that read frame.json as soon as
    // transforms.json held the pair once found the frame of before).
    nlohmann::json frame = toJson(frame_);
    frame["schema_version"] = kJsonSchemaVersion;
    frame["agent"] = config.agent();
    writeJsonAtomically((dir / "frame.json").string(), frame);
    nlohmann::json list = nlohmann::json::array();
    for (const auto& t : agreed_) list.push_back(toJson(t));
    writeJsonAtomically((dir / "transforms.json").string(),
                        {{"schema_version", kJsonSchemaVersion}, {"agent", config.agent()}, {"transforms", list}});
    if (unwritten_) log_.info("transforms.json written again: it holds every agreed transform");
    unwritten_ = false;
    write_error_.clear();
  } catch (const std::exception& e) {
    // Said once per failing spell; retried with every status write (tick).
    if (!unwritten_) log_.error(std::string("cannot write transforms.json (retrying): ") + e.what());
    unwritten_ = true;
    write_error_ = e.what();
  }
}

}  // namespace tomomap::daemon
