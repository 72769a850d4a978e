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

TEST(SpectrumCorrelation, AnOffsetsBoundIsTheSumOfItsSlicePairsFewerCells) {
  // a holds 3, 0 and 5 cells, b 2 and 4: offset -1 pairs a0 with b1 (at most
  // 3), 0 pairs a0 with b0 and a1 with b1 (2), 1 pairs a1 with b0 and a2 with
  // b1 (4), and 2 pairs a2 with b0 (2); half a cell more each, for rounding.
  const std::vector<int> a{3, 0, 5}, b{2, 4};
  EXPECT_EQ(offsetsPeakingWithin(a, b, 3, 4.5), (std::vector<char>{1, 0, 0, 0}));
  EXPECT_EQ(offsetsPeakingWithin(a, b, 0, 3), (std::vector<char>{0, 1, 0, 1}));
  EXPECT_EQ(offsetsPeakingWithin(a, b, 4.5, 100), (std::vector<char>{0, 0, 1, 0}));
}

TEST(SpectrumCorrelation, NoOffsetPeaksAboveItsBoundAndOneStackOnItselfReachesIt) {
  // Random binary slices, zero-padded as the search pads them: every
  // offset's correlation peaks within its bound, and a stack laid on itself
  // at offset 0 scores every cell it has.
  const cv::Size size(12, 10), padded(24, 20);
  cv::RNG rng(6);
  const auto stack = [&](int n) {
    std::vector<cv::Mat> spectra(static_cast<size_t>(n));
    std::vector<int> cells(spectra.size());
    for (size_t k = 0; k < spectra.size(); ++k) {
      cv::Mat noise(size, CV_32F), big = cv::Mat::zeros(padded, CV_32F);
      rng.fill(noise, cv::RNG::UNIFORM, 0, 2);
      cv::Mat(noise > 1.4).convertTo(big(cv::Rect(cv::Point(0, 0), size)), CV_32F, 1.0 / 255);
      cells[k] = cv::countNonZero(big);
      cv::dft(big, spectra[k]);
    }
    return std::pair{spectra, cells};
  };
  const auto [a, a_cells] = stack(4);
  const auto [b, b_cells] = stack(3);
  const auto peaks = [](const std::vector<cv::Mat>& x, const std::vector<cv::Mat>& y) {
    std::vector<cv::Mat> sums;
    std::vector<char> any;
    correlateStacks(x, y, sums, any);
    std::vector<double> out(sums.size(), 0);
    for (size_t at = 0; at < sums.size(); ++at) {
      cv::Mat corr;
      cv::dft(sums[at], corr, cv::DFT_INVERSE | cv::DFT_REAL_OUTPUT | cv::DFT_SCALE);
      cv::minMaxLoc(corr, nullptr, &out[at]);
    }
    return out;
  };
  const std::vector<double> ab = peaks(a, b);
  for (size_t at = 0; at < ab.size(); ++at)
    EXPECT_TRUE(offsetsPeakingWithin(a_cells, b_cells, ab[at], 1e9)[at]) << "offset index " << at << " peak " << ab[at];
  const std::vector<double> aa = peaks(a, a);
  int all = 0;
  for (int n : a_cells) all += n;
  EXPECT_NEAR(aa[3], all, 1e-3);  // offset 0 of two 4-slice stacks
  EXPECT_FALSE(offsetsPeakingWithin(a_cells, a_cells, all + 1, 1e9)[3]);
}
