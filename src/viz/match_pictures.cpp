#include "match_pictures.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "core/rigid2d.hpp"
#include "core/text.hpp"

namespace tomomap::viz {
namespace {

/// Map-frame x, y of the cells occupied in at least `min_slices` slices: walls,
/// columns and furniture seen from above. Floors and ceilings fill one or two
/// slices each and would paint the whole footprint.
std::vector<Eigen::Vector2d> verticalStructure(const SliceStack& s, int min_slices = 3) {
  std::vector<uint32_t> cells;
  for (const auto& slice : s.cells) cells.insert(cells.end(), slice.begin(), slice.end());
  std::sort(cells.begin(), cells.end());
  std::vector<Eigen::Vector2d> xy;
  for (size_t i = 0; i < cells.size();) {
    size_t j = i;
    while (j < cells.size() && cells[j] == cells[i]) ++j;
    if (static_cast<int>(j - i) >= min_slices) xy.push_back(s.grid.cellCentre(cells[i]));
    i = j;
  }
  return xy;
}

/// A slice as dark cells on white, BGR.
cv::Mat sliceImage(const SliceStack& s, int k, int pad) {
  cv::Mat grey = 255 - s.image(k, pad), bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  return bgr;
}

const SliceFeatures* findSlice(const MapFeatures& f, int index) {
  for (const auto& s : f.slices)
    if (s.index == index) return &s;
  return nullptr;
}

}  // namespace

cv::Mat drawOverlay(const SliceStack& target, const SliceStack& source, const Pose4& T,
                    const std::vector<std::string>& caption) {
  std::vector<Eigen::Vector2d> t_xy = verticalStructure(target);
  std::vector<Eigen::Vector2d> s_xy = verticalStructure(source);
  const Rigid2D onto_target = planar(T);
  for (auto& p : s_xy) p = onto_target.apply(p);

  Eigen::Vector2d lo(INFINITY, INFINITY), hi(-INFINITY, -INFINITY);
  for (const auto* set : {&t_xy, &s_xy})
    for (const auto& p : *set) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  if (t_xy.empty() && s_xy.empty()) lo = hi = Eigen::Vector2d::Zero();
  const double extent = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1.0});
  // About 1000 pixels across; a cell is drawn as a square of at least one pixel.
  const double px = extent / 1000.0;  // metres per pixel
  const int cell_px = std::max(1, static_cast<int>(std::lround(target.grid.cell / px)));
  const int w = static_cast<int>((hi.x() - lo.x()) / px) + cell_px,
            h = static_cast<int>((hi.y() - lo.y()) / px) + cell_px;

  cv::Mat t_mask = cv::Mat::zeros(h, w, CV_8U), s_mask = cv::Mat::zeros(h, w, CV_8U);
  auto plot = [&](const std::vector<Eigen::Vector2d>& xy, cv::Mat& mask) {
    for (const auto& p : xy) {
      const int u = static_cast<int>((p.x() - lo.x()) / px), v = h - cell_px - static_cast<int>((p.y() - lo.y()) / px);
      cv::rectangle(mask, cv::Rect(u, v, cell_px, cell_px), 255, cv::FILLED);
    }
  };
  plot(t_xy, t_mask);
  plot(s_xy, s_mask);

  cv::Mat image(h, w, CV_8UC3, colour::kWhite);
  const cv::Vec3b blue(178, 114, 0), orange(0, 140, 230), both(60, 40, 40);
  for (int v = 0; v < h; ++v)
    for (int u = 0; u < w; ++u) {
      const bool a = t_mask.at<uint8_t>(v, u), b = s_mask.at<uint8_t>(v, u);
      if (a || b) image.at<cv::Vec3b>(v, u) = a && b ? both : a ? blue : orange;
    }
  return framePlanView(image, lo, px, caption,
                       {{"target", colour::kSeries[0]},
                        {"source (aligned)", colour::kSeries[1]},
                        {"both", cv::Scalar(both[0], both[1], both[2])}});
}

cv::Mat drawSlicePairs(const MapFeatures& target, const MapFeatures& source, const MatchResult& r, int count,
                       double inlier_cells) {
  std::vector<cv::Mat> rows;
  const SliceGrid& tg = target.occupancy.grid;
  const SliceGrid& sg = source.occupancy.grid;
  const Rigid2D T = planar(r.T_target_source);
  const int pad = 8;
  int drawn_pairs = 0;
  for (const auto& pair : r.features.supporters) {
    if (drawn_pairs >= count) break;
    const SliceFeatures* ft = findSlice(target, pair.target_slice);
    const SliceFeatures* fs = findSlice(source, pair.source_slice);
    if (!ft || !fs || pair.target_slice >= target.occupancy.size() || pair.source_slice >= source.occupancy.size())
      continue;
    const Correspondences c = matchSlices(*ft, *fs);
    const auto inliers = collectInliers(c, T, inlier_cells * target.grid);

    cv::Mat left = sliceImage(target.occupancy, pair.target_slice, pad);
    cv::Mat right = sliceImage(source.occupancy, pair.source_slice, pad);
    // Same height on both sides, white below (drawMatches would fill black).
    const int rows_needed = std::max(left.rows, right.rows);
    cv::copyMakeBorder(left, left, 0, rows_needed - left.rows, 0, 0, cv::BORDER_CONSTANT, colour::kWhite);
    cv::copyMakeBorder(right, right, 0, rows_needed - right.rows, 0, 0, cv::BORDER_CONSTANT, colour::kWhite);
    // Enlarge small slices (whole pixels, no smoothing), shrink huge ones.
    const double scale = std::clamp(700.0 / std::max({left.cols, left.rows, right.cols, right.rows}), 0.25, 8.0);
    const double f = scale >= 1 ? std::floor(scale) : scale;
    cv::resize(left, left, {}, f, f, f >= 1 ? cv::INTER_NEAREST : cv::INTER_AREA);
    cv::resize(right, right, {}, f, f, f >= 1 ? cv::INTER_NEAREST : cv::INTER_AREA);
    auto toPixel = [&](const SliceGrid& g, const Eigen::Vector2d& p) {
      const Eigen::Vector2d px = g.toPixel(p.x(), p.y());  // scaled about pixel corners: + 0.5
      return cv::Point2f(static_cast<float>((px.x() + pad + 0.5) * f), static_cast<float>((px.y() + pad + 0.5) * f));
    };
    std::vector<cv::KeyPoint> kt, ks;
    std::vector<cv::DMatch> matches;
    std::vector<char> mask(c.size(), 0);
    for (uint32_t i : inliers) mask[i] = 1;
    for (size_t i = 0; i < c.size(); ++i) {
      kt.emplace_back(toPixel(tg, c.target[i]), 1.f);
      ks.emplace_back(toPixel(sg, c.source[i]), 1.f);
      matches.emplace_back(static_cast<int>(i), static_cast<int>(i), 0.f);
    }
    cv::Mat drawn;
    cv::drawMatches(left, kt, right, ks, matches, drawn, cv::Scalar(40, 170, 40), colour::kGrey, mask);
    cv::line(drawn, {left.cols, 0}, {left.cols, drawn.rows}, colour::kGrey, 2);

    cv::Mat header(56, std::max(drawn.cols, 1000), CV_8UC3, colour::kWhite);
    drawText(header,
             "target slice " + std::to_string(pair.target_slice) + " (z " +
                 fixed(tg.sliceHeight(pair.target_slice), 2) + " m)  |  source slice " +
                 std::to_string(pair.source_slice) + " (z " + fixed(sg.sliceHeight(pair.source_slice), 2) + " m)",
             {8, 22}, 0.55, colour::kBlack, Align::Left, 2);
    drawText(header,
             std::to_string(c.size()) + " mutual descriptor matches, " + std::to_string(inliers.size()) +
                 " agree with the result (green, within " + fixed(inlier_cells, 0) + " cells); grey: the rest",
             {8, 46}, 0.48);
    rows.push_back(header);
    rows.push_back(drawn);
    rows.push_back(cv::Mat(16, drawn.cols, CV_8UC3, colour::kWhite));
    ++drawn_pairs;
  }
  if (rows.empty()) {
    // A dense answer stands on the occupancy alone: no descriptor matches lie behind it.
    const bool dense = r.reliable && isDenseSearch(r.answered_by);
    cv::Mat none(80, 1000, CV_8UC3, colour::kWhite);
    drawText(none,
             dense ? "found by the dense search of the occupancy, not by descriptor matches: see the overlay"
                   : "no supporting slice pair to show",
             {10, 45}, 0.6, dense ? colour::kBlack : colour::kRed);
    return none;
  }
  cv::Mat out = stack(rows);
  cv::Mat head(40, std::max(out.cols, 1000), CV_8UC3, colour::kWhite);
  drawText(head,
           "the features' height offset " + std::to_string(r.features.height_offset) + " slices, " +
               std::to_string(r.features.support) + " agreeing slice pairs",
           {8, 28}, 0.65, colour::kBlack, Align::Left, 2);
  return stack({head, out});
}

}  // namespace tomomap::viz
