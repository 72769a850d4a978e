#pragma once
// How clearly one candidate leads another over a series of differences (one
// per slice or source slice), as the normal deviate of a one-sided test's
// tail: the decision over the candidates' one yardstick (candidate_decision.hpp).
#include <vector>

namespace tomomap {

/// How far the mean of `differences` (one per slice, in slice order, lowest
/// first) lies above zero, by a one-sided Student t test over them, as the
/// normal deviate of the same tail probability: a lead over 5 slices counts
/// for less than the same t over 50. Neighbouring slices are not
/// independent (they see the same walls): with
/// their straight-line course with height taken out, the differences' lag-1
/// autocorrelation rho (0 where negative) counts n slices as n (1 - rho) /
/// (1 + rho) independent ones, at least 2 (the effective sample size of a
/// first-order autoregressive series). Below 4 slices, signFlipLeadSigma:
/// the spread of two or three differences may be near nothing, and a t then
/// reads their lead as certain.
double sliceLeadSigma(const std::vector<double>& differences);

/// How far the sum of `differences` (one per slice or source slice) lies
/// above zero against flipping their signs at random (no lead: each
/// difference as likely either sign), by that test's normal approximation:
/// their sum over the root of their sum of squares, at most the root of
/// their number. Unlike a t, it makes no more of a lead that is the same on
/// every slice than its slices' number allows: 2 slices a vote ahead each
/// read 1.4, not beyond any bar. 0 for fewer than two differences or a sum
/// at or below zero.
double signFlipLeadSigma(const std::vector<double>& differences);

/// Count `a` over count `b` in standard deviations of a difference of two
/// counts (each count's variance its own size, as for Poisson counts; a
/// negative score counts as none): how far two poses' scores lie apart
/// beyond chance.
double significance(double a, double b);

}  // namespace tomomap
