#pragma once
// Basic geometric types shared by every stage of the matcher.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "huge_pages.hpp"

namespace tomomap {

/// A gravity-aligned point cloud in its map frame [m]. Maps run to millions
/// of points, each copy (filtered, levelled, cropped) touched once: in huge pages.
using Points = std::vector<Eigen::Vector3f, HugePageAllocator<Eigen::Vector3f>>;

/// Raised for input a user can fix (bad file, bad number, too small map).
/// Front ends map it to the "bad input" exit code.
struct InputError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

constexpr double kPi = 3.14159265358979323846;

/// Angle unit conversions: radians inside, degrees where people read or write.
constexpr double degrees(double radians) { return radians * 180.0 / kPi; }
constexpr double radians(double degrees) { return degrees * kPi / 180.0; }

/// Wraps an angle into (-pi, pi].
inline double wrapAngle(double a) {
  a = std::fmod(a + kPi, 2.0 * kPi);
  if (a <= 0.0) a += 2.0 * kPi;
  return a - kPi;
}

/// A 4-DoF rigid transform: rotation about gravity (z) then translation.
struct Pose4 {
  double x = 0, y = 0, z = 0;  ///< translation [m]
  double yaw = 0;              ///< rotation about z [rad], in (-pi, pi]

  Eigen::Matrix4d matrix() const {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    const double c = std::cos(yaw), s = std::sin(yaw);
    m(0, 0) = c;
    m(0, 1) = -s;
    m(1, 0) = s;
    m(1, 1) = c;
    m(0, 3) = x;
    m(1, 3) = y;
    m(2, 3) = z;
    return m;
  }

  /// Projects a rigid 4x4 onto 4-DoF (yaw from the rotation's x axis).
  static Pose4 fromMatrix(const Eigen::Matrix4d& m) {
    return Pose4{m(0, 3), m(1, 3), m(2, 3), std::atan2(m(1, 0), m(0, 0))};
  }

  Pose4 inverse() const { return fromMatrix(matrix().inverse()); }
  Pose4 operator*(const Pose4& o) const { return fromMatrix(matrix() * o.matrix()); }

  Eigen::Vector3f apply(const Eigen::Vector3f& p) const {
    const double c = std::cos(yaw), s = std::sin(yaw);
    return {static_cast<float>(c * p.x() - s * p.y() + x), static_cast<float>(s * p.x() + c * p.y() + y),
            static_cast<float>(p.z() + z)};
  }
};

/// Whether a 4x4 matrix is a rigid transform: finite, a proper rotation (to
/// 1e-6) and a translation, last row 0 0 0 1.
inline bool isRigid(const Eigen::Matrix4d& m) {
  if (!m.allFinite() || !m.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1))) return false;
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  return (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff() < 1e-6 && r.determinant() > 0;
}

/// One keyframe of a SLAM sequence: its points in the sensor (body) frame and
/// where the SLAM put it.
struct PosedScan {
  Points points;
  Eigen::Matrix4d T_world_body = Eigen::Matrix4d::Identity();  ///< p_world = T_world_body * p_body
};

/// Applies a transform to every point.
inline Points transformPoints(const Points& in, const Pose4& T) {
  Points out;
  out.reserve(in.size());
  for (const auto& p : in) out.push_back(T.apply(p));
  return out;
}

/// Translation and yaw error between an estimate and a reference.
struct PoseError {
  double translation = 0;  ///< Euclidean distance [m]
  double yaw = 0;          ///< absolute wrapped difference [rad]
};

inline PoseError poseError(const Pose4& estimate, const Pose4& reference) {
  const double dx = estimate.x - reference.x, dy = estimate.y - reference.y, dz = estimate.z - reference.z;
  return {std::sqrt(dx * dx + dy * dy + dz * dz), std::abs(wrapAngle(estimate.yaw - reference.yaw))};
}

}  // namespace tomomap
