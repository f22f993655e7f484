#include <opencv2/imgproc.hpp>

#include "detect_internal.h"

namespace rocklab::track::detail {

cv::Mat redMask(const cv::Mat& bgr, const DetectorSettings& s) {
  cv::Mat hsv, low, high;
  cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV);
  // Red wraps around hue 0: one band just above 0, one just below 180.
  cv::inRange(hsv, cv::Scalar(0, s.saturation_min, s.value_min), cv::Scalar(s.hue_low_max, 255, 255), low);
  cv::inRange(hsv, cv::Scalar(s.hue_high_min, s.saturation_min, s.value_min), cv::Scalar(179, 255, 255), high);
  cv::Mat mask = low | high;
  // Open: erosion then dilation drops specks and one-pixel threads, keeps discs.
  if (s.open_kernel_px > 1) {
    const cv::Mat kernel = cv::getStructuringElement(cv::MORPH_RECT, cv::Size(s.open_kernel_px, s.open_kernel_px));
    cv::morphologyEx(mask, mask, cv::MORPH_OPEN, kernel);
  }
  return mask;
}

}  // namespace rocklab::track::detail
