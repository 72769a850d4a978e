#include "hamming.hpp"

#include <algorithm>
#include <cstring>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#define TOMOMAP_HAVE_X86_KERNELS 1  ///< the AVX-512 and AVX2 kernels, chosen at run time
#endif

namespace tomomap {
namespace {

/// Nearest neighbours both ways: best_a[i] is the first j nearest a_i,
/// best_b[j] the first i nearest b_j.
struct Nearest {
  Nearest(int na, int nb) : best_a(static_cast<size_t>(na), -1), best_b(static_cast<size_t>(nb), -1) {}
  std::vector<int> best_a, best_b;
};

Nearest nearestScalar(const cv::Mat& a, const cv::Mat& b) {
  const int na = a.rows, nb = b.rows;
  const std::vector<uint64_t> wa = descriptorWords(a), wb = descriptorWords(b);
  Nearest n(na, nb);
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

#ifdef TOMOMAP_HAVE_X86_KERNELS
/// The vector kernels' keys: each distance travels with its index as one
/// key, distance << kIndexBits | index, so that the smallest key is the
/// nearest neighbour with the lowest index, the scalar scan's tie rule both
/// ways, and one unsigned min keeps it (a distance of 256 sets the key's top
/// bit). Lanes past the end of b hold the largest key; rows past the end of
/// a repeat a's last row, whose keys change no minimum.
constexpr int kIndexBits = 23;  ///< indices below 8 M; distances (at most 256) take the 9 bits above

/// b's descriptors word-major in blocks of `lanes` descriptors: block k holds
/// word 0 of descriptors k*lanes.. k*lanes+lanes-1, then word 1, and so on
/// (eight 32-bit words a descriptor); the last block padded with zeros.
std::vector<uint32_t> wordMajor(const cv::Mat& b, int lanes) {
  constexpr int kWords = 8;
  const int blocks = (b.rows + lanes - 1) / lanes;
  std::vector<uint32_t> out(static_cast<size_t>(blocks) * static_cast<size_t>(lanes) * kWords, 0);
  for (int j = 0; j < b.rows; ++j)
    for (int w = 0; w < kWords; ++w)
      std::memcpy(&out[static_cast<size_t>((j / lanes) * lanes * kWords + w * lanes + j % lanes)], b.ptr(j) + 4 * w, 4);
  return out;
}

/// The index a key carries.
int keyIndex(uint32_t key) { return static_cast<int>(key & ((1u << kIndexBits) - 1)); }

/// The index of the smallest of `lanes` keys: a row's nearest neighbour,
/// from the keys its lanes kept.
int nearestIndex(const uint32_t* keys, int lanes) { return keyIndex(*std::min_element(keys, keys + lanes)); }

/// The nearest a descriptor of each b descriptor, read off its kept key.
void keptIndices(const std::vector<uint32_t>& key_b, std::vector<int>& best_b) {
  for (size_t j = 0; j < best_b.size(); ++j) best_b[j] = keyIndex(key_b[j]);
}

/// The same scan, sixteen b descriptors against four a descriptors at a time
/// (AVX-512 with VPOPCNTDQ). b is laid out word-major in blocks of sixteen
/// 32-bit lanes (wordMajor), so one load brings the same word of sixteen
/// descriptors and serves four rows of a.
__attribute__((target("avx512f,avx512vpopcntdq"))) Nearest nearestAvx512(const cv::Mat& a, const cv::Mat& b) {
  constexpr int kLanes = 16, kRows = 4, kWords = 8;
  // Every lane, through the zero-masking forms: GCC 12's unmasked shift and min
  // warn of an uninitialised temporary.
  constexpr __mmask16 kAll = 0xFFFF;
  CV_Assert(a.rows < (1 << kIndexBits) && b.rows < (1 << kIndexBits));
  const int na = a.rows, nb = b.rows, blocks = (nb + kLanes - 1) / kLanes;
  const std::vector<uint32_t> wb = wordMajor(b, kLanes);
  std::vector<uint32_t> key_b(static_cast<size_t>(blocks) * kLanes, UINT32_MAX);
  Nearest n(na, nb);
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
      n.best_a[static_cast<size_t>(i0 + r)] = nearestIndex(keys, kLanes);
    }
  }
  keptIndices(key_b, n.best_b);
  return n;
}

/// The same scan on AVX2, eight b descriptors against four a descriptors at a
/// time, for CPUs without VPOPCNTDQ: each byte's bits counted by a sixteen-entry
/// table of nibbles (VPSHUFB), summed over the eight words byte by byte (at
/// most 64 a byte) and then over each lane's four bytes. The keys, the tie
/// rule and the padding are nearestAvx512's.
__attribute__((target("avx2"))) Nearest nearestAvx2(const cv::Mat& a, const cv::Mat& b) {
  constexpr int kLanes = 8, kRows = 4, kWords = 8;
  CV_Assert(a.rows < (1 << kIndexBits) && b.rows < (1 << kIndexBits));
  const int na = a.rows, nb = b.rows, blocks = (nb + kLanes - 1) / kLanes;
  const std::vector<uint32_t> wb = wordMajor(b, kLanes);
  std::vector<uint32_t> key_b(static_cast<size_t>(blocks) * kLanes, UINT32_MAX);
  Nearest n(na, nb);
  const __m256i none = _mm256_set1_epi32(-1), lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7),
                nibble = _mm256_set1_epi8(0x0F), ones8 = _mm256_set1_epi8(1), ones16 = _mm256_set1_epi16(1),
                bits = _mm256_setr_epi8(0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4, 0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2,
                                        3, 2, 3, 3, 4);
  // Lanes past the end of b: all ones, so that their keys are the largest.
  const __m256i past_end =
      _mm256_cmpgt_epi32(_mm256_add_epi32(lane, _mm256_set1_epi32((blocks - 1) * kLanes + 1)), _mm256_set1_epi32(nb));
  for (int i0 = 0; i0 < na; i0 += kRows) {
    uint32_t x[kRows][kWords];
    __m256i row_index[kRows], best[kRows];
#pragma GCC unroll 4
    for (int r = 0; r < kRows; ++r) {
      const int i = std::min(i0 + r, na - 1);
      std::memcpy(x[r], a.ptr(i), sizeof x[r]);
      row_index[r] = _mm256_set1_epi32(i);
      best[r] = none;
    }
    for (int k = 0; k < blocks; ++k) {
      const uint32_t* y = &wb[static_cast<size_t>(k) * kLanes * kWords];
      __m256i yw[kWords];
#pragma GCC unroll 8
      for (int w = 0; w < kWords; ++w) yw[w] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(y + w * kLanes));
      const __m256i j = _mm256_add_epi32(_mm256_set1_epi32(kLanes * k), lane);
      const __m256i pad = k == blocks - 1 ? past_end : _mm256_setzero_si256();
      uint32_t* kb = &key_b[static_cast<size_t>(k) * kLanes];
      __m256i nearest_b = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kb));
#pragma GCC unroll 4
      for (int r = 0; r < kRows; ++r) {
        __m256i bytes = _mm256_setzero_si256();
#pragma GCC unroll 8
        for (int w = 0; w < kWords; ++w) {
          const __m256i v = _mm256_xor_si256(yw[w], _mm256_set1_epi32(static_cast<int>(x[r][w])));
          bytes = _mm256_add_epi8(bytes, _mm256_shuffle_epi8(bits, _mm256_and_si256(v, nibble)));
          bytes = _mm256_add_epi8(bytes, _mm256_shuffle_epi8(bits, _mm256_and_si256(_mm256_srli_epi16(v, 4), nibble)));
        }
        const __m256i d = _mm256_slli_epi32(_mm256_madd_epi16(_mm256_maddubs_epi16(bytes, ones8), ones16), kIndexBits);
        best[r] = _mm256_min_epu32(best[r], _mm256_or_si256(_mm256_or_si256(d, j), pad));
        nearest_b = _mm256_min_epu32(nearest_b, _mm256_or_si256(d, row_index[r]));
      }
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(kb), nearest_b);
    }
    for (int r = 0; r < kRows && i0 + r < na; ++r) {
      alignas(32) uint32_t keys[kLanes];
      _mm256_store_si256(reinterpret_cast<__m256i*>(keys), best[r]);
      n.best_a[static_cast<size_t>(i0 + r)] = nearestIndex(keys, kLanes);
    }
  }
  keptIndices(key_b, n.best_b);
  return n;
}

bool haveAvx512Popcount() {
  static const bool yes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vpopcntdq");
  return yes;
}

bool haveAvx2() {
  static const bool yes = __builtin_cpu_supports("avx2");
  return yes;
}
#endif

}  // namespace

std::vector<uint64_t> descriptorWords(const cv::Mat& m) {
  std::vector<uint64_t> w(static_cast<size_t>(m.rows) * 4);
  for (int i = 0; i < m.rows; ++i) std::memcpy(&w[static_cast<size_t>(i) * 4], m.ptr(i), 32);
  return w;
}

bool hammingKernelRuns(HammingKernel kernel) {
#ifdef TOMOMAP_HAVE_X86_KERNELS
  switch (kernel) {
    case HammingKernel::Avx512:
      return haveAvx512Popcount();
    case HammingKernel::Avx2:
      return haveAvx2();
    case HammingKernel::Fastest:
    case HammingKernel::Scalar:
      return true;
  }
  return false;
#else
  return kernel == HammingKernel::Fastest || kernel == HammingKernel::Scalar;
#endif
}

std::vector<std::pair<int, int>> mutualNearest(const cv::Mat& a, const cv::Mat& b, HammingKernel kernel) {
  CV_Assert(a.empty() || (a.type() == CV_8U && a.cols == 32));
  CV_Assert(b.empty() || (b.type() == CV_8U && b.cols == 32));
  CV_Assert(hammingKernelRuns(kernel));
  std::vector<std::pair<int, int>> out;
  if (a.rows == 0 || b.rows == 0) return out;
  if (kernel == HammingKernel::Fastest)
    for (const HammingKernel k : {HammingKernel::Avx512, HammingKernel::Avx2, HammingKernel::Scalar})
      if (hammingKernelRuns(k)) {
        kernel = k;
        break;
      }
  const Nearest n = [&] {
    switch (kernel) {
#ifdef TOMOMAP_HAVE_X86_KERNELS
      case HammingKernel::Avx512:
        return nearestAvx512(a, b);
      case HammingKernel::Avx2:
        return nearestAvx2(a, b);
#else
      case HammingKernel::Avx512:
      case HammingKernel::Avx2:
#endif
      case HammingKernel::Fastest:  // resolved above
      case HammingKernel::Scalar:
        break;
    }
    return nearestScalar(a, b);
  }();
  for (int i = 0; i < a.rows; ++i) {
    const int j = n.best_a[static_cast<size_t>(i)];
    if (n.best_b[static_cast<size_t>(j)] == i) out.emplace_back(i, j);
  }
  return out;
}

}  // namespace tomomap
