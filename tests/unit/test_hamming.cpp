#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <random>
#include <tuple>

#include "core/hamming.hpp"

using namespace tomomap;

static int hamming(const cv::Mat& a, int i, const cv::Mat& b, int j) {
  return static_cast<int>(cv::norm(a.row(i), b.row(j), cv::NORM_HAMMING));
}

TEST(Hamming, MutualNearestMatchesBruteForce) {
  cv::RNG rng(7);
  cv::Mat a(300, 32, CV_8U), b(250, 32, CV_8U);
  rng.fill(a, cv::RNG::UNIFORM, 0, 256);
  rng.fill(b, cv::RNG::UNIFORM, 0, 256);
  a.rowRange(0, 100).copyTo(b.rowRange(50, 150));  // 100 exact pairs
  // Reference: the first-lowest nearest neighbour each way, via OpenCV's norm.
  std::vector<std::pair<int, int>> expected;
  for (int i = 0; i < a.rows; ++i) {
    int bj = 0;
    for (int j = 1; j < b.rows; ++j)
      if (hamming(a, i, b, j) < hamming(a, i, b, bj)) bj = j;
    int bi = 0;
    for (int k = 1; k < a.rows; ++k)
      if (hamming(a, k, b, bj) < hamming(a, bi, b, bj)) bi = k;
    if (bi == i) expected.emplace_back(i, bj);
  }
  const auto got = mutualNearest(a, b);
  EXPECT_EQ(got, expected);
  for (int i = 0; i < 100; ++i) EXPECT_NE(std::find(got.begin(), got.end(), std::make_pair(i, i + 50)), got.end());
}

TEST(Hamming, EmptySetsGiveNoMatches) {
  cv::Mat a(5, 32, CV_8U, cv::Scalar(1));
  EXPECT_TRUE(mutualNearest(a, cv::Mat()).empty());
  EXPECT_TRUE(mutualNearest(cv::Mat(), a).empty());
}

TEST(Hamming, EachVectorKernelGivesTheScalarKernelsMatchesTiesIncluded) {
  std::vector<HammingKernel> kernels;
  for (const HammingKernel k : {HammingKernel::Avx512, HammingKernel::Avx2})
    if (hammingKernelRuns(k)) kernels.push_back(k);
  if (kernels.empty()) GTEST_SKIP() << "this CPU has neither AVX-512 VPOPCNTDQ nor AVX2: only the scalar kernel runs";
  cv::RNG rng(11);
  // Few distinct bytes make many equal distances, so the tie rules are exercised;
  // sizes that are not multiples of the kernels' 16 or 8 lanes or 4 rows
  // exercise the last, partial block and the last rows.
  for (const HammingKernel kernel : kernels)
    for (const auto& [na, nb, values] :
         {std::tuple{1, 1, 256}, std::tuple{37, 13, 2}, std::tuple{64, 64, 3}, std::tuple{500, 999, 256},
          std::tuple{9, 300, 4}, std::tuple{3, 16, 2}, std::tuple{6, 17, 2}, std::tuple{5, 7, 2}, std::tuple{2, 9, 3},
          std::tuple{1000, 1000, 256}}) {
      cv::Mat a(na, 32, CV_8U), b(nb, 32, CV_8U);
      rng.fill(a, cv::RNG::UNIFORM, 0, values);
      rng.fill(b, cv::RNG::UNIFORM, 0, values);
      EXPECT_EQ(mutualNearest(a, b, kernel), mutualNearest(a, b, HammingKernel::Scalar))
          << (kernel == HammingKernel::Avx512 ? "AVX-512 " : "AVX2 ") << na << " x " << nb << ", bytes below "
          << values;
    }
  // The largest distance, 256 (all bits apart), sets a key's top bit: a
  // signed minimum would rank it nearest. Rows at 256 come first, so that
  // the lower index does not hide it; the row at 255 is the nearest.
  cv::Mat zeros(3, 32, CV_8U, cv::Scalar(0)), far(11, 32, CV_8U, cv::Scalar(255));
  far.at<uint8_t>(9, 31) = 0x7F;
  for (const HammingKernel kernel : kernels)
    EXPECT_EQ(mutualNearest(zeros, far, kernel), (std::vector<std::pair<int, int>>{{0, 9}}));
  EXPECT_EQ(mutualNearest(zeros, far, HammingKernel::Scalar), (std::vector<std::pair<int, int>>{{0, 9}}));
}
