#pragma once
// The fleet's map, built on a thread of its own (docs/operations.md, "The
// fleet's map"): every placed map's slices, this agent's and its peers' as
// they arrived (no byte more on the link), merged in the tree root's map
// levelled and written beside transforms.json. The agent's loop starts a
// build when what the map is made of changed and settled, never waits for
// one, and hands the result to ROS 2 itself (its node is the loop's to make
// and unmake). It runs at the daemon's own priority: a thread of lower
// priority holding the process's memory map lock while it waits for a core
// stalled a daemon's loop for 29 s among ten daemons on two cores.
#include <atomic>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "core/features.hpp"
#include "core/fleet_map.hpp"

namespace tomomap::daemon {

/// One map the fleet's map is made of.
struct FleetMapPart {
  std::string agent;
  std::shared_ptr<const MapFeatures> map;  ///< its slices, as held here
  Pose4 T_root_map;                        ///< between the root's map and this one as sliced (levelled)
  bool operator==(const FleetMapPart& o) const {
    const Pose4 &a = T_root_map, &b = o.T_root_map;
    return agent == o.agent && map == o.map && a.x == b.x && a.y == b.y && a.z == b.z && a.yaw == b.yaw;
  }
};

/// What to build, and where it goes.
struct FleetMapJob {
  std::vector<FleetMapPart> parts;  ///< the root's map first where it is held
  double grid = 0;                  ///< [m]
  HeightBand band;
  std::string dir;    ///< the output folder
  std::string where;  ///< the picture's caption: "alpha's frame, levelled"
};

/// What a build made.
struct FleetMapBuilt {
  nlohmann::json status;  ///< status.json's `fleet_map` (docs/json.md)
  std::shared_ptr<const FleetMap> map;    ///< null when the build failed (`status` says why)
  std::shared_ptr<const FleetGrid> grid;
};

class FleetMapBuilder {
 public:
  /// `wake` is called from the builder's thread when a build is done.
  explicit FleetMapBuilder(std::function<void()> wake) : wake_(std::move(wake)) {}
  ~FleetMapBuilder();
  FleetMapBuilder(const FleetMapBuilder&) = delete;
  FleetMapBuilder& operator=(const FleetMapBuilder&) = delete;

  /// Starts building `job`; only while idle().
  void start(FleetMapJob job);
  bool idle() const { return !thread_.joinable(); }
  bool ready() const { return done_; }
  /// The build just done, once ready(); the builder is idle again afterwards.
  FleetMapBuilt take();

 private:
  std::function<void()> wake_;
  std::thread thread_;
  std::atomic<bool> done_{false};
  FleetMapBuilt result_;
};

}  // namespace tomomap::daemon
