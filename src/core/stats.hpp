#pragma once
// Summary statistics shared by every report (eval's summary, the box plots).
#include <algorithm>
#include <cmath>
#include <vector>

namespace tomomap {

/// The q-quantile (0 <= q <= 1) of `values`, NaNs left out, interpolated
/// linearly between order statistics (the definition of R's default and
/// NumPy's "linear"): the median of {96, 188} is 142. NaN when nothing is left.
inline double quantile(std::vector<double> values, double q) {
  values.erase(std::remove_if(values.begin(), values.end(), [](double x) { return std::isnan(x); }), values.end());
  if (values.empty()) return NAN;
  std::sort(values.begin(), values.end());
  const double at = q * static_cast<double>(values.size() - 1);
  const size_t i = static_cast<size_t>(std::floor(at));
  const size_t j = std::min(i + 1, values.size() - 1);
  return values[i] + (at - static_cast<double>(i)) * (values[j] - values[i]);
}

}  // namespace tomomap
