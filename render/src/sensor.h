#pragma once
// What the camera sensor adds after the optics: Gaussian read noise.
#include <cstdint>

#include <opencv2/core.hpp>

namespace rocklab::render::detail {

/// Adds N(0, sigma²) grey levels to every channel of an 8-bit BGR image, saturating.
/// Reproducible: the noise is seeded by (seed, frameIndex), so re-rendering a frame
/// gives the same image and consecutive frames get independent noise.
void addSensorNoise(cv::Mat& image, double sigma, std::uint64_t seed, std::uint64_t frameIndex);

}  // namespace rocklab::render::detail
