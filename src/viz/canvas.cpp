#include "canvas.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <opencv2/imgproc.hpp>
#include <sstream>

#include "core/types.hpp"

namespace tomomap::viz {

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;

void drawText(cv::Mat& img, const std::string& text, cv::Point at, double scale, const cv::Scalar& c, Align align,
              int thickness) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, thickness, &baseline);
  if (align == Align::Centre) at.x -= size.width / 2;
  if (align == Align::Right) at.x -= size.width;
  cv::putText(img, text, at, kFont, scale, c, thickness, cv::LINE_AA);
}

void drawVerticalText(cv::Mat& img, const std::string& text, cv::Point centre, double scale) {
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, kFont, scale, 1, &baseline);
  cv::Mat strip(size.height + baseline + 4, size.width + 4, img.type(), colour::kWhite);
  cv::putText(strip, text, {2, size.height + 2}, kFont, scale, colour::kBlack, 1, cv::LINE_AA);
  cv::Mat turned;
  cv::rotate(strip, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
  cv::Rect where(centre.x - turned.cols / 2, centre.y - turned.rows / 2, turned.cols, turned.rows);
  where &= cv::Rect(0, 0, img.cols, img.rows);
  turned(cv::Rect(0, 0, where.width, where.height)).copyTo(img(where));
}

void drawDashedLine(cv::Mat& img, cv::Point a, cv::Point b, const cv::Scalar& c, int thickness, int dash) {
  const double length = std::hypot(b.x - a.x, b.y - a.y);
  for (double s = 0; s < length; s += 2 * dash) {
    const double e = std::min(length, s + dash);
    const cv::Point p(a.x + static_cast<int>((b.x - a.x) * s / length),
                      a.y + static_cast<int>((b.y - a.y) * s / length));
    const cv::Point q(a.x + static_cast<int>((b.x - a.x) * e / length),
                      a.y + static_cast<int>((b.y - a.y) * e / length));
    cv::line(img, p, q, c, thickness, cv::LINE_AA);
  }
}

ValueAxis ValueAxis::fit(std::vector<double> values, bool log, int top, int bottom, double also) {
  if (std::isfinite(also)) values.push_back(also);
  values.erase(
      std::remove_if(values.begin(), values.end(), [log](double v) { return !std::isfinite(v) || (log && v <= 0); }),
      values.end());
  ValueAxis a;
  a.log = log;
  a.top = top;
  a.bottom = bottom;
  if (values.empty()) {
    a.lo = log ? 0.1 : 0;
    a.hi = log ? 10 : 1;
    return a;
  }
  const auto [mn, mx] = std::minmax_element(values.begin(), values.end());
  if (log) {
    a.lo = std::pow(10.0, std::floor(std::log10(*mn)));
    a.hi = std::pow(10.0, std::ceil(std::log10(*mx)));
    if (a.hi <= a.lo) a.hi = a.lo * 10;
  } else {
    a.lo = std::min(0.0, *mn);
    a.hi = *mx > a.lo ? *mx * 1.1 : a.lo + 1;
  }
  return a;
}

int ValueAxis::row(double v) const {
  double f;
  if (log)
    f = (std::log10(std::max(v, lo)) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
  else
    f = (v - lo) / (hi - lo);
  f = std::clamp(f, 0.0, 1.0);
  return bottom - static_cast<int>(std::lround(f * (bottom - top)));
}

std::vector<double> ValueAxis::ticks() const {
  std::vector<double> t;
  if (log) {
    for (double v = lo; v <= hi * 1.0001; v *= 10) t.push_back(v);
    return t;
  }
  const double raw = (hi - lo) / 6;
  const double decade = std::pow(10.0, std::floor(std::log10(raw)));
  double step = decade;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * decade >= raw) {
      step = m * decade;
      break;
    }
  for (double v = std::ceil(lo / step) * step; v <= hi + 1e-9; v += step) t.push_back(v);
  return t;
}

std::string tickLabel(double v) {
  std::ostringstream o;
  if (std::abs(v) < 1e-9) v = 0;  // no "-0"
  if (v != 0 && (std::abs(v) >= 1e4 || std::abs(v) < 1e-3))
    o << std::scientific << std::setprecision(0) << v;
  else
    o << v;
  return o.str();
}

cv::Mat stack(const std::vector<cv::Mat>& images, bool vertical) {
  int w = 0, h = 0;
  for (const auto& m : images) {
    w = vertical ? std::max(w, m.cols) : w + m.cols;
    h = vertical ? h + m.rows : std::max(h, m.rows);
  }
  cv::Mat out(std::max(h, 1), std::max(w, 1), CV_8UC3, colour::kWhite);
  int at = 0;
  for (const auto& m : images) {
    m.copyTo(out(vertical ? cv::Rect(0, at, m.cols, m.rows) : cv::Rect(at, 0, m.cols, m.rows)));
    at += vertical ? m.rows : m.cols;
  }
  return out;
}

cv::Mat framePlanView(const cv::Mat& plot, const Eigen::Vector2d& lo, double px,
                      const std::vector<std::string>& caption,
                      const std::vector<std::pair<std::string, cv::Scalar>>& legend) {
  const int w = plot.cols, h = plot.rows;
  const int margin_l = 80, margin_t = 64 + 24 * static_cast<int>(caption.size()), margin_b = 60;
  const int margin_r = std::max(30, 1100 - margin_l - w);  // room for the caption
  cv::Mat img(h + margin_t + margin_b, w + margin_l + margin_r, CV_8UC3, colour::kWhite);
  plot.copyTo(img(cv::Rect(margin_l, margin_t, w, h)));
  cv::rectangle(img, cv::Rect(margin_l - 1, margin_t - 1, w + 2, h + 2), colour::kGrey, 1);

  for (size_t i = 0; i < caption.size(); ++i)
    drawText(img, caption[i], {margin_l, 26 + 24 * static_cast<int>(i)}, 0.55, colour::kBlack, Align::Left,
             i == 0 ? 2 : 1);
  // Metre ticks on both axes.
  const ValueAxis xa{lo.x(), lo.x() + w * px, false, 0, 0}, ya{lo.y(), lo.y() + h * px, false, 0, 0};
  for (double x : xa.ticks()) {
    const int u = margin_l + static_cast<int>((x - lo.x()) / px);
    cv::line(img, {u, margin_t + h}, {u, margin_t + h + 6}, colour::kBlack);
    drawText(img, tickLabel(std::round(x * 100) / 100), {u, margin_t + h + 22}, 0.42, colour::kBlack, Align::Centre);
  }
  for (double y : ya.ticks()) {
    const int v = margin_t + h - 1 - static_cast<int>((y - lo.y()) / px);
    cv::line(img, {margin_l - 6, v}, {margin_l, v}, colour::kBlack);
    drawText(img, tickLabel(std::round(y * 100) / 100), {margin_l - 9, v + 5}, 0.42, colour::kBlack, Align::Right);
  }
  drawText(img, "x [m]", {margin_l + w / 2, margin_t + h + 44}, 0.5, colour::kBlack, Align::Centre);
  drawVerticalText(img, "y [m]", {18, margin_t + h / 2}, 0.5);
  // Legend, under the caption.
  int lx = margin_l;
  const int ly = margin_t - 18;
  for (const auto& [name, col] : legend) {
    cv::rectangle(img, cv::Rect(lx, ly - 11, 14, 12), col, cv::FILLED);
    drawText(img, name, {lx + 20, ly}, 0.45);
    lx += 40 + 9 * static_cast<int>(name.size());
  }
  return img;
}

void writePng(const std::string& path, const cv::Mat& img) {
  // libpng's simplified API, not OpenCV's imgcodecs: that one links GDAL and
  // ~140 libraries, which doubled the start-up time and memory of `tomomap`.
  CV_Assert(img.type() == CV_8UC3);
  const cv::Mat bgr = img.isContinuous() ? img : img.clone();
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = static_cast<png_uint_32>(bgr.cols);
  image.height = static_cast<png_uint_32>(bgr.rows);
  image.format = PNG_FORMAT_BGR;
  const bool ok = png_image_write_to_file(&image, path.c_str(), 0, bgr.data, 0, nullptr) != 0;
  png_image_free(&image);
  if (!ok) throw InputError(path + ": cannot write the picture (does the folder exist and is it writable?)");
}

}  // namespace tomomap::viz
