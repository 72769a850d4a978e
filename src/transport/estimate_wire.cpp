#include "estimate_wire.hpp"

#include <cmath>

namespace tomomap::transport {

namespace {
/// Longest reason the wire type carries (string<128>), with room to spare.
constexpr size_t kReasonChars = 120;
}  // namespace

wire::TransformEstimate toWire(const AgreedTransform& t) {
  wire::TransformEstimate e;
  e.target(t.target);
  e.source(t.source);
  e.target_version(t.target_version);
  e.source_version(t.source_version);
  e.reliable(t.reliable);
  e.reason(t.reason.substr(0, kReasonChars));
  const Pose4& T = t.T_target_source;
  e.x(T.x);
  e.y(T.y);
  e.z(T.z);
  e.yaw(T.yaw);
  const Eigen::Matrix4d M = T.matrix();
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) e.matrix()[static_cast<size_t>(4 * row + col)] = M(row, col);
  e.support(t.support);
  e.runner_up_support(t.runner_up_support);
  e.inliers(t.inliers);
  e.spread(t.spread);
  e.computed_by(t.computed_by);
  e.computed_at_ms(t.computed_at_ms);
  e.seconds(t.seconds);
  return e;
}

Rejection fromWire(const wire::TransformEstimate& e, AgreedTransform& t) {
  if (e.target().to_string() >= e.source().to_string()) return {Reject::UnorderedPair};
  for (double v : {e.x(), e.y(), e.z(), e.yaw()})
    if (!std::isfinite(v)) return {Reject::NonFiniteTransform};
  t = AgreedTransform{};
  t.target = e.target().to_string();
  t.source = e.source().to_string();
  t.target_version = e.target_version();
  t.source_version = e.source_version();
  t.reliable = e.reliable();
  t.reason = e.reason().to_string();
  t.T_target_source = {e.x(), e.y(), e.z(), e.yaw()};
  t.support = e.support();
  t.runner_up_support = e.runner_up_support();
  t.inliers = e.inliers();
  t.spread = e.spread();
  t.computed_by = e.computed_by().to_string();
  t.computed_at_ms = e.computed_at_ms();
  t.seconds = e.seconds();
  return {};
}

}  // namespace tomomap::transport
