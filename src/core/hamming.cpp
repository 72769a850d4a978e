#include "hamming.hpp"

#include <algorithm>
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
/// The same scan, sixteen b descriptors against four a descriptors at a time
/// (AVX-512 with VPOPCNTDQ). b is laid out word-major in blocks of sixteen
/// 32-bit lanes, so one load brings the same word of sixteen descriptors and
/// serves four rows of a. Each distance travels with its index as one key,
/// distance << kIndexBits | index: the smallest key is the nearest neighbour
/// with the lowest index, the scalar scan's tie rule both ways, and one
/// unsigned min keeps it. Lanes past the end of b hold the largest key; rows
/// past the end of a repeat a's last row, whose keys change no minimum.
constexpr int kIndexBits = 23;  ///< indices below 8 M; distances (at most 256) take the 9 bits above

__attribute__((target("avx512f,avx512vpopcntdq"))) Nearest nearestAvx512(const cv::Mat& a, const cv::Mat& b) {
  constexpr int kLanes = 16, kRows = 4, kWords = 8;
  // Every lane, through the zero-masking forms: GCC 12's unmasked shift and min
  // warn of an uninitialised temporary.
  constexpr __mmask16 kAll = 0xFFFF;
  CV_Assert(a.rows < (1 << kIndexBits) && b.rows < (1 << kIndexBits));
  const int na = a.rows, nb = b.rows, blocks = (nb + kLanes - 1) / kLanes;
  std::vector<uint32_t> wb(static_cast<size_t>(blocks) * kLanes * kWords, 0);
  for (int j = 0; j < nb; ++j)
    for (int w = 0; w < kWords; ++w)
      std::memcpy(&wb[static_cast<size_t>((j / kLanes) * kLanes * kWords + w * kLanes + j % kLanes)], b.ptr(j) + 4 * w,
                  4);
  std::vector<uint32_t> key_b(static_cast<size_t>(blocks) * kLanes, UINT32_MAX);
  Nearest n{std::vector<int>(static_cast<size_t>(na), -1), std::vector<int>(static_cast<size_t>(nb), -1)};
  const __mmask16 last_valid = static_cast<__mmask16>(nb % kLanes == 0 ? 0xFFFF : (1u << (nb % kLanes)) - 1);
  const __m512i none = _mm512_set1_epi32(-1),
                lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  for (int i0 = 0; i0 < na; i0 += kRows) {
    uint32_t x[kRows][kWords];
    __m512i row_index[kRows], best[kRows];
#pragma GCC unroll 4
    for (int r = 0; r < kRows; ++r) {
      const int i = std::min(i0 + r, na - 1);
      std::memcpy(x[r], a.ptr(i), sizeof x[r]);
      row_index[r] = _mm512_set1_epi32(i);
      best[r] = none;
    }
    for (int k = 0; k < blocks; ++k) {
      const uint32_t* y = &wb[static_cast<size_t>(k) * kLanes * kWords];
      __m512i yw[kWords];
#pragma GCC unroll 8
      for (int w = 0; w < kWords; ++w) yw[w] = _mm512_loadu_si512(y + w * kLanes);
      const __m512i j = _mm512_add_epi32(_mm512_set1_epi32(kLanes * k), lane);
      uint32_t* kb = &key_b[static_cast<size_t>(k) * kLanes];
      __m512i nearest_b = _mm512_loadu_si512(kb);
#pragma GCC unroll 4
      for (int r = 0; r < kRows; ++r) {
        __m512i d = _mm512_popcnt_epi32(_mm512_xor_si512(yw[0], _mm512_set1_epi32(static_cast<int>(x[r][0]))));
#pragma GCC unroll 8
        for (int w = 1; w < kWords; ++w)
          d = _mm512_add_epi32(
              d, _mm512_popcnt_epi32(_mm512_xor_si512(yw[w], _mm512_set1_epi32(static_cast<int>(x[r][w])))));
        d = _mm512_maskz_slli_epi32(kAll, d, kIndexBits);
        const __m512i key_a = k == blocks - 1 ? _mm512_mask_or_epi32(none, last_valid, d, j) : _mm512_or_si512(d, j);
        best[r] = _mm512_maskz_min_epu32(kAll, best[r], key_a);
        nearest_b = _mm512_maskz_min_epu32(kAll, nearest_b, _mm512_or_si512(d, row_index[r]));
      }
      _mm512_storeu_si512(kb, nearest_b);
    }
    for (int r = 0; r < kRows && i0 + r < na; ++r) {
      // Sixteen lanes reduced by hand (GCC 12's reduce intrinsics warn of an uninitialised temporary).
      alignas(64) uint32_t keys[kLanes];
      _mm512_store_si512(keys, best[r]);
      const uint32_t m = *std::min_element(keys, keys + kLanes);
      n.best_a[static_cast<size_t>(i0 + r)] = static_cast<int>(m & ((1u << kIndexBits) - 1));
    }
  }
  for (int j = 0; j < nb; ++j)
    n.best_b[static_cast<size_t>(j)] = static_cast<int>(key_b[static_cast<size_t>(j)] & ((1u << kIndexBits) - 1));
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
