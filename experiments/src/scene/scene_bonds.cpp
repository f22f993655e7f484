// Scene reader: [bonds], the kind of the agglomerates' bonds (type: parallel,
// dem-models.md §8.2; contact, §8.1; or both), the parallel-bond model and the
// strengths (parallel: Pa; contact: N) (experiments.md §f.6): one constant
// value, or Weibull draws (modulus m, 37 % value) per bond or one per
// agglomerate (the study's way of giving agglomerates a spread of strengths).
#include <span>

#include "analysis/weibull.h"
#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

namespace {

const char* const kParallelKeys[] = {"radius_multiplier", "normal_stiffness", "shear_stiffness",
                                     "failure_rule", "tensile_strength", "shear_strength"};
const char* const kContactKeys[] = {"contact_normal_strength", "contact_shear_strength"};

/// A key of the other kind of bond is an error naming the types it belongs to.
void refuseKeys(TableReader& t, std::span<const char* const> keys, const std::string& type,
                const char* belongs) {
  for (const char* key : keys)
    if (t.has(key)) t.fail(key, "not with type = \"" + type + "\" (only with type = " + belongs + ")");
}

}  // namespace

void readBonds(TableReader& root, std::uint64_t seed, Scene& scene) {
  auto t = root.table("bonds");
  if (!t) {
    if (!scene.agglomerates.empty())
      root.fail("bonds", "the scene has agglomerates (" + scene.agglomerates.front().source +
                             "): give their bonds in a [bonds] table (normal_stiffness, "
                             "shear_stiffness in Pa/m, tensile_strength, shear_strength in Pa)");
    return;
  }
  // Which bonds join each bonded pair: a parallel bond (§8.2), a contact bond
  // (§8.1), or both (the contact bonds then follow all the parallel ones).
  const std::string type = t->string("type", "parallel", {"parallel", "contact", "parallel+contact"});
  const bool parallel = type != "contact", contact = type != "parallel";
  double tensile = 0, shear = 0;
  if (parallel) {
    sim::ParallelBondModel& bm = scene.model.bonds;
    bm.radius_multiplier = t->number("radius_multiplier", 1.0, Range::positive());  // Eq 2-35
    // Per unit area: the study's "N/m" are N/m^3 = Pa/m (dem-models §8.2 [I]).
    bm.normal_stiffness = t->requiredNumber("normal_stiffness", Range::positive());
    bm.shear_stiffness = t->requiredNumber("shear_stiffness", Range::nonNegative());
    bm.failure_rule = t->choice("failure_rule", sim::BondFailureRule::Stress,
                                {{sim::BondFailureRule::Stress, "stress"}, {sim::BondFailureRule::Combined, "combined"}});
    tensile = t->requiredNumber("tensile_strength", Range::positive());  // Pa
    shear = t->number("shear_strength", tensile, Range::positive());     // Pa
  } else {
    refuseKeys(*t, kParallelKeys, type, "\"parallel\" or \"parallel+contact\"");
  }
  double contact_normal = 0, contact_shear = 0;  // N, F_c^n and F_c^s (§8.1: forces)
  if (contact) {
    contact_normal = t->requiredNumber("contact_normal_strength", Range::positive());
    contact_shear = t->number("contact_shear_strength", contact_normal, Range::positive());
  } else {
    refuseKeys(*t, kContactKeys, type, "\"contact\" or \"parallel+contact\"");
  }
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
  std::vector<sim::BondSpec> contact_bonds;
  for (AgglomerateReport& a : scene.agglomerates) {
    // A factor on every strength of a pair (the study drew one value for normal and shear, §f.6 [I]).
    const double agglomerate_factor =
        distribution == "weibull_per_agglomerate" ? drawWeibull(modulus, 1.0, rng) : 1.0;
    a.bond_strength = distribution == "weibull_per_bond" ? 0.0
                                                         : (parallel ? tensile : contact_normal) * agglomerate_factor;
    for (std::size_t k = a.first_bond; k < a.first_bond + a.bonds; ++k) {
      const double factor =
          distribution == "weibull_per_bond" ? drawWeibull(modulus, 1.0, rng) : agglomerate_factor;
      sim::BondSpec& bond = scene.bonds[k];
      if (parallel) {
        bond.tensile_strength = tensile * factor;
        bond.shear_strength = shear * factor;
      }
      if (contact) {
        sim::BondSpec glue{bond.a, bond.b, contact_normal * factor, contact_shear * factor,
                           sim::BondKind::Contact};
        if (parallel)
          contact_bonds.push_back(glue);
        else
          bond = glue;
      }
    }
  }
  scene.bonds.insert(scene.bonds.end(), contact_bonds.begin(), contact_bonds.end());
  t->finish();
}

}  // namespace rocklab::experiments::detail
