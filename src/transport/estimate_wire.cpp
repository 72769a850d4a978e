#include "estimate_wire.hpp"

#include <cmath>

#include "core/gravity.hpp"

namespace tomomap::transport {

namespace {
/// Longest reason the wire type carries (string<128>), with room to spare.
constexpr size_t kReasonChars = 120;
/// Longest search name the wire type carries (string<16>).
constexpr size_t kAnsweredByChars = 16;
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
  const Eigen::Matrix4d M = t.ownFrames();
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) e.matrix()[static_cast<size_t>(4 * row + col)] = M(row, col);
  e.target_up({t.target_up.x(), t.target_up.y(), t.target_up.z()});
  e.source_up({t.source_up.x(), t.source_up.y(), t.source_up.z()});
  e.answered_by(t.answered_by.substr(0, kAnsweredByChars));
  e.lead_sigma(t.lead_sigma);
  e.computed_by(t.computed_by);
  e.computed_at_ms(t.computed_at_ms);
  e.seconds(t.seconds);
  return e;
}

Rejection fromWire(const wire::TransformEstimate& e, AgreedTransform& t) {
  if (e.target().to_string() >= e.source().to_string()) return {Reject::UnorderedPair};
  for (double v : {e.x(), e.y(), e.z(), e.yaw()})
    if (!std::isfinite(v)) return {Reject::NonFiniteTransform};
  if (!plausibleQuality(e.answered_by().to_string(), e.lead_sigma())) return {Reject::BadQuality};
  Eigen::Matrix4d M;
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 4; ++col) M(row, col) = e.matrix()[static_cast<size_t>(4 * row + col)];
  if (!M.allFinite()) return {Reject::NonFiniteTransform};
  if (!isRigid(M)) return {Reject::NotRigid};
  const Eigen::Vector3d target_up(e.target_up()[0], e.target_up()[1], e.target_up()[2]);
  const Eigen::Vector3d source_up(e.source_up()[0], e.source_up()[1], e.source_up()[2]);
  if (!levelableUp(target_up) || !levelableUp(source_up)) return {Reject::BadUp};
  t = AgreedTransform{};
  t.target = e.target().to_string();
  t.source = e.source().to_string();
  t.target_version = e.target_version();
  t.source_version = e.source_version();
  t.reliable = e.reliable();
  t.reason = e.reason().to_string();
  t.T_target_source = {e.x(), e.y(), e.z(), e.yaw()};
  t.target_up = target_up;
  t.source_up = source_up;
  t.T_target_source_6dof = M;
  t.answered_by = e.answered_by().to_string();
  t.lead_sigma = e.lead_sigma();
  t.computed_by = e.computed_by().to_string();
  t.computed_at_ms = e.computed_at_ms();
  t.seconds = e.seconds();
  return {};
}

}  // namespace tomomap::transport
