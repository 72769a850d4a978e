#include "hamming.hpp"

#include <cstdint>
#include <cstring>

namespace tomomap {

std::vector<std::pair<int, int>> mutualNearest(const cv::Mat& a, const cv::Mat& b) {
  CV_Assert(a.empty() || (a.type() == CV_8U && a.cols == 32));
  CV_Assert(b.empty() || (b.type() == CV_8U && b.cols == 32));
  const int na = a.rows, nb = b.rows;
  std::vector<std::pair<int, int>> out;
  if (na == 0 || nb == 0) return out;

  // Copy into aligned 4 x 64-bit words so the inner loop is four XOR+POPCNT.
  std::vector<uint64_t> wa(static_cast<size_t>(na) * 4), wb(static_cast<size_t>(nb) * 4);
  for (int i = 0; i < na; ++i) std::memcpy(&wa[static_cast<size_t>(i) * 4], a.ptr(i), 32);
  for (int j = 0; j < nb; ++j) std::memcpy(&wb[static_cast<size_t>(j) * 4], b.ptr(j), 32);

  std::vector<int> best_a(static_cast<size_t>(na), -1), best_b(static_cast<size_t>(nb), -1);
  std::vector<uint32_t> dist_b(static_cast<size_t>(nb), UINT32_MAX);
  for (int i = 0; i < na; ++i) {
    const uint64_t* x = &wa[static_cast<size_t>(i) * 4];
    uint32_t best = UINT32_MAX;
    for (int j = 0; j < nb; ++j) {
      const uint64_t* y = &wb[static_cast<size_t>(j) * 4];
      const auto d = static_cast<uint32_t>(__builtin_popcountll(x[0] ^ y[0]) + __builtin_popcountll(x[1] ^ y[1]) +
                                           __builtin_popcountll(x[2] ^ y[2]) + __builtin_popcountll(x[3] ^ y[3]));
      if (d < best) {
        best = d;
        best_a[static_cast<size_t>(i)] = j;
      }
      if (d < dist_b[static_cast<size_t>(j)]) {
        dist_b[static_cast<size_t>(j)] = d;
        best_b[static_cast<size_t>(j)] = i;
      }
    }
  }
  for (int i = 0; i < na; ++i) {
    const int j = best_a[static_cast<size_t>(i)];
    if (best_b[static_cast<size_t>(j)] == i) out.emplace_back(i, j);
  }
  return out;
}

}  // namespace tomomap
