#pragma once
// ROS 2's /tf_static, published the way its static transform broadcaster does
// (DDS topic rt/tf_static, type tf2_msgs::msg::dds_::TFMessage_, reliable,
// transient local, the whole tree in the last sample), from a participant of
// its own on the ROS 2 domain: ROS 2 nodes see the fleet's frames with no
// ROS 2 dependency here (docs/operations.md, "ROS 2").
#include <memory>
#include <string>
#include <vector>

#include "core/types.hpp"

namespace tomomap::transport {

struct TfFrame {
  std::string parent, child;  ///< frame ids
  Pose4 T_parent_child;       ///< the child frame's pose in the parent frame
  uint64_t stamp_ms = 0;      ///< [ms since the epoch]
};

/// The ROS 2 message's quaternion (x, y, z, w) for a rotation by `yaw` about z.
Eigen::Vector4d yawQuaternion(double yaw);

class TfStaticPublisher {
 public:
  /// `localhost_only`: the participant reaches ROS 2 nodes on this host only,
  /// under any of ROS 2's local discovery settings, and nothing of it reaches
  /// the robots' thin link; otherwise the network's nodes too, by multicast
  /// (tf_static.cpp, configureDiscovery). Throws std::runtime_error if DDS refuses.
  TfStaticPublisher(int ros_domain, bool localhost_only);
  ~TfStaticPublisher();
  TfStaticPublisher(const TfStaticPublisher&) = delete;
  TfStaticPublisher& operator=(const TfStaticPublisher&) = delete;

  /// Replaces what /tf_static holds with `frames` (all of them, one sample).
  void publish(const std::vector<TfFrame>& frames);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace tomomap::transport
