#pragma once
// What leaves the daemon when the agreed transforms change: the fleet's frame
// built from them (results/fleet_frame.hpp), transforms.json and frame.json in
// the output directory (written again until a write succeeds), and the frame's
// tree for ROS 2's /tf_static (handed to a publisher, when there is a ROS 2
// node). No DDS here: the publisher is a function.
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "config.hpp"
#include "log.hpp"
#include "results/agreed_transform.hpp"
#include "results/fleet_frame.hpp"
#include "transport/ros2_node.hpp"

namespace tomomap::daemon {

class FleetOutputs {
 public:
  using TreePublisher = std::function<void(const std::vector<transport::TfFrame>&)>;

  explicit FleetOutputs(Log& log) : log_(log) {}

  /// Where the tree goes from now on (empty: nowhere); it is handed the whole
  /// tree at the next update, even an empty one (a late reader then gets a sample).
  void setTreePublisher(TreePublisher publish);
  /// The agreed transforms changed: the frame is rebuilt (a pair that turns
  /// inconsistent said once), the tree handed on if it changed, the files written.
  void update(std::vector<AgreedTransform> agreed, const Config& config);
  /// Writes the files again if the last write failed (said once it works).
  void retry(const Config& config);

  const FleetFrame& frame() const { return frame_; }
  /// transforms.json is behind: its last write failed (writeError says why).
  bool unwritten() const { return unwritten_; }
  const std::string& writeError() const { return write_error_; }

 private:
  void rebuildFrame(const Config& config);
  void handTree(const Config& config);
  void write(const Config& config);

  Log& log_;
  std::vector<AgreedTransform> agreed_;
  FleetFrame frame_;  ///< every agent's pose in the reference's map, and each pair's verdict
  TreePublisher publish_;
  std::optional<std::vector<TreeEdge>> published_;  ///< what the publisher holds; none before the first
  bool unwritten_ = false;
  std::string write_error_;
};

}  // namespace tomomap::daemon
