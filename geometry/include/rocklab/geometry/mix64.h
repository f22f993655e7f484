#pragma once
// splitmix64's finaliser: 64 well-mixed bits from any 64-bit value. rocklab's
// generator (packing.h Rng), its counter-based hashes (a crusher ball's strength
// from the seed and its id, a frame's sensor noise seed) and the network check's
// fixed start vector all mix with it, so it is written once.
#include <cstdint>

namespace rocklab::geometry {

/// splitmix64's increment (the golden-ratio gamma).
inline constexpr std::uint64_t kSplitmixGamma = 0x9e3779b97f4a7c15ull;

constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
  return z ^ (z >> 31);
}

}  // namespace rocklab::geometry
