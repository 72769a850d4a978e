#pragma once
// What makes a point cloud a map the matcher can work on.
#include <string>

#include "types.hpp"

namespace tomomap {

/// Smallest map the matcher accepts: below this there is nothing to slice.
constexpr size_t kMinMapPoints = 100;

/// Throws InputError (naming `what`) for an empty, too small or non-finite map.
void validateMap(const Points& points, const std::string& what);

/// Removes points with a NaN or infinite coordinate (organised clouds from
/// PCL-based SLAM carry them: a normal map, not a broken one); returns how
/// many. The order of the rest is kept.
size_t dropNonFinite(Points& points);

}  // namespace tomomap
