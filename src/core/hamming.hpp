#pragma once
// Mutual nearest neighbours between two sets of 256-bit binary descriptors.
#include <cstdint>
#include <opencv2/core.hpp>
#include <utility>
#include <vector>

namespace tomomap {

/// Hamming distance of two 256-bit descriptors held as four 64-bit words.
/// Files that call it are built with POPCNT where the CPU family has it.
inline int hamming256(const uint64_t* x, const uint64_t* y) {
  return __builtin_popcountll(x[0] ^ y[0]) + __builtin_popcountll(x[1] ^ y[1]) + __builtin_popcountll(x[2] ^ y[2]) +
         __builtin_popcountll(x[3] ^ y[3]);
}

/// N x 32 CV_8U descriptors as four 64-bit words each, row after row: the
/// layout hamming256 reads.
std::vector<uint64_t> descriptorWords(const cv::Mat& m);

/// Pairs (index in a, index in b) that are each other's nearest neighbour in
/// Hamming distance; ties go to the lower index. Both Mats are N x 32 CV_8U.
/// One pass over the distance matrix gives both directions, where OpenCV's
/// cross-checking BFMatcher runs two full searches: this is the matcher's
/// innermost loop (n_target x n_source slice pairs), so the factor matters.
/// Where the CPU has AVX-512 with VPOPCNTDQ, sixty-four distances are
/// computed at once, with AVX2 thirty-two (checked at run time, so one binary
/// runs on any x86-64); the answer is the same either way. A kernel named
/// other than Fastest is used as named (tests and benchmarks compare them);
/// it must run here (hammingKernelRuns).
enum class HammingKernel { Fastest, Avx512, Avx2, Scalar };
std::vector<std::pair<int, int>> mutualNearest(const cv::Mat& a, const cv::Mat& b,
                                               HammingKernel kernel = HammingKernel::Fastest);

/// Whether mutualNearest's `kernel` runs on this CPU.
bool hammingKernelRuns(HammingKernel kernel);

}  // namespace tomomap
