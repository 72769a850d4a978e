#pragma once
// One slice's occupancy at a bit a pixel, indexed as SliceStack::cells are
// (v * width + u): what the landings and the refinement on occupancy read.
// A large map's slices as byte images took most of a match's memory and,
// cleared and dilated, most of its time, though a slice's occupied cells
// are a percent of its raster or less; as bits they are an eighth, and a
// dilation stamps the occupied cells instead of sweeping the raster
// (docs/results.md, "Occupancy at a bit a pixel").
#include <cstddef>
#include <cstdint>
#include <utility>
#include <vector>

#include "slices.hpp"

namespace tomomap {

class BitRaster {
 public:
  /// A pixel's neighbours that a dilation sets: (du, dv) offsets. Stamped
  /// around each occupied cell, a stamp symmetric about its centre (as a disk
  /// or a square is) sets the pixels a dilation by it would.
  using Stamp = std::vector<std::pair<int, int>>;
  /// The pixels within `radius_cells` as OpenCV draws a disk of the whole
  /// cells in it (cv::MORPH_ELLIPSE): radius 1 is a cross of five.
  static Stamp disk(double radius_cells);

  /// An empty raster keeps no words and reads nothing set.
  BitRaster() = default;
  /// `cells` (pixel indices on `g`) set, each with `stamp` around it where
  /// that lies on the raster (a dilation whose border adds nothing). An empty
  /// `cells` gives an empty raster.
  BitRaster(const SliceGrid& g, const std::vector<uint32_t>& cells, const Stamp& stamp = {{0, 0}})
      : width_(g.width), height_(g.height) {
    if (cells.empty()) return;
    words_.assign((static_cast<size_t>(g.width) * static_cast<size_t>(g.height) + 63) / 64, 0);
    const auto w = static_cast<uint32_t>(g.width);
    for (uint32_t c : cells) {
      const int u = static_cast<int>(c % w), v = static_cast<int>(c / w);
      for (const auto& [du, dv] : stamp)
        if (u + du >= 0 && u + du < width_ && v + dv >= 0 && v + dv < height_) set(index(u + du, v + dv));
    }
  }

  bool empty() const { return words_.empty(); }
  /// Calls f(idx) for every set pixel, in order; none on an empty raster.
  template <typename F>
  void forEachSet(F&& f) const {
    for (size_t w = 0; w < words_.size(); ++w)
      for (uint64_t bits = words_[w]; bits != 0; bits &= bits - 1)
        f(w * 64 + static_cast<size_t>(__builtin_ctzll(bits)));
  }
  /// Whether pixel `idx` (v * width + u) is set; the raster must not be empty.
  bool test(size_t idx) const { return (words_[idx / 64] >> (idx % 64)) & 1U; }
  /// Every pixel set in `other` (a raster of the same size) set here too.
  void add(const BitRaster& other) {
    if (other.empty()) return;
    if (empty()) {
      *this = other;
      return;
    }
    for (size_t k = 0; k < words_.size(); ++k) words_[k] |= other.words_[k];
  }

  /// Calls f(u) for every set u in [u_lo, u_hi] of row v, in order: a word
  /// at a time, so the empty stretches that most of a search window is cost
  /// one test each (demo-room's refinement: 0.038 -> 0.032 s, against
  /// testing every cell of the window). The raster must not be empty.
  template <typename F>
  void forEachSet(int v, int u_lo, int u_hi, F&& f) const {
    const size_t row = index(0, v), lo = row + static_cast<size_t>(u_lo), hi = row + static_cast<size_t>(u_hi);
    for (size_t w = lo / 64; w <= hi / 64; ++w) {
      uint64_t bits = words_[w];
      if (w == lo / 64) bits &= ~uint64_t{0} << (lo % 64);
      if (w == hi / 64 && hi % 64 != 63) bits &= (uint64_t{1} << (hi % 64 + 1)) - 1;
      for (; bits != 0; bits &= bits - 1)
        f(static_cast<int>(w * 64 + static_cast<size_t>(__builtin_ctzll(bits)) - row));
    }
  }

 private:
  size_t index(int u, int v) const {
    return static_cast<size_t>(v) * static_cast<size_t>(width_) + static_cast<size_t>(u);
  }
  void set(size_t idx) { words_[idx / 64] |= uint64_t{1} << (idx % 64); }

  int width_ = 0, height_ = 0;
  std::vector<uint64_t> words_;
};

/// A stack of rasters of one size read down its columns: per pixel, a bit
/// per raster. Choosing a pose's height tests each cell of it on every
/// slice within reach; down a column those are one or two words, where the
/// rasters are a word each (pose_judge.hpp, mostInliersAt). It takes a
/// word per pixel per 64 rasters, whatever they hold: for the small maps a
/// dense search searches, not for every stack.
class BitColumns {
 public:
  BitColumns() = default;
  /// The columns of `rasters` (each empty or of `pixels` pixels).
  BitColumns(const std::vector<BitRaster>& rasters, size_t pixels)
      : rasters_(static_cast<int>(rasters.size())), words_((rasters.size() + 63) / 64), bits_(pixels * words_, 0) {
    for (size_t k = 0; k < rasters.size(); ++k)
      rasters[k].forEachSet([&](size_t idx) { bits_[idx * words_ + k / 64] |= uint64_t{1} << (k % 64); });
  }
  int size() const { return rasters_; }  ///< the rasters'
  /// Rasters first to first + count - 1 at pixel `idx`, raster `first` in
  /// bit 0: 0 <= first, first + count <= the rasters' number, 1 <= count <= 64.
  uint64_t window(size_t idx, int first, int count) const {
    const uint64_t* column = &bits_[idx * words_];
    const auto word = static_cast<size_t>(first) / 64, bit = static_cast<size_t>(first) % 64;
    uint64_t out = column[word] >> bit;
    if (bit != 0 && word + 1 < words_) out |= column[word + 1] << (64 - bit);
    return count == 64 ? out : out & ((uint64_t{1} << count) - 1);
  }

 private:
  int rasters_ = 0;
  size_t words_ = 0;  ///< per column
  std::vector<uint64_t> bits_;
};

}  // namespace tomomap
