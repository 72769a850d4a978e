#include "spectrum_correlation.hpp"

#include <fftw3.h>

#include <algorithm>
#include <limits>
#include <map>
#include <mutex>
#include <stdexcept>
#include <utility>

namespace tomomap {
namespace {

/// (re, im) += (xr, xi) times the conjugate of (yr, yi), element by element
/// over n, in float: the correlation only ranks coarse poses, which are
/// refined on the grid after. The sums are most of a wide search's time once
/// FFTW transforms it: a copy for each vector width (chosen when the program
/// loads), each element summed alike in every copy (no fused multiply-add),
/// so that every machine ranks the poses the same.
__attribute__((target_clones("avx512f", "avx2", "default"), optimize("fp-contract=off"))) void addConjugateProducts(
    size_t n, const float* __restrict xr, const float* __restrict xi, const float* __restrict yr,
    const float* __restrict yi, float* __restrict re, float* __restrict im) {
  for (size_t i = 0; i < n; ++i) {
    re[i] += xr[i] * yr[i] + xi[i] * yi[i];
    im[i] += xi[i] * yr[i] - xr[i] * yi[i];
  }
}

/// Calls f(za, zb) for the slice pairs of offset dz: a[z + dz] with b[z],
/// for each z that both stacks (of na and nb slices) hold.
template <class F>
void forEachPair(int na, int nb, int dz, F&& f) {
  for (int z = std::max(0, -dz); z < nb && z + dz < na; ++z) f(z + dz, z);
}

}  // namespace

std::vector<char> offsetsPeakingWithin(const std::vector<int>& a_cells, const std::vector<int>& b_cells, double from,
                                       double below) {
  const int na = static_cast<int>(a_cells.size()), nb = static_cast<int>(b_cells.size());
  std::vector<char> out(static_cast<size_t>(std::max(0, na + nb - 1)));
  for (int dz = -(nb - 1); dz <= na - 1; ++dz) {
    int most = 0;
    forEachPair(na, nb, dz, [&](int za, int zb) {
      most += std::min(a_cells[static_cast<size_t>(za)], b_cells[static_cast<size_t>(zb)]);
    });
    const double bound = most + 0.5;  // half a cell for the transforms' rounding
    out[static_cast<size_t>(dz + nb - 1)] = bound >= from && bound < below;
  }
  return out;
}

void* fftwAllocate(size_t bytes) {
  void* p = fftwf_malloc(std::max<size_t>(bytes, 1));
  if (!p) throw std::bad_alloc();
  return p;
}

void fftwFree(void* p) noexcept { fftwf_free(p); }

/// A size's two plans, destroyed with the process's table of them (at exit):
/// FFTW's memory for a plan is its own, and a plan left undestroyed leaks it.
struct RealFft::Plans {
  fftwf_plan forward = nullptr, inverse = nullptr;
  Plans() = default;
  Plans(const Plans&) = delete;
  Plans& operator=(const Plans&) = delete;
  ~Plans() {
    if (forward) fftwf_destroy_plan(forward);
    if (inverse) fftwf_destroy_plan(inverse);
  }
};

RealFft::RealFft(int rows, int cols) : rows_(rows), cols_(cols) {
  if (rows < 1 || cols < 1) throw std::invalid_argument("RealFft: an empty size");
  // One plan per size for the process: planning (with FFTW_ESTIMATE, which
  // looks at no data) takes milliseconds, a search runs thousands of transforms.
  static std::mutex planner;
  static std::map<std::pair<int, int>, std::shared_ptr<const Plans>> made;
  const std::lock_guard<std::mutex> lock(planner);
  std::shared_ptr<const Plans>& plans = made[{rows, cols}];
  if (!plans) {
    RealImage image(imageSize());
    Spectrum spectrum(spectrumSize());
    auto* complex = reinterpret_cast<fftwf_complex*>(spectrum.data());
    auto p = std::make_shared<Plans>();
    p->forward = fftwf_plan_dft_r2c_2d(rows, cols, image.data(), complex, FFTW_ESTIMATE);
    p->inverse = fftwf_plan_dft_c2r_2d(rows, cols, complex, image.data(), FFTW_ESTIMATE);
    if (!p->forward || !p->inverse) throw std::runtime_error("FFTW could not plan a transform");
    plans = std::move(p);
  }
  plans_ = plans;
}

void RealFft::forward(const RealImage& image, Spectrum& out) const {
  if (image.size() != imageSize()) throw std::invalid_argument("RealFft::forward: an image of another size");
  out.resize(spectrumSize());
  // FFTW's r2c leaves its input as it was (it is const here for that).
  fftwf_execute_dft_r2c(plans_->forward, const_cast<float*>(image.data()),
                        reinterpret_cast<fftwf_complex*>(out.data()));
}

void RealFft::inverse(Spectrum& spectrum, RealImage& out) const {
  if (spectrum.size() != spectrumSize()) throw std::invalid_argument("RealFft::inverse: a spectrum of another size");
  out.resize(imageSize());
  fftwf_execute_dft_c2r(plans_->inverse, reinterpret_cast<fftwf_complex*>(spectrum.data()), out.data());
}

int RealFft::fastSize(int n) {
  long best = std::numeric_limits<long>::max();
  for (long odd : {1, 3, 5, 9}) {
    long size = 2 * odd;
    while (size < n) size *= 2;
    best = std::min(best, size);
  }
  return static_cast<int>(best);
}

void correlateStacks(const std::vector<Spectrum>& a, const std::vector<Spectrum>& b, size_t row,
                     std::vector<Spectrum>& out, std::vector<char>& any, const std::vector<char>& wanted) {
  const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
  const size_t offsets = static_cast<size_t>(std::max(0, na + nb - 1));
  out.resize(offsets);
  any.assign(offsets, 0);
  size_t size = 0;
  for (const Spectrum& m : a)
    if (!m.empty()) size = m.size();
  if (size == 0 || row == 0) return;  // every a is an empty image's: no offset has a pair
  // The pairs (z + dz, z) of non-empty spectra, offset by offset.
  std::vector<std::vector<std::pair<int, int>>> pairs(offsets);
  for (int dz = -(nb - 1); dz <= na - 1; ++dz) {
    const size_t at = static_cast<size_t>(dz + nb - 1);
    if (!wanted.empty() && !wanted[at]) continue;
    forEachPair(na, nb, dz, [&](int za, int zb) {
      if (!a[static_cast<size_t>(za)].empty() && !b[static_cast<size_t>(zb)].empty()) pairs[at].emplace_back(za, zb);
    });
    if (pairs[at].empty()) continue;
    any[at] = 1;
    out[at].resize(size);
  }
  // A row at a time, laid out as a plane of re and one of im, so that the sums vectorise.
  const size_t n = row;
  std::vector<float> a_re(a.size() * n), a_im(a_re.size()), b_re(b.size() * n), b_im(b_re.size());
  std::vector<float> c_re(offsets * n), c_im(c_re.size());
  const auto split = [n](const Spectrum& m, size_t r, float* re, float* im) {
    const std::complex<float>* values = m.data() + r * n;
    for (size_t i = 0; i < n; ++i) re[i] = values[i].real(), im[i] = values[i].imag();
  };
  for (size_t r = 0; r < size / n; ++r) {
    for (size_t k = 0; k < a.size(); ++k)
      if (!a[k].empty()) split(a[k], r, a_re.data() + k * n, a_im.data() + k * n);
    for (size_t k = 0; k < b.size(); ++k)
      if (!b[k].empty()) split(b[k], r, b_re.data() + k * n, b_im.data() + k * n);
    for (size_t at = 0; at < offsets; ++at) {
      if (!any[at]) continue;
      float* __restrict re = c_re.data() + at * n;
      float* __restrict im = c_im.data() + at * n;
      std::fill(re, re + n, 0.f);
      std::fill(im, im + n, 0.f);
      for (const auto& [ia, ib] : pairs[at]) {
        const float* __restrict xr = a_re.data() + static_cast<size_t>(ia) * n;
        const float* __restrict xi = a_im.data() + static_cast<size_t>(ia) * n;
        const float* __restrict yr = b_re.data() + static_cast<size_t>(ib) * n;
        const float* __restrict yi = b_im.data() + static_cast<size_t>(ib) * n;
        addConjugateProducts(n, xr, xi, yr, yi, re, im);
      }
      std::complex<float>* sums = out[at].data() + r * n;
      for (size_t i = 0; i < n; ++i) sums[i] = {re[i], im[i]};
    }
  }
}

}  // namespace tomomap
