// Scene reader: [bonds], the parallel-bond model (dem-models.md §8.2) and the
// strengths of the agglomerates' bonds (experiments.md §f.6): one constant
// value, or Weibull draws (modulus m, 37 % value) per bond or one per
// agglomerate (the study's way of giving agglomerates a spread of strengths).
#include "analysis/weibull.h"
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

void readBonds(TableReader& root, std::uint64_t seed, Scene& scene) {
  auto t = root.table("bonds");
  if (!t) {
    if (!scene.agglomerates.empty())
      root.fail("bonds", "the scene has agglomerates (" + scene.agglomerates.front().source +
                             "): give their bonds in a [bonds] table (normal_stiffness, "
                             "shear_stiffness in Pa/m, tensile_strength, shear_strength in Pa)");
    return;
  }
  sim::ParallelBondModel& bm = scene.model.bonds;
  bm.radius_multiplier = t->number("radius_multiplier", 1.0, Range::positive());  // Eq 2-35
  // Per unit area: the study's "N/m" are N/m^3 = Pa/m (dem-models §8.2 [I]).
  bm.normal_stiffness = t->requiredNumber("normal_stiffness", Range::positive());
  bm.shear_stiffness = t->requiredNumber("shear_stiffness", Range::nonNegative());
  bm.failure_rule = t->string("failure_rule", "stress", {"stress", "combined"}) == "stress"
                        ? sim::BondFailureRule::Stress
                        : sim::BondFailureRule::Combined;
  const double tensile = t->requiredNumber("tensile_strength", Range::positive());
  const double shear = t->number("shear_strength", tensile, Range::positive());
  const std::string distribution =
      t->string("strength_distribution", "constant",
                {"constant", "weibull_per_bond", "weibull_per_agglomerate"});
  double modulus = 0;
  if (distribution != "constant") {
    modulus = t->requiredNumber("weibull_modulus", Range::positive());
  } else if (t->has("weibull_modulus")) {
    t->fail("weibull_modulus",
            "only with strength_distribution = weibull_per_bond or weibull_per_agglomerate");
  }
  // Draws of their own stream: changing the bonds' spread does not move particles.
  geometry::Rng rng(seed * 7919ull + 17ull);
  for (AgglomerateReport& a : scene.agglomerates) {
    // A factor on both strengths (the study drew one value for normal and shear, §f.6 [I]).
    const double agglomerate_factor =
        distribution == "weibull_per_agglomerate" ? drawWeibull(modulus, 1.0, rng) : 1.0;
    a.bond_strength = distribution == "weibull_per_bond" ? 0.0 : tensile * agglomerate_factor;
    for (std::size_t k = a.first_bond; k < a.first_bond + a.bonds; ++k) {
      const double factor =
          distribution == "weibull_per_bond" ? drawWeibull(modulus, 1.0, rng) : agglomerate_factor;
      scene.bonds[k].tensile_strength = tensile * factor;
      scene.bonds[k].shear_strength = shear * factor;
    }
  }
  t->finish();
}

}  // namespace rocklab::experiments::detail
