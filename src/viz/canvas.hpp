#pragma once
// Small drawing vocabulary shared by every picture tomomap writes: text, dashed
// lines, axes with ticks. OpenCV does the rasterising.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

namespace tomomap::viz {

namespace colour {
const cv::Scalar kBlack{0, 0, 0}, kGrey{150, 150, 150}, kLightGrey{225, 225, 225}, kWhite{255, 255, 255};
const cv::Scalar kRed{40, 40, 200};
/// Series colours (BGR), distinguishable in colour-blind palettes (Okabe-Ito): blue, orange, green, purple,
/// vermillion, near-black.
const std::vector<cv::Scalar> kSeries{{178, 114, 0},   {0, 140, 230}, {115, 158, 0},
                                      {167, 121, 204}, {0, 94, 213},  {40, 40, 40}};
}  // namespace colour

enum class Align { Left, Centre, Right };

/// Writes `text` with its baseline at `at` (anchored as `align` says).
void drawText(cv::Mat& img, const std::string& text, cv::Point at, double scale = 0.5,
              const cv::Scalar& colour = colour::kBlack, Align align = Align::Left, int thickness = 1);

/// Same, rotated 90 degrees counter-clockwise (for a y-axis label), centred on `centre`.
void drawVerticalText(cv::Mat& img, const std::string& text, cv::Point centre, double scale = 0.5);

void drawDashedLine(cv::Mat& img, cv::Point a, cv::Point b, const cv::Scalar& colour, int thickness = 1, int dash = 8);

/// A value axis mapped to pixel rows [top, bottom], linear or logarithmic.
struct ValueAxis {
  double lo = 0, hi = 1;
  bool log = false;
  int top = 0, bottom = 100;

  /// Range covering `values` (and `also`, e.g. a threshold), with some headroom.
  static ValueAxis fit(std::vector<double> values, bool log, int top, int bottom, double also = NAN);
  int row(double v) const;
  /// Tick values: 1-2-5 steps, or the decades on a log axis.
  std::vector<double> ticks() const;
};

/// Short tick label: 0.01, 0.5, 12, 1e+03.
std::string tickLabel(double v);

/// Stacks images vertically (or horizontally), padding the narrower ones with white.
cv::Mat stack(const std::vector<cv::Mat>& images, bool vertical = true);

/// A map seen from above (`plot`: `px` metres a pixel, its bottom-left pixel
/// at `lo`, x right and y up) framed with metre ticks on both axes, the
/// caption's lines above (the first in bold) and a legend of colours under them.
cv::Mat framePlanView(const cv::Mat& plot, const Eigen::Vector2d& lo, double px,
                      const std::vector<std::string>& caption,
                      const std::vector<std::pair<std::string, cv::Scalar>>& legend);

/// Writes a PNG; throws InputError naming the path if it cannot.
void writePng(const std::string& path, const cv::Mat& img);

}  // namespace tomomap::viz
