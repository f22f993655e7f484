#include "sensor.h"

#include "rocklab/geometry/mix64.h"

namespace rocklab::render::detail {

namespace {

// splitmix64 finaliser: a well-mixed seed from (options seed, frame index).
std::uint64_t mix(std::uint64_t a, std::uint64_t b) {
  return geometry::mix64(a ^ (b + geometry::kSplitmixGamma + (a << 6) + (a >> 2)));
}

}  // namespace

void addSensorNoise(cv::Mat& image, double sigma, std::uint64_t seed, std::uint64_t frameIndex) {
  cv::Mat noisy, noise(image.size(), CV_MAKETYPE(CV_32F, image.channels()));
  cv::RNG rng(mix(seed, frameIndex));
  rng.fill(noise, cv::RNG::NORMAL, 0.0, sigma);
  image.convertTo(noisy, CV_32F);
  noisy += noise;
  noisy.convertTo(image, CV_8U);
}

}  // namespace rocklab::render::detail
