#include "camera/fragment_colours.h"

#include <cmath>
#include <stdexcept>

#include "rocklab/sim/bonds.h"

namespace rocklab::experiments {

namespace {

/// HSV (h in turns, s, v in [0, 1]) to RGB, the standard hexcone formula.
render::Rgb fromHsv(double h, double s, double v) {
  const double h6 = 6.0 * (h - std::floor(h));
  const int sector = static_cast<int>(h6) % 6;
  const double f = h6 - std::floor(h6);
  const auto p = static_cast<float>(v * (1 - s)), q = static_cast<float>(v * (1 - s * f)),
             u = static_cast<float>(v * (1 - s * (1 - f))), w = static_cast<float>(v);
  switch (sector) {
    case 0:
      return {w, u, p};
    case 1:
      return {q, w, p};
    case 2:
      return {p, w, u};
    case 3:
      return {p, q, w};
    case 4:
      return {u, p, w};
    default:
      return {w, p, q};
  }
}

}  // namespace

render::Rgb fragmentHue(std::uint32_t lowest_ball) {
  constexpr double kGoldenTurn = 0.6180339887498949;  // (sqrt 5 - 1) / 2
  // Saturated and bright, so every piece stands out from the grey specimen.
  return fromHsv(0.08 + kGoldenTurn * lowest_ball, 0.75, 0.92);
}

std::vector<render::Rgb> fragmentColours(const sim::Snapshot& s, std::span<const render::Rgb> own) {
  const std::size_t n = s.position.size();
  if (own.size() != n)
    throw std::invalid_argument("fragmentColours: " + std::to_string(own.size()) + " colours for " +
                                std::to_string(n) + " balls");
  const std::vector<std::uint32_t> label =
      sim::bondedClusters(n, s.bond_a, s.bond_b, s.bond_intact);
  // Labels run 0, 1, ... in the order of each fragment's lowest ball, so the
  // first ball met with a new label is that lowest ball.
  std::vector<std::uint32_t> lowest;
  std::vector<double> volume;  // m^3 / (4 pi / 3): r^3 summed
  for (std::size_t i = 0; i < n; ++i) {
    if (label[i] == lowest.size()) {
      lowest.push_back(static_cast<std::uint32_t>(i));
      volume.push_back(0.0);
    }
    volume[label[i]] += s.radius[i] * s.radius[i] * s.radius[i];
  }
  std::size_t largest = 0;
  for (std::size_t f = 1; f < volume.size(); ++f)
    if (volume[f] > volume[largest]) largest = f;
  std::vector<render::Rgb> colour(n);
  for (std::size_t i = 0; i < n; ++i)
    colour[i] = label[i] == largest ? own[i] : fragmentHue(lowest[label[i]]);
  return colour;
}

}  // namespace rocklab::experiments
