#pragma once
// Hexagonal close packed agglomerate of the anisotropy study (experiments.md §f.3).
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::geometry {

/// Porosity of the infinite HCP (and FCC) lattice of touching equal spheres: 1 − π/√18.
inline constexpr double kHcpPorosity = 0.25951;

/// Equal touching spheres of `radius` in hexagonal close packing, every sphere wholly
/// inside the sphere of `diameter` centred at the origin (a sphere sits at the origin).
/// Close-packed layers lie in the x–z plane and stack A-B-A-B along y (layer spacing
/// 2r √(2/3)); the whole packing is then rotated by `angle_deg` about z (x towards y),
/// which turns the stacking axis in the x–y plane. Throws std::invalid_argument for
/// radius <= 0, diameter < 2 radius, or angle_deg outside [0, 90].
std::vector<Sphere> hcpPacking(double radius, double diameter, double angle_deg);

}  // namespace rocklab::geometry
