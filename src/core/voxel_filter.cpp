#include "voxel_filter.hpp"

#include <algorithm>
#include <cstdint>

namespace tomomap {

Points voxelFilter(const Points& in, double leaf) {
  if (in.empty()) return {};
  if (!(leaf > 0.0)) throw InputError("voxel leaf size must be positive");
  Eigen::Vector3f lo = in.front();
  for (const auto& p : in) lo = lo.cwiseMin(p);

  // Pack three 21-bit cell indices into one key: 2^21 cells per axis is 100 km at 0.05 m.
  constexpr int64_t kBits = 21, kMax = (int64_t{1} << kBits) - 1;
  std::vector<std::pair<uint64_t, uint32_t>> keyed;
  keyed.reserve(in.size());
  for (uint32_t i = 0; i < in.size(); ++i) {
    const Eigen::Vector3f d = (in[i] - lo) / static_cast<float>(leaf);
    const int64_t ix = std::min<int64_t>(static_cast<int64_t>(d.x()), kMax);
    const int64_t iy = std::min<int64_t>(static_cast<int64_t>(d.y()), kMax);
    const int64_t iz = std::min<int64_t>(static_cast<int64_t>(d.z()), kMax);
    keyed.emplace_back(static_cast<uint64_t>((iz << (2 * kBits)) | (iy << kBits) | ix), i);
  }
  std::sort(keyed.begin(), keyed.end());

  Points out;
  for (size_t b = 0; b < keyed.size();) {
    size_t e = b;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (; e < keyed.size() && keyed[e].first == keyed[b].first; ++e) sum += in[keyed[e].second].cast<double>();
    out.push_back((sum / static_cast<double>(e - b)).cast<float>());
    b = e;
  }
  return out;
}

}  // namespace tomomap
