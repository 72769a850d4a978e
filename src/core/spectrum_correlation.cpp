#include "spectrum_correlation.hpp"

#include <algorithm>
#include <utility>

namespace tomomap {
namespace {

/// (re, im) += (ar, ai) times the conjugate of (br, bi), in float: the
/// correlation only ranks coarse poses, which are refined on the grid after.
inline void addConjugateProduct(float ar, float ai, float br, float bi, float& re, float& im) {
  re += ar * br + ai * bi;
  im += ai * br - ar * bi;
}

/// In CCS, the first column (and the last, where the width is even) holds
/// the transform of a real column: its first element real, then (re, im)
/// pairs down the rows, then one more real where the height is even. Every
/// other column pair (2j-1, 2j) is (re, im) on each row.
void addColumn(const cv::Mat& a, const cv::Mat& b, cv::Mat& c, int col) {
  const int rows = a.rows;
  c.at<float>(0, col) += a.at<float>(0, col) * b.at<float>(0, col);
  int r = 1;
  for (; r + 1 < rows; r += 2)
    addConjugateProduct(a.at<float>(r, col), a.at<float>(r + 1, col), b.at<float>(r, col), b.at<float>(r + 1, col),
                        c.at<float>(r, col), c.at<float>(r + 1, col));
  if (r < rows) c.at<float>(r, col) += a.at<float>(r, col) * b.at<float>(r, col);
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

void correlateStacks(const std::vector<cv::Mat>& a, const std::vector<cv::Mat>& b, std::vector<cv::Mat>& out,
                     std::vector<char>& any, const std::vector<char>& wanted) {
  const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
  const size_t offsets = static_cast<size_t>(std::max(0, na + nb - 1));
  out.resize(offsets);
  any.assign(offsets, 0);
  cv::Size size;
  for (const cv::Mat& m : a)
    if (!m.empty()) size = m.size();
  if (size.empty()) return;  // every a is an empty image's: no offset has a pair
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
    out[at].create(size, CV_32F);
    out[at].setTo(0);
  }
  const int cols = size.width;
  // The (re, im) pairs of columns 1, 2 to the last pair's, a row at a time,
  // laid out as a plane of re and one of im, so that the sums vectorise.
  const size_t n = static_cast<size_t>(cols % 2 == 0 ? cols - 2 : cols - 1) / 2;
  std::vector<float> a_re(a.size() * n), a_im(a_re.size()), b_re(b.size() * n), b_im(b_re.size());
  std::vector<float> c_re(offsets * n), c_im(c_re.size());
  const auto split = [n](const cv::Mat& m, int r, float* re, float* im) {
    const float* row = m.ptr<float>(r);
    for (size_t i = 0; i < n; ++i) re[i] = row[2 * i + 1], im[i] = row[2 * i + 2];
  };
  for (int r = 0; r < size.height; ++r) {
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
        for (size_t i = 0; i < n; ++i) addConjugateProduct(xr[i], xi[i], yr[i], yi[i], re[i], im[i]);
      }
      float* row = out[at].ptr<float>(r);
      for (size_t i = 0; i < n; ++i) row[2 * i + 1] = re[i], row[2 * i + 2] = im[i];
    }
  }
  for (size_t at = 0; at < offsets; ++at) {
    if (!any[at]) continue;
    for (const auto& [ia, ib] : pairs[at]) {
      addColumn(a[static_cast<size_t>(ia)], b[static_cast<size_t>(ib)], out[at], 0);
      if (cols % 2 == 0 && cols > 1)
        addColumn(a[static_cast<size_t>(ia)], b[static_cast<size_t>(ib)], out[at], cols - 1);
    }
  }
}

}  // namespace tomomap
