#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>
#include <set>

#include "core/bit_raster.hpp"

using namespace tomomap;

namespace {

/// A raster whose rows are not a whole number of words (rows share words).
SliceGrid oddGrid() {
  SliceGrid g;
  g.cell = 0.1;
  g.width = 131;
  g.height = 37;
  return g;
}

/// `n` distinct random cells of `g`, three of them on its border and corners.
std::vector<uint32_t> randomCells(const SliceGrid& g, int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<uint32_t> any(0, static_cast<uint32_t>(g.width * g.height - 1));
  std::set<uint32_t> cells{0, static_cast<uint32_t>(g.width - 1), static_cast<uint32_t>(g.width * g.height - 1)};
  while (static_cast<int>(cells.size()) < n) cells.insert(any(rng));
  return {cells.begin(), cells.end()};
}

}  // namespace

TEST(BitRaster, AStampedRasterIsOpenCvsDilation) {
  // The landings read a target cell's pixel in the bits where they read
  // cv::dilate's image before: the two must set the very same pixels.
  EXPECT_EQ(BitRaster::disk(1.5).size(), 5U) << "a cross";
  const SliceGrid g = oddGrid();
  const std::vector<uint32_t> cells = randomCells(g, 150, 7);
  for (double radius : {1.5, 2.5}) {  // the landings' 1.5 cells: a cross; 2.5: a disk wider than tall
    const int r = static_cast<int>(radius);
    const BitRaster bits(g, cells, BitRaster::disk(radius));
    cv::Mat dilated;
    cv::dilate(SliceStack{g, {cells}}.image(0), dilated,
               cv::getStructuringElement(cv::MORPH_ELLIPSE, cv::Size(2 * r + 1, 2 * r + 1)));
    int set = 0;
    for (int v = 0; v < g.height; ++v)
      for (int u = 0; u < g.width; ++u) {
        const bool expected = dilated.at<uint8_t>(v, u) != 0;
        ASSERT_EQ(bits.test(static_cast<size_t>(v * g.width + u)), expected)
            << "radius " << radius << " at " << u << ", " << v;
        set += expected;
      }
    EXPECT_GT(set, static_cast<int>(cells.size()));  // it grew
  }
}

TEST(BitRaster, ARowsSetPixelsAreListedInOrderWithinTheRange) {
  const SliceGrid g = oddGrid();
  const std::vector<uint32_t> cells = randomCells(g, 900, 11);
  const BitRaster bits(g, cells);
  const std::set<uint32_t> occupied(cells.begin(), cells.end());
  for (int v = 0; v < g.height; ++v)
    for (const auto& [lo, hi] : {std::pair{0, g.width - 1}, std::pair{3, 70}, std::pair{63, 64}, std::pair{64, 127},
                                 std::pair{128, 130}, std::pair{17, 17}}) {
      std::vector<int> listed, expected;
      bits.forEachSet(v, lo, hi, [&](int u) { listed.push_back(u); });
      for (int u = lo; u <= hi; ++u)
        if (occupied.count(static_cast<uint32_t>(v * g.width + u))) expected.push_back(u);
      ASSERT_EQ(listed, expected) << "row " << v << " [" << lo << ", " << hi << "]";
    }
}

TEST(BitRaster, NoCellsKeepNoWordsAndAddingIsTheUnion) {
  const SliceGrid g = oddGrid();
  EXPECT_TRUE(BitRaster(g, {}).empty());
  const std::vector<uint32_t> a = randomCells(g, 40, 1), b = randomCells(g, 40, 2);
  BitRaster both;
  both.add(BitRaster(g, {}));
  EXPECT_TRUE(both.empty());
  both.add(BitRaster(g, a));
  both.add(BitRaster(g, b));
  std::set<uint32_t> either(a.begin(), a.end());
  either.insert(b.begin(), b.end());
  for (uint32_t p = 0; p < static_cast<uint32_t>(g.width * g.height); ++p)
    ASSERT_EQ(both.test(p), either.count(p) == 1) << "pixel " << p;
}

// Choosing a pose's height reads a window of slices down a pixel's column:
// it must read each raster's own bit, across the words a column spans (130
// rasters: three words), and none where a raster is empty.
TEST(BitColumns, AWindowDownAColumnReadsEachRastersOwnPixel) {
  const SliceGrid g = oddGrid();
  std::vector<BitRaster> rasters;
  for (unsigned k = 0; k < 130; ++k)
    rasters.push_back(k % 17 == 5 ? BitRaster() : BitRaster(g, randomCells(g, 300 + static_cast<int>(k), k)));
  const size_t pixels = static_cast<size_t>(g.width) * static_cast<size_t>(g.height);
  const BitColumns columns(rasters, pixels);
  size_t set = 0;
  for (size_t idx = 0; idx < pixels; idx += 7)
    for (const auto& [first, count] : {std::pair{0, 64}, std::pair{0, 1}, std::pair{60, 11}, std::pair{64, 64},
                                       std::pair{66, 64}, std::pair{125, 5}, std::pair{119, 11}}) {
      uint64_t expected = 0;
      for (int k = 0; k < count; ++k)
        if (const BitRaster& r = rasters[static_cast<size_t>(first + k)]; !r.empty() && r.test(idx))
          expected |= uint64_t{1} << k;
      ASSERT_EQ(columns.window(idx, first, count), expected) << "pixel " << idx << " from " << first;
      set += expected != 0;
    }
  EXPECT_GT(set, 1000u) << "the windows read something";
}
