#pragma once
// Colours of a crush movie by fragment: the balls joined by intact bonds
// (sim::bondedClusters over a snapshot's bond_a, bond_b, bond_intact) share a
// colour. The largest fragment (by volume) keeps the balls' own colours, so the
// intact specimen at the start looks as it does coloured by material; every
// other fragment gets a bright hue fixed by its lowest ball index, so a piece
// keeps its colour from the frame it breaks off on (it takes a new lowest
// index only if it breaks again, and then its lower part keeps the colour).
#include <cstdint>
#include <span>
#include <vector>

#include "rocklab/render/frame.h"
#include "rocklab/sim/snapshot.h"

namespace rocklab::experiments {

/// The hue of the fragment whose lowest ball index is `lowest_ball`: golden-ratio
/// steps round the colour wheel (hue = frac(0.618034 k)), so neighbouring indices,
/// which in a packing are neighbouring balls, get far-apart hues.
render::Rgb fragmentHue(std::uint32_t lowest_ball);

/// One colour per ball of `s`: `own` (one per ball, e.g. by material) in the
/// largest fragment (ties: the one with the lowest ball), fragmentHue elsewhere.
/// Without bonds every ball is a fragment of its own.
std::vector<render::Rgb> fragmentColours(const sim::Snapshot& s, std::span<const render::Rgb> own);

}  // namespace rocklab::experiments
