#include "line_plot.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <set>

namespace tomomap::viz {

cv::Mat drawLinePanel(const LinePanel& p, Axes axes, cv::Size size) {
  cv::Mat img(size, CV_8UC3, colour::kWhite);
  const int left = 90, right = size.width - 30, top = 60, bottom = size.height - 60;
  const bool log = axes == Axes::LogLog;
  std::vector<double> xs, ys;
  for (const auto& s : p.series) {
    xs.insert(xs.end(), s.x.begin(), s.x.end());
    ys.insert(ys.end(), s.y.begin(), s.y.end());
  }
  // A linear axis starts at zero (ValueAxis::fit), so growth reads against the whole.
  const ValueAxis y_axis = ValueAxis::fit(ys, log, top, bottom);
  // The x axis reuses the row mapping, mirrored: rows grow downwards, columns
  // rightwards. On a log axis it spans the points with a margin (sizes rarely
  // span decades).
  ValueAxis x_axis = ValueAxis::fit(xs, log, left, right);
  std::vector<double> positive;
  for (double x : xs)
    if (x > 0) positive.push_back(x);
  if (log && !positive.empty()) {
    const auto [mn, mx] = std::minmax_element(positive.begin(), positive.end());
    x_axis.lo = *mn / 1.25;
    x_axis.hi = *mx * 1.25;
  }
  const auto column = [&](double x) { return left + right - x_axis.row(x); };
  const auto shown = [&](double v) { return log ? v > 0 : std::isfinite(v); };

  drawText(img, p.title, {size.width / 2, 24}, 0.65, colour::kBlack, Align::Centre, 2);
  for (double t : y_axis.ticks()) {
    const int y = y_axis.row(t);
    cv::line(img, {left, y}, {right, y}, colour::kLightGrey, 1);
    drawText(img, tickLabel(t), {left - 8, y + 5}, 0.45, colour::kBlack, Align::Right);
  }
  const std::vector<double> x_ticks = log ? std::vector<double>(xs.begin(), xs.end()) : x_axis.ticks();
  for (double t : std::set<double>(x_ticks.begin(), x_ticks.end())) {
    if (!shown(t)) continue;
    const int x = column(t);
    cv::line(img, {x, top}, {x, bottom}, colour::kLightGrey, 1);
    drawText(img, tickLabel(t), {x, bottom + 20}, 0.45, colour::kBlack, Align::Centre);
  }
  cv::rectangle(img, cv::Point(left, top), cv::Point(right, bottom), colour::kGrey, 1);
  drawVerticalText(img, p.y_label, {22, (top + bottom) / 2}, 0.5);
  drawText(img, p.x_label, {(left + right) / 2, bottom + 45}, 0.5, colour::kBlack, Align::Centre);

  int lx = left;
  for (size_t s = 0; s < p.series.size(); ++s) {
    const LineSeries& series = p.series[s];
    const cv::Scalar c = colour::kSeries[s % colour::kSeries.size()];
    cv::rectangle(img, cv::Rect(lx, 38, 14, 12), c, cv::FILLED);
    drawText(img, series.name, {lx + 20, 49}, 0.45);
    lx += 40 + 9 * static_cast<int>(series.name.size());
    std::vector<cv::Point> points;
    for (size_t i = 0; i < series.x.size() && i < series.y.size(); ++i)
      if (shown(series.x[i]) && shown(series.y[i])) points.emplace_back(column(series.x[i]), y_axis.row(series.y[i]));
    if (points.size() > 1) cv::polylines(img, points, false, c, 2, cv::LINE_AA);
    if (points.size() <= 30)  // a long series is its line; markers would hide it
      for (const auto& q : points) cv::circle(img, q, 4, c, cv::FILLED, cv::LINE_AA);
  }
  return img;
}

double logLogSlope(const std::vector<double>& x, const std::vector<double>& y) {
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  for (size_t i = 0; i < x.size() && i < y.size(); ++i) {
    if (!(x[i] > 0 && y[i] > 0)) continue;
    const double lx = std::log(x[i]), ly = std::log(y[i]);
    n += 1, sx += lx, sy += ly, sxx += lx * lx, sxy += lx * ly;
  }
  const double d = n * sxx - sx * sx;
  return n >= 2 && d > 0 ? (n * sxy - sx * sy) / d : NAN;
}

}  // namespace tomomap::viz
