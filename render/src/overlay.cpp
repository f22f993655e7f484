#include "rocklab/render/overlay.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <string>

#include <opencv2/imgproc.hpp>

namespace rocklab::render {

namespace {

// Light text over a dark outline, readable on any background.
void outlinedText(cv::Mat& image, const std::string& text, cv::Point origin, const OverlayStyle& s) {
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, s.fontScale, cv::Scalar(0, 0, 0), s.thickness + 2,
              cv::LINE_AA);
  cv::putText(image, text, origin, cv::FONT_HERSHEY_SIMPLEX, s.fontScale, s.colour, s.thickness, cv::LINE_AA);
}

// The 1-2-5 number nearest below x.
double roundDown125(double x) {
  const double decade = std::pow(10.0, std::floor(std::log10(x)));
  for (double m : {5.0, 2.0, 1.0})
    if (m * decade <= x) return m * decade;
  return decade;
}

}  // namespace

void drawTimestamp(cv::Mat& image, double time_s, int decimals, const OverlayStyle& style) {
  char text[64];
  std::snprintf(text, sizeof text, "t = %.*f s", decimals, time_s);
  int baseline = 0;
  const cv::Size size = cv::getTextSize(text, cv::FONT_HERSHEY_SIMPLEX, style.fontScale, style.thickness, &baseline);
  outlinedText(image, text, cv::Point(style.margin, style.margin + size.height), style);
}

double drawScaleBar(cv::Mat& image, const geometry::Camera& camera, double depth_m, double length_mm,
                    const OverlayStyle& style) {
  if (!(depth_m > 0.0)) throw std::invalid_argument("drawScaleBar: depth must be > 0 m");
  const double pixelsPerMm = camera.fx * 1e-3 / depth_m;
  if (length_mm <= 0.0) length_mm = roundDown125(0.2 * image.cols / pixelsPerMm);
  const int length = static_cast<int>(std::lround(length_mm * pixelsPerMm));
  const int x0 = style.margin, y = image.rows - style.margin - 4;
  // A filled bar whose first and last pixel columns are `length` apart, over a dark border.
  const int half = style.thickness;
  cv::rectangle(image, cv::Point(x0 - 2, y - half - 2), cv::Point(x0 + length + 2, y + half + 2), cv::Scalar(0, 0, 0),
                cv::FILLED);
  cv::rectangle(image, cv::Point(x0, y - half), cv::Point(x0 + length, y + half), style.colour, cv::FILLED);
  char text[32];
  std::snprintf(text, sizeof text, "%g mm", length_mm);
  outlinedText(image, text, cv::Point(x0, y - 8), style);
  return length_mm;
}

}  // namespace rocklab::render
