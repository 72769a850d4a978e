#pragma once
// Stacked cross-correlation in the frequency domain: the dense search's inner
// loop (dense_search.cpp), every height offset's sum of slice products at once.
#include <opencv2/core.hpp>
#include <vector>

namespace tomomap {

/// For every offset dz from -(b.size() - 1) to a.size() - 1, the sum over z
/// of a[z + dz] times the conjugate of b[z]: what cv::mulSpectrums (conjB)
/// summed over z gives (up to float rounding), on OpenCV's packed (CCS) real
/// spectra of one size. Into out[dz + b.size() - 1]; `any` says which offsets had at
/// least one pair of non-empty spectra (an empty cv::Mat is an empty image's
/// spectrum), of those `wanted` (all where it is empty). `out` keeps its
/// buffers from call to call.
///
/// Why not mulSpectrums: its product is a whole matrix written out and read
/// back to be added, once per pair of slices. This walks the spectra a row at
/// a time, for every pair and offset, so that the rows it reads and the sums
/// it adds to stay in the cache: on the largest rooms the sums and products
/// were a quarter of a match.
void correlateStacks(const std::vector<cv::Mat>& a, const std::vector<cv::Mat>& b, std::vector<cv::Mat>& out,
                     std::vector<char>& any, const std::vector<char>& wanted = {});

/// Which offsets (indexed as correlateStacks indexes them) may peak at a
/// score in [from, below), for binary images holding a_cells[z] and
/// b_cells[z] set cells: a cell coincides with one other at most, so an
/// offset peaks at most at the sum, over its slice pairs, of the fewer cells.
/// What correlateStacks' `wanted` takes.
std::vector<char> offsetsPeakingWithin(const std::vector<int>& a_cells, const std::vector<int>& b_cells, double from,
                                       double below);

}  // namespace tomomap
