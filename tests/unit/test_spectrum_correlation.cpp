#include <gtest/gtest.h>

#include <algorithm>
#include <complex>
#include <opencv2/core.hpp>

#include "core/spectrum_correlation.hpp"

using namespace tomomap;

namespace {

/// Half spectra of random binary images of rows x cols; those listed in
/// `empty` left empty, as the search leaves an empty slice's.
std::vector<Spectrum> spectra(int n, int rows, int cols, std::initializer_list<int> empty, uint64_t seed) {
  cv::RNG rng(seed);
  const RealFft fft(rows, cols);
  std::vector<Spectrum> out(static_cast<size_t>(n));
  for (int k = 0; k < n; ++k) {
    if (std::find(empty.begin(), empty.end(), k) != empty.end()) continue;
    RealImage image(fft.imageSize());
    for (float& v : image) v = rng.uniform(0, 2) == 1 ? 1.f : 0.f;
    fft.forward(image, out[static_cast<size_t>(k)]);
  }
  return out;
}

}  // namespace

TEST(SpectrumCorrelation, SumsEveryOffsetsProductsOnEveryShape) {
  // Odd and even widths and heights: a half spectrum's row holds cols / 2 + 1 values.
  for (const auto& [rows, cols] : {std::pair{6, 8}, {6, 9}, {5, 8}, {9, 15}, {4, 1}}) {
    const std::vector<Spectrum> a = spectra(4, rows, cols, {2}, 1), b = spectra(3, rows, cols, {0}, 2);
    const size_t row = static_cast<size_t>(cols / 2 + 1);
    std::vector<Spectrum> sums;
    std::vector<char> any;
    correlateStacks(a, b, row, sums, any);
    ASSERT_EQ(sums.size(), 6u);
    for (int dz = -2; dz <= 3; ++dz) {
      std::vector<std::complex<double>> expected;
      for (int z = std::max(0, -dz); z < 3 && z + dz < 4; ++z) {
        const Spectrum &x = a[static_cast<size_t>(z + dz)], &y = b[static_cast<size_t>(z)];
        if (x.empty() || y.empty()) continue;
        expected.resize(x.size());
        for (size_t i = 0; i < x.size(); ++i)
          expected[i] += std::complex<double>(x[i]) * std::conj(std::complex<double>(y[i]));
      }
      const size_t at = static_cast<size_t>(dz + 2);
      ASSERT_EQ(any[at] != 0, !expected.empty()) << rows << " x " << cols << " dz " << dz;
      if (expected.empty()) continue;
      ASSERT_EQ(sums[at].size(), expected.size());
      double largest = 0, off = 0;
      for (size_t i = 0; i < expected.size(); ++i) {
        largest = std::max(largest, std::abs(expected[i]));
        off = std::max(off, std::abs(std::complex<double>(sums[at][i]) - expected[i]));
      }
      // Float sums of float products: what is left is rounding.
      EXPECT_LE(off, 1e-6 * largest) << rows << " x " << cols << " dz " << dz;
    }
  }
}

TEST(SpectrumCorrelation, AnOffsetWithoutAPairOfNonEmptySlicesIsNotSummed) {
  // b's only non-empty slice is its first, a's its first two: only at dz 0
  // and 1 does a non-empty slice meet another.
  const std::vector<Spectrum> a = spectra(4, 6, 6, {2, 3}, 3), b = spectra(2, 6, 6, {1}, 4);
  std::vector<Spectrum> sums;
  std::vector<char> any;
  correlateStacks(a, b, 4, sums, any);
  ASSERT_EQ(any.size(), 5u);
  EXPECT_EQ(std::vector<char>(any.begin(), any.end()), (std::vector<char>{0, 1, 1, 0, 0}));
}

TEST(SpectrumCorrelation, StacksOfEmptySlicesSumNothing) {
  // A peer's map may come as slices without a cell: no offset is summed.
  const std::vector<Spectrum> empty(3), b = spectra(2, 6, 6, {}, 5);
  std::vector<Spectrum> sums;
  std::vector<char> any;
  correlateStacks(empty, b, 4, sums, any);
  EXPECT_EQ(std::vector<char>(any.begin(), any.end()), std::vector<char>(4, 0));
  correlateStacks(b, empty, 4, sums, any);
  EXPECT_EQ(std::vector<char>(any.begin(), any.end()), std::vector<char>(4, 0));
}

TEST(SpectrumCorrelation, TheInverseOfAProductIsTheCorrelationAtEveryShift) {
  // Two binary images of 12 x 18, the second the first shifted by (3, -2):
  // back from the spectra, every shift counts its coincident cells, most at (3, -2).
  const int rows = 12, cols = 18;
  const RealFft fft(rows, cols);
  RealImage a(fft.imageSize(), 0.f), b(a);
  cv::RNG rng(6);
  for (int v = 2; v < 8; ++v)
    for (int u = 4; u < 12; ++u)
      if (rng.uniform(0, 2) == 1)
        a[static_cast<size_t>(v * cols + u)] = 1.f, b[static_cast<size_t>((v + 2) * cols + u - 3)] = 1.f;
  std::vector<Spectrum> sa(1), sb(1), sums;
  fft.forward(a, sa[0]);
  fft.forward(b, sb[0]);
  std::vector<char> any;
  correlateStacks(sa, sb, static_cast<size_t>(cols / 2 + 1), sums, any);
  RealImage back;
  fft.inverse(sums[0], back);
  for (int dy = 0; dy < rows; ++dy)
    for (int dx = 0; dx < cols; ++dx) {
      double coincide = 0;  // sum over pixels of a(p + d) b(p), wrapping around
      for (int v = 0; v < rows; ++v)
        for (int u = 0; u < cols; ++u)
          coincide +=
              a[static_cast<size_t>(((v + dy) % rows) * cols + (u + dx) % cols)] * b[static_cast<size_t>(v * cols + u)];
      ASSERT_NEAR(back[static_cast<size_t>(dy * cols + dx)] / static_cast<double>(fft.imageSize()), coincide, 1e-3)
          << dx << ", " << dy;
    }
  const size_t top = static_cast<size_t>(std::max_element(back.begin(), back.end()) - back.begin());
  EXPECT_EQ(top % cols, 3u);
  EXPECT_EQ(top / cols, static_cast<size_t>(rows - 2));
}

TEST(SpectrumCorrelation, TransformSizesArePowersOfTwoTimesOneThreeFiveOrNine) {
  EXPECT_EQ(RealFft::fastSize(1), 2);
  EXPECT_EQ(RealFft::fastSize(130), 144);  // OpenCV's optimal size was 135 = 3^3 5
  EXPECT_EQ(RealFft::fastSize(140), 144);
  EXPECT_EQ(RealFft::fastSize(145), 160);  // not 162 = 2 3^4, twice as slow
  EXPECT_EQ(RealFft::fastSize(97), 128);
  EXPECT_EQ(RealFft::fastSize(64), 64);
  EXPECT_EQ(RealFft::fastSize(65), 72);
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
  const int rows = 10, cols = 12;
  const RealFft fft(20, 24);  // zero-padded
  cv::RNG rng(6);
  const auto stack = [&](int n) {
    std::vector<Spectrum> spectra(static_cast<size_t>(n));
    std::vector<int> cells(spectra.size());
    for (size_t k = 0; k < spectra.size(); ++k) {
      RealImage big(fft.imageSize(), 0.f);
      for (int v = 0; v < rows; ++v)
        for (int u = 0; u < cols; ++u)
          if (rng.uniform(0.0, 2.0) > 1.4) big[static_cast<size_t>(v * fft.cols() + u)] = 1.f, ++cells[k];
      fft.forward(big, spectra[k]);
    }
    return std::pair{spectra, cells};
  };
  const auto [a, a_cells] = stack(4);
  const auto [b, b_cells] = stack(3);
  const auto peaks = [&fft](const std::vector<Spectrum>& x, const std::vector<Spectrum>& y) {
    std::vector<Spectrum> sums;
    std::vector<char> any;
    correlateStacks(x, y, static_cast<size_t>(fft.cols() / 2 + 1), sums, any);
    std::vector<double> out(sums.size(), 0);
    for (size_t at = 0; at < sums.size(); ++at) {
      RealImage corr;
      fft.inverse(sums[at], corr);
      out[at] = *std::max_element(corr.begin(), corr.end()) / static_cast<double>(fft.imageSize());
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
