#include "lead_sigma.hpp"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>

namespace tomomap {
namespace {

/// A lead whose chance probability is below double's range reads as this many sigmas.
constexpr double kMostSigma = 37.0;

/// The one-sided t test of the differences' mean, as a normal deviate, with
/// the differences worth `independent` independent ones (at most their
/// number): the standard error and the t's degrees of freedom follow from that many.
double leadSigma(const std::vector<double>& differences, double independent) {
  const size_t n = differences.size();
  if (n < 2) return 0.0;
  double mean = 0;
  for (double x : differences) mean += x;
  mean /= static_cast<double>(n);
  if (mean <= 0) return 0.0;
  double ss = 0;
  for (double x : differences) ss += (x - mean) * (x - mean);
  const double se = std::sqrt(ss / static_cast<double>(n - 1) / independent);
  if (se <= 0) return kMostSigma;
  const double tail = boost::math::cdf(boost::math::complement(boost::math::students_t(independent - 1), mean / se));
  if (!(tail > 1e-300)) return kMostSigma;
  return std::min(kMostSigma, boost::math::quantile(boost::math::complement(boost::math::normal(), tail)));
}

}  // namespace

double signFlipLeadSigma(const std::vector<double>& differences) {
  double sum = 0, squares = 0;
  for (double x : differences) sum += x, squares += x * x;
  return differences.size() >= 2 && sum > 0 ? std::min(kMostSigma, sum / std::sqrt(squares)) : 0.0;
}

double sliceLeadSigma(const std::vector<double>& differences) {
  const size_t n = differences.size();
  if (n < 4) return signFlipLeadSigma(differences);
  // Each slice's difference less the lead's straight-line course with
  // height: the lead may grow towards a furnished floor, which is a
  // difference in the mean, not slices echoing each other.
  const double mid = (static_cast<double>(n) - 1) / 2;
  double mean = 0, sxx = 0, sxy = 0;
  for (double x : differences) mean += x;
  mean /= static_cast<double>(n);
  for (size_t k = 0; k < n; ++k) {
    sxx += (static_cast<double>(k) - mid) * (static_cast<double>(k) - mid);
    sxy += (static_cast<double>(k) - mid) * (differences[k] - mean);
  }
  std::vector<double> residual(n);
  for (size_t k = 0; k < n; ++k) residual[k] = differences[k] - mean - sxy / sxx * (static_cast<double>(k) - mid);
  double lagged = 0, squares = 0, scale = 0;
  for (size_t k = 0; k < n; ++k) {
    squares += residual[k] * residual[k];
    scale += differences[k] * differences[k];
    if (k + 1 < n) lagged += residual[k] * residual[k + 1];
  }
  // Residuals within rounding of the differences themselves (a straight
  // line, a constant lead) echo nothing.
  const double rho = squares > 1e-24 * scale ? std::clamp(lagged / squares, 0.0, 1.0) : 0.0;
  const double independent = std::max(2.0, static_cast<double>(n) * (1 - rho) / (1 + rho));
  return leadSigma(differences, independent);
}

double significance(double a, double b) {
  a = std::max(a, 0.0), b = std::max(b, 0.0);
  return (a - b) / std::sqrt(std::max(a + b, 1.0));
}

}  // namespace tomomap
