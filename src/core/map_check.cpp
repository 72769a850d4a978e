#include "map_check.hpp"

#include <algorithm>

namespace tomomap {

void validateMap(const Points& points, const std::string& what) {
  for (size_t i = 0; i < points.size(); ++i) {
    if (!points[i].allFinite()) {
      const auto bad =
          std::count_if(points.begin(), points.end(), [](const Eigen::Vector3f& p) { return !p.allFinite(); });
      throw InputError(what + ": " + std::to_string(bad) + " of " + std::to_string(points.size()) +
                       " points are NaN or infinite (first at index " + std::to_string(i) + ")");
    }
  }
  if (points.empty()) throw InputError(what + ": map is empty");
  if (points.size() < kMinMapPoints)
    throw InputError(what + ": map has only " + std::to_string(points.size()) + " points; at least " +
                     std::to_string(kMinMapPoints) + " are needed");
}

size_t dropNonFinite(Points& points) {
  const auto kept =
      std::remove_if(points.begin(), points.end(), [](const Eigen::Vector3f& p) { return !p.allFinite(); });
  const auto dropped = static_cast<size_t>(points.end() - kept);
  points.erase(kept, points.end());
  return dropped;
}

}  // namespace tomomap
