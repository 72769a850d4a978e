#pragma once
// Stacked cross-correlation in the frequency domain: the dense search's inner
// loop (dense_search.cpp), every height offset's sum of slice products at once,
// on FFTW's real transforms.
#include <complex>
#include <cstddef>
#include <memory>
#include <new>
#include <vector>

namespace tomomap {

/// Memory of FFTW's alignment (fftwf_malloc): its transforms, planned once
/// per size, run on any array so aligned.
void* fftwAllocate(size_t bytes);
void fftwFree(void* p) noexcept;

template <typename T>
struct FftwAllocator {
  using value_type = T;
  FftwAllocator() = default;
  template <typename U>
  FftwAllocator(const FftwAllocator<U>&) {}
  T* allocate(size_t n) { return static_cast<T*>(fftwAllocate(n * sizeof(T))); }
  void deallocate(T* p, size_t) noexcept { fftwFree(p); }
  template <typename U>
  bool operator==(const FftwAllocator<U>&) const {
    return true;
  }
};

/// A real image, row-major.
using RealImage = std::vector<float, FftwAllocator<float>>;
/// A real image's half spectrum, FFTW's layout: rows x (cols / 2 + 1)
/// complex, row-major (the other half is its conjugate). Empty: an empty
/// image's.
using Spectrum = std::vector<std::complex<float>, FftwAllocator<std::complex<float>>>;

/// Real 2D transforms of one size, single precision (FFTW). Planned once per
/// size in a process and kept (FFTW's planner is not thread-safe; running a
/// plan is, on arrays of its own). On the wide search's rasters, against
/// OpenCV's dft: 28-45 us forward and 30-45 us back at 144 x 144, where OpenCV
/// took 80-170 and 110-280 us at its own optimal 144 x 135 (docs/results.md,
/// "Transforms by FFTW").
class RealFft {
 public:
  RealFft(int rows, int cols);
  int rows() const { return rows_; }
  int cols() const { return cols_; }
  size_t imageSize() const { return static_cast<size_t>(rows_) * static_cast<size_t>(cols_); }
  size_t spectrumSize() const { return static_cast<size_t>(rows_) * static_cast<size_t>(cols_ / 2 + 1); }
  /// The spectrum of `image` (imageSize() values) into `out`.
  void forward(const RealImage& image, Spectrum& out) const;
  /// The image whose spectrum `spectrum` is, times rows * cols (FFTW's
  /// inverse leaves the scale), into `out`; `spectrum` is used up (FFTW's
  /// inverse of more than one dimension works in its input).
  void inverse(Spectrum& spectrum, RealImage& out) const;
  /// The smallest size of at least `n` of the form 2^a times 1, 3, 5 or 9
  /// (a >= 1): FFTW, planned without measuring, is fastest on those, 2 ns
  /// a pixel at 144 and 160, 4.5 at 162 = 2 3^4 (and 6 at OpenCV's 135).
  static int fastSize(int n);

 private:
  struct Plans;
  int rows_, cols_;
  std::shared_ptr<const Plans> plans_;
};

/// For every offset dz from -(b.size() - 1) to a.size() - 1, the sum over z
/// of a[z + dz] times the conjugate of b[z], element by element: half spectra
/// (RealFft) of one size, whose rows hold `row` complex values. Into
/// out[dz + b.size() - 1]; `any` says which offsets had at least one pair of
/// non-empty spectra, of those `wanted` (all where it is empty). `out` keeps
/// its buffers from call to call.
///
/// It walks the spectra a row at a time, for every pair and offset, so that
/// the rows it reads and the sums it adds to stay in the cache: summed a
/// whole product at a time, on the largest rooms the sums and products were
/// a quarter of a match.
void correlateStacks(const std::vector<Spectrum>& a, const std::vector<Spectrum>& b, size_t row,
                     std::vector<Spectrum>& out, std::vector<char>& any, const std::vector<char>& wanted = {});

/// Which offsets (indexed as correlateStacks indexes them) may peak at a
/// score in [from, below), for binary images holding a_cells[z] and
/// b_cells[z] set cells: a cell coincides with one other at most, so an
/// offset peaks at most at the sum, over its slice pairs, of the fewer cells.
/// What correlateStacks' `wanted` takes.
std::vector<char> offsetsPeakingWithin(const std::vector<int>& a_cells, const std::vector<int>& b_cells, double from,
                                       double below);

}  // namespace tomomap
