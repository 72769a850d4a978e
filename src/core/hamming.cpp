#include "hamming.hpp"

#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define TOMOMAP_HAVE_AVX512_PATH 1
#endif

namespace tomomap {
namespace {

/// Nearest neighbours both ways: best_a[i] is the first j nearest a_i,
/// best_b[j] the first i nearest b_j.
struct Nearest {
  std::vector<int> best_a, best_b;
};

Nearest nearestScalar(const cv::Mat& a, const cv::Mat& b) {
  const int na = a.rows, nb = b.rows;
  const std::vector<uint64_t> wa = descriptorWords(a), wb = descriptorWords(b);
  Nearest n{std::vector<int>(static_cast<size_t>(na), -1), std::vector<int>(static_cast<size_t>(nb), -1)};
  std::vector<uint32_t> dist_b(static_cast<size_t>(nb), UINT32_MAX);
  for (int i = 0; i < na; ++i) {
    const uint64_t* x = &wa[static_cast<size_t>(i) * 4];
    uint32_t best = UINT32_MAX;
    for (int j = 0; j < nb; ++j) {
      const auto d = static_cast<uint32_t>(hamming256(x, &wb[static_cast<size_t>(j) * 4]));
      if (d < best) {
        best = d;
        n.best_a[static_cast<size_t>(i)] = j;
      }
      if (d < dist_b[static_cast<size_t>(j)]) {
        dist_b[static_cast<size_t>(j)] = d;
        n.best_b[static_cast<size_t>(j)] = i;
      }
    }
  }
  return n;
}

#ifdef TOMOMAP_HAVE_AVX512_PATH
/// The same scan, eight b descriptors at a time (AVX-512 with VPOPCNTDQ:
/// 5-6x the scalar loop). b is laid out word-major in blocks of eight so one
/// load brings the same word of eight descriptors; lanes past the end of b
/// read as the farthest possible distance. Ties resolve as in the scalar
/// scan: each lane keeps its first nearest j, and the lowest such j among the
/// lanes at the minimum wins; b's nearest i only moves on a strictly smaller distance.
__attribute__((target("avx512f,avx512vpopcntdq"))) Nearest nearestAvx512(const cv::Mat& a, const cv::Mat& b) {
  const int na = a.rows, nb = b.rows, blocks = (nb + 7) / 8;
  const std::vector<uint64_t> wa = descriptorWords(a);
  std::vector<uint64_t> wb(static_cast<size_t>(blocks) * 32, 0);
  for (int j = 0; j < nb; ++j)
    for (int w = 0; w < 4; ++w) {
      uint64_t v;
      std::memcpy(&v, b.ptr(j) + 8 * w, 8);
      wb[static_cast<size_t>((j / 8) * 32 + w * 8 + j % 8)] = v;
    }
  std::vector<uint64_t> dist_b(static_cast<size_t>(blocks) * 8, UINT64_MAX);
  std::vector<int64_t> best_b(static_cast<size_t>(blocks) * 8, -1);
  Nearest n{std::vector<int>(static_cast<size_t>(na), -1), {}};
  const __mmask8 last_valid = static_cast<__mmask8>((nb % 8 == 0) ? 0xFF : ((1u << (nb % 8)) - 1));
  const __m512i farthest = _mm512_set1_epi64(1024), lane = _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7);
  for (int i = 0; i < na; ++i) {
    const uint64_t* x = &wa[static_cast<size_t>(i) * 4];
    const __m512i x0 = _mm512_set1_epi64(static_cast<long long>(x[0])),
                  x1 = _mm512_set1_epi64(static_cast<long long>(x[1])),
                  x2 = _mm512_set1_epi64(static_cast<long long>(x[2])),
                  x3 = _mm512_set1_epi64(static_cast<long long>(x[3]));
    const __m512i self = _mm512_set1_epi64(i);
    __m512i best = farthest, best_j = _mm512_set1_epi64(-1);
    for (int k = 0; k < blocks; ++k) {
      const uint64_t* y = &wb[static_cast<size_t>(k) * 32];
      __m512i d =
          _mm512_add_epi64(_mm512_add_epi64(_mm512_popcnt_epi64(_mm512_xor_si512(x0, _mm512_loadu_si512(y))),
                                            _mm512_popcnt_epi64(_mm512_xor_si512(x1, _mm512_loadu_si512(y + 8)))),
                           _mm512_add_epi64(_mm512_popcnt_epi64(_mm512_xor_si512(x2, _mm512_loadu_si512(y + 16))),
                                            _mm512_popcnt_epi64(_mm512_xor_si512(x3, _mm512_loadu_si512(y + 24)))));
      if (k == blocks - 1) d = _mm512_mask_mov_epi64(farthest, last_valid, d);
      const __m512i j = _mm512_add_epi64(_mm512_set1_epi64(8LL * k), lane);
      const __mmask8 closer = _mm512_cmplt_epu64_mask(d, best);
      best = _mm512_mask_mov_epi64(best, closer, d);
      best_j = _mm512_mask_mov_epi64(best_j, closer, j);
      uint64_t* db = &dist_b[static_cast<size_t>(k) * 8];
      const __mmask8 nearer_b = _mm512_cmplt_epu64_mask(d, _mm512_loadu_si512(db));
      _mm512_mask_storeu_epi64(db, nearer_b, d);
      _mm512_mask_storeu_epi64(&best_b[static_cast<size_t>(k) * 8], nearer_b, self);
    }
    // Eight lanes reduced by hand (GCC 12's reduce intrinsics warn of an uninitialised temporary).
    alignas(64) uint64_t lane_best[8];
    alignas(64) int64_t lane_j[8];
    _mm512_store_si512(lane_best, best);
    _mm512_store_si512(lane_j, best_j);
    uint64_t m = 1024;
    int64_t first_j = -1;
    for (int l = 0; l < 8; ++l)
      if (lane_best[l] < m || (lane_best[l] == m && m < 1024 && lane_j[l] < first_j)) {
        m = lane_best[l];
        first_j = lane_j[l];
      }
    n.best_a[static_cast<size_t>(i)] = static_cast<int>(first_j);
  }
  n.best_b.assign(best_b.begin(), best_b.begin() + nb);
  return n;
}

bool haveAvx512Popcount() {
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vpopcntdq");
  return yes;
}
#endif

}  // namespace

std::vector<uint64_t> descriptorWords(const cv::Mat& m) {
  std::vector<uint64_t> w(static_cast<size_t>(m.rows) * 4);
  for (int i = 0; i < m.rows; ++i) std::memcpy(&w[static_cast<size_t>(i) * 4], m.ptr(i), 32);
  return w;
}

std::vector<std::pair<int, int>> mutualNearest(const cv::Mat& a, const cv::Mat& b, HammingKernel kernel) {
  CV_Assert(a.empty() || (a.type() == CV_8U && a.cols == 32));
  CV_Assert(b.empty() || (b.type() == CV_8U && b.cols == 32));
  std::vector<std::pair<int, int>> out;
  if (a.rows == 0 || b.rows == 0) return out;
#ifdef TOMOMAP_HAVE_AVX512_PATH
  const Nearest n =
      kernel == HammingKernel::Fastest && haveAvx512Popcount() ? nearestAvx512(a, b) : nearestScalar(a, b);
#else
  (void)kernel;
  const Nearest n = nearestScalar(a, b);
#endif
  for (int i = 0; i < a.rows; ++i) {
    const int j = n.best_a[static_cast<size_t>(i)];
    if (n.best_b[static_cast<size_t>(j)] == i) out.emplace_back(i, j);
  }
  return out;
}

bool vectorHammingAvailable() {
#ifdef TOMOMAP_HAVE_AVX512_PATH
  return haveAvx512Popcount();
#else
  return false;
#endif
}

}  // namespace tomomap
