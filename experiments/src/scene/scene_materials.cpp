// Scene reader: [materials.NAME] and [contact] (the law and the stiffness
// scale, which acts on the materials).
#include <map>

#include "scene/scene_internal.h"

namespace rocklab::experiments::detail {

namespace {

/// One material; what its contact law needs (kn > 0 for the linear law, a shear
/// modulus for Hertz-Mindlin) is checked here, where the message can name the
/// key and its line (the World would say only "material 'rock'").
sim::Material readMaterial(TableReader t, const std::string& name, sim::ContactLaw law) {
  sim::Material m;
  m.name = name;
  m.density = t.number("density", m.density, Range::positive());
  m.kn = t.number("kn", m.kn, Range::nonNegative());
  m.ks = t.number("ks", m.kn, Range::nonNegative());  // defaults to kn
  m.friction = t.number("friction", m.friction, Range::nonNegative());
  m.shear_modulus = t.number("shear_modulus", m.shear_modulus, Range::nonNegative());
  m.poisson = t.number("poisson", m.poisson, {-1.0, 0.5, true, true});
  if (law == sim::ContactLaw::Linear && !(m.kn > 0))
    t.fail("kn", "the linear contact law needs kn > 0 N/m (contact.law = \"linear\" is the default)");
  if (law == sim::ContactLaw::HertzMindlin && !(m.shear_modulus > 0))
    t.fail("shear_modulus", "contact.law = \"hertz_mindlin\" needs shear_modulus > 0 Pa");
  t.finish();
  return m;
}

}  // namespace

/// An RGB colour [r, g, b] with channels in [0, 1].
render::Rgb readColour(TableReader& t, const std::string& key, render::Rgb fallback) {
  if (!t.has(key)) return fallback;
  const Vec3 c = t.vec3(key, Vec3::Zero());
  if (c.minCoeff() < 0 || c.maxCoeff() > 1)
    t.fail(key, "expected [r, g, b] with each channel in [0, 1]");
  return {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())};
}

int materialIndex(TableReader& t, const std::map<std::string, int>& materials) {
  std::vector<std::string> names;
  for (const auto& [n, i] : materials) names.push_back(n);
  return materials.at(t.requiredString("material", names));
}

/// [materials.NAME]: one sim::Material (and its colour) per table, by name.
std::map<std::string, int> readMaterials(TableReader& root, Scene& scene) {
  sim::Model& model = scene.model;
  std::map<std::string, int> materials;
  auto t = root.table("materials");
  if (!t) root.fail("materials", "missing; define at least one [materials.NAME] table");
  // The law the materials must suit; readContact checks the key itself.
  const toml::node* law_node = root.raw().at_path("contact.law").node();
  const auto law = law_node && law_node->value<std::string>() == "hertz_mindlin" ? sim::ContactLaw::HertzMindlin
                                                                                 : sim::ContactLaw::Linear;
  for (const std::string& name : t->keys()) {
    auto mt = t->table(name);
    materials[name] = static_cast<int>(model.materials.size());
    scene.material_colours.push_back(readColour(*mt, "colour", render::kGreyPebble));
    model.materials.push_back(readMaterial(*mt, name, law));
  }
  if (model.materials.empty()) root.fail("materials", "define at least one [materials.NAME] table");
  t->finish();
  return materials;
}

/// [contact]: the law, its damping and the stiffness scale; Hertz needs shear
/// moduli.
void readContact(TableReader& root, sim::Model& model) {
  if (auto t = root.table("contact")) {
    const std::string law = t->string("law", "linear", {"linear", "hertz_mindlin"});
    model.contact.law = law == "linear" ? sim::ContactLaw::Linear : sim::ContactLaw::HertzMindlin;
    model.contact.damping_normal = t->number("damping_normal", 0.0, {0.0, 1.0, false, true});
    model.contact.damping_shear =
        t->number("damping_shear", model.contact.damping_normal, {0.0, 1.0, false, true});
    const std::string mass = t->string("damping_mass", "average", {"average", "reduced"});
    model.contact.damping_mass =
        mass == "average" ? sim::DampingMass::Average : sim::DampingMass::Reduced;
    model.contact.local_damping = t->number("local_damping", 0.0, {0.0, 1.0, false, true});
    const std::string rule = t->string("friction_rule", "min", {"min", "max", "mean"});
    model.contact.friction_rule = rule == "min"   ? sim::FrictionRule::Min
                                  : rule == "max" ? sim::FrictionRule::Max
                                                  : sim::FrictionRule::Mean;
    // Stiffness scaling, the usual way DEM users buy speed (dt_crit ~
    // 1/sqrt(k)): one factor on every material's kn, ks and G, so a study
    // varies one key.
    const double scale = t->number("stiffness_scale", 1.0, Range::positive());
    for (auto& m : model.materials) {
      m.kn *= scale;
      m.ks *= scale;
      m.shear_modulus *= scale;
    }
    t->finish();
  }
}

}  // namespace rocklab::experiments::detail
