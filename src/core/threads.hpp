#pragma once
// How many threads a setting of `threads` means: the one place where 0 becomes every core.
#include <omp.h>

namespace tomomap {

/// `threads`, or every core OpenMP has where it is 0 (or less).
inline int resolvedThreads(int threads) { return threads > 0 ? threads : omp_get_max_threads(); }

}  // namespace tomomap
