#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/core.hpp>

#include "core/spectrum_correlation.hpp"

using namespace tomomap;

namespace {

/// Spectra of random binary images of `size`; those listed in `empty` left empty, as the search leaves an empty
/// slice's.
std::vector<cv::Mat> spectra(int n, cv::Size size, std::initializer_list<int> empty, uint64_t seed) {
  cv::RNG rng(seed);
  std::vector<cv::Mat> out(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    if (std::find(empty.begin(), empty.end(), k) != empty.end()) continue;
    cv::Mat image(size, CV_32F);
    rng.fill(image, cv::RNG::UNIFORM, 0, 2);
    cv::Mat binary;
    cv::Mat(image > 1.0).convertTo(binary, CV_32F, 1.0 / 255);
    cv::dft(binary, out[static_cast<size_t>(k)]);
  }
  return out;
}

}  // namespace

TEST(SpectrumCorrelation, SumsWhatMulSpectrumsGivesOnEveryShape) {
  // Odd and even widths and heights: the packed spectrum's first and last
  // columns and rows are laid out differently for each.
  for (const cv::Size size : {cv::Size(8, 6), cv::Size(9, 6), cv::Size(8, 5), cv::Size(15, 9), cv::Size(1, 4)}) {
    const std::vector<cv::Mat> a = spectra(4, size, {2}, 1), b = spectra(3, size, {0}, 2);
    std::vector<cv::Mat> sums;
    std::vector<char> any;
    correlateStacks(a, b, sums, any);
    ASSERT_EQ(sums.size(), 6u);
    for (int dz = -2; dz <= 3; ++dz) {
      cv::Mat expected, product;
      for (int z = std::max(0, -dz); z < 3 && z + dz < 4; ++z) {
        const cv::Mat &x = a[static_cast<size_t>(z + dz)], &y = b[static_cast<size_t>(z)];
        if (x.empty() || y.empty()) continue;
        cv::mulSpectrums(x, y, product, 0, true);
        if (expected.empty())
          product.copyTo(expected);
        else
          expected += product;
      }
      const size_t at = static_cast<size_t>(dz + 2);
      ASSERT_EQ(any[at] != 0, !expected.empty()) << size << " dz " << dz;
      if (!expected.empty()) {
        // Float sums of float products: what is left is rounding.
        EXPECT_LE(cv::norm(sums[at], expected, cv::NORM_INF | cv::NORM_RELATIVE), 1e-6) << size << " dz " << dz;
      }
    }
  }
}

TEST(SpectrumCorrelation, AnOffsetWithoutAPairOfNonEmptySlicesIsNotSummed) {
  // b's only non-empty slice is its first, a's its first two: only at dz 0
  // and 1 does a non-empty slice meet another.
  const std::vector<cv::Mat> a = spectra(4, cv::Size(6, 6), {2, 3}, 3), b = spectra(2, cv::Size(6, 6), {1}, 4);
  std::vector<cv::Mat> sums;
  std::vector<char> any;
  correlateStacks(a, b, sums, any);
  ASSERT_EQ(any.size(), 5u);
  EXPECT_EQ(std::vector<char>(any.begin(), any.end()), (std::vector<char>{0, 1, 1, 0, 0}));
}

TEST(SpectrumCorrelation, StacksOfEmptySlicesSumNothing) {
  // A peer's map may come as slices without a cell: no offset is summed.
  const std::vector<cv::Mat> empty(3), b = spectra(2, cv::Size(6, 6), {}, 5);
  std::vector<cv::Mat> sums;
  std::vector<char> any;
  correlateStacks(empty, b, sums, any);
  EXPECT_EQ(std::vector<char>(any.begin(), any.end()), std::vector<char>(4, 0));
  correlateStacks(b, empty, sums, any);
  EXPECT_EQ(std::vector<char>(any.begin(), any.end()), std::vector<char>(4, 0));
}
