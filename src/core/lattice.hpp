#pragma once
// Cubes of one edge on the lattice with a corner at the origin, as hash keys.
#include <cmath>
#include <cstdint>

#include "types.hpp"

namespace tomomap {

/// The cube of edge `side` [m] holding `p`, packed into 64 bits (21 bits an
/// axis, z then y then x): cubes 2^21 apart share a key (100 km at 5 cm), so
/// it is a hash key for a map's cubes, not an index.
inline uint64_t latticeKey(const Eigen::Vector3f& p, double side) {
  const auto cell = [side](float v) {
    return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / side)) & 0x1FFFFF);
  };
  return (cell(p.z()) << 42) | (cell(p.y()) << 21) | cell(p.x());
}

/// The centre of the cube of edge `side` holding `p`.
inline Eigen::Vector3f latticeCentre(const Eigen::Vector3f& p, double side) {
  return ((p.cast<double>() / side).array().floor() + 0.5).matrix().cast<float>() * static_cast<float>(side);
}

}  // namespace tomomap
