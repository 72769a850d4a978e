#include "box_plot.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/stats.hpp"

namespace tomomap::viz {

cv::Mat drawBoxPanel(const BoxPanel& p, cv::Size size) {
  cv::Mat img(size, CV_8UC3, colour::kWhite);
  const int left = 90, right = size.width - 20, top = 60, bottom = size.height - 60;
  std::vector<double> all;
  for (const auto& [key, v] : p.values) all.insert(all.end(), v.begin(), v.end());
  const ValueAxis axis = ValueAxis::fit(all, p.log, top, bottom, p.threshold);

  drawText(img, p.title, {size.width / 2, 24}, 0.65, colour::kBlack, Align::Centre, 2);
  for (double t : axis.ticks()) {
    const int y = axis.row(t);
    cv::line(img, {left, y}, {right, y}, colour::kLightGrey, 1);
    drawText(img, tickLabel(t), {left - 8, y + 5}, 0.45, colour::kBlack, Align::Right);
  }
  cv::rectangle(img, cv::Point(left, top), cv::Point(right, bottom), colour::kGrey, 1);
  drawVerticalText(img, p.axis_label, {22, (top + bottom) / 2}, 0.5);

  // Legend along the top edge.
  int lx = left;
  for (size_t s = 0; s < p.series.size(); ++s) {
    const cv::Scalar c = colour::kSeries[s % colour::kSeries.size()];
    cv::rectangle(img, cv::Rect(lx, 38, 14, 12), c, cv::FILLED);
    drawText(img, p.series[s], {lx + 20, 49}, 0.45);
    lx += 40 + 9 * static_cast<int>(p.series[s].size());
  }

  const int groups = std::max<int>(1, static_cast<int>(p.groups.size()));
  const int series = std::max<int>(1, static_cast<int>(p.series.size()));
  const double group_w = static_cast<double>(right - left) / groups;
  const double box_w = std::min(60.0, 0.8 * group_w / series);
  for (int gi = 0; gi < static_cast<int>(p.groups.size()); ++gi) {
    const double centre = left + (gi + 0.5) * group_w;
    drawText(img, p.groups[static_cast<size_t>(gi)], {static_cast<int>(centre), bottom + 22}, 0.5, colour::kBlack,
             Align::Centre);
    for (int si = 0; si < series; ++si) {
      const auto it = p.values.find({p.groups[static_cast<size_t>(gi)], p.series[static_cast<size_t>(si)]});
      if (it == p.values.end()) continue;
      std::vector<double> v;
      for (double x : it->second)
        if (std::isfinite(x)) v.push_back(p.log ? std::max(x, axis.lo) : x);
      const int x0 = static_cast<int>(centre + (si - series / 2.0) * box_w + 0.1 * box_w);
      const int x1 = static_cast<int>(x0 + 0.8 * box_w);
      const int xm = (x0 + x1) / 2;
      const cv::Scalar c = colour::kSeries[static_cast<size_t>(si) % colour::kSeries.size()];
      if (v.empty()) {
        drawText(img, "n/a", {xm, bottom - 8}, 0.4, colour::kGrey, Align::Centre);
        continue;
      }
      std::sort(v.begin(), v.end());
      const int q10 = axis.row(quantile(v, 0.1)), q25 = axis.row(quantile(v, 0.25));
      const int q50 = axis.row(quantile(v, 0.5)), q75 = axis.row(quantile(v, 0.75));
      const int q90 = axis.row(quantile(v, 0.9));
      cv::line(img, {xm, q10}, {xm, q25}, c, 1, cv::LINE_AA);
      cv::line(img, {xm, q75}, {xm, q90}, c, 1, cv::LINE_AA);
      cv::line(img, {xm - 6, q10}, {xm + 6, q10}, c, 1, cv::LINE_AA);
      cv::line(img, {xm - 6, q90}, {xm + 6, q90}, c, 1, cv::LINE_AA);
      cv::Mat roi = img(cv::Rect(cv::Point(x0, q75), cv::Point(x1 + 1, q25 + 1)));
      cv::Mat tint(roi.size(), roi.type(), c);
      cv::addWeighted(roi, 0.65, tint, 0.35, 0, roi);
      cv::rectangle(img, cv::Point(x0, q75), cv::Point(x1, q25), c, 2);
      cv::line(img, {x0, q50}, {x1, q50}, colour::kBlack, 2);
      for (size_t k = 0; k < v.size(); ++k) {  // every sample, spread a little sideways
        const int jitter = static_cast<int>((static_cast<double>(k % 5) - 2) * 0.08 * (x1 - x0));
        cv::circle(img, {xm + jitter, axis.row(v[k])}, 3, colour::kBlack, cv::FILLED, cv::LINE_AA);
      }
      // Samples shown / runs: a run without a value (no match) shows as the gap.
      drawText(img, "n=" + std::to_string(v.size()) + "/" + std::to_string(it->second.size()), {xm, bottom + 40}, 0.38,
               colour::kGrey, Align::Centre);
    }
  }
  if (std::isfinite(p.threshold)) {
    const int y = axis.row(p.threshold);
    drawDashedLine(img, {left, y}, {right, y}, colour::kRed, 2);
    drawText(img, p.threshold_label, {right - 4, y - 6}, 0.45, colour::kRed, Align::Right);
  }
  return img;
}

}  // namespace tomomap::viz
