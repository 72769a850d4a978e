#include "spectrum_correlation.hpp"

#include <algorithm>

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

}  // namespace

void correlateStacks(const std::vector<cv::Mat>& a, const std::vector<cv::Mat>& b, std::vector<cv::Mat>& out,
                     std::vector<char>& any) {
  const int na = static_cast<int>(a.size()), nb = static_cast<int>(b.size());
  const size_t offsets = static_cast<size_t>(std::max(0, na + nb - 1));
  out.resize(offsets);
  any.assign(offsets, 0);
  cv::Size size;
  for (const cv::Mat& m : a)
    if (!m.empty()) size = m.size();
  // The pairs (z + dz, z) of non-empty spectra, offset by offset.
  std::vector<std::vector<std::pair<int, int>>> pairs(offsets);
  for (int dz = -(nb - 1); dz <= na - 1; ++dz) {
    const size_t at = static_cast<size_t>(dz + nb - 1);
    for (int z = std::max(0, -dz); z < nb && z + dz < na; ++z)
      if (!a[static_cast<size_t>(z + dz)].empty() && !b[static_cast<size_t>(z)].empty())
        pairs[at].emplace_back(z + dz, z);
    if (pairs[at].empty()) continue;
    any[at] = 1;
    out[at].create(size, CV_32F);
    out[at].setTo(0);
  }
  const int cols = size.width;
  const int last_pair = cols % 2 == 0 ? cols - 2 : cols - 1;  // the last column of (re, im) pairs
  for (int r = 0; r < size.height; ++r)
    for (size_t at = 0; at < offsets; ++at) {
      if (!any[at]) continue;
      float* c = out[at].ptr<float>(r);
      for (const auto& [ia, ib] : pairs[at]) {
        const float* x = a[static_cast<size_t>(ia)].ptr<float>(r);
        const float* y = b[static_cast<size_t>(ib)].ptr<float>(r);
        for (int j = 1; j < last_pair; j += 2) addConjugateProduct(x[j], x[j + 1], y[j], y[j + 1], c[j], c[j + 1]);
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
