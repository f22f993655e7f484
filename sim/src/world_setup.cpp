#include "world_impl.h"

#include <cmath>
#include <sstream>

#include "rigid_body.h"
#include "state_check.h"
#include "rocklab/sim/wall_motion.h"

namespace rocklab::sim {

using detail::PairProps;

// ---------------------------------------------------------------------------
// Set-up

std::string validateModel(const Model& model, const std::vector<SphereSpec>& spheres,
                          const std::vector<ClumpSpec>& clumps) {
  std::ostringstream e;
  if (model.materials.empty()) return "no materials defined";
  if (model.relaxation.steps < 0) return "relaxation.steps must be >= 0";
  for (std::size_t k = 0; k < model.materials.size(); ++k) {
    const Material& m = model.materials[k];
    const std::string where = "material '" + m.name + "'";
    if (!(m.density > 0)) return where + ": density must be > 0 kg/m^3";
    if (!(m.friction >= 0)) return where + ": friction must be >= 0";
    if (model.contact.law == ContactLaw::Linear && !(m.kn > 0 && m.ks >= 0))
      return where + ": the linear law needs kn > 0 and ks >= 0 N/m";
    if (model.contact.law == ContactLaw::HertzMindlin &&
        !(m.shear_modulus > 0 && m.poisson > -1 && m.poisson < 0.5))
      return where + ": Hertz–Mindlin needs shear_modulus > 0 Pa and -1 < poisson < 0.5";
  }
  const auto nm = static_cast<int>(model.materials.size());
  for (const Wall& w : model.walls) {
    const std::string where = "wall '" + w.name + "'";
    if (w.material < 0 || w.material >= nm) return where + ": unknown material";
    if (w.shape == WallShape::Plane) {
      if (!(w.normal.norm() > 0)) return where + ": normal must not be zero";
      if (!w.motion.angular_velocity.isZero(0) || w.motion.spin_rate != 0.0)
        return where + ": an infinite plane cannot rotate or spin; use a polygon";
    }
    if (w.motion.spin_rate != 0.0 && !(std::isfinite(w.motion.spin_rate) && w.motion.spin_axis.norm() > 0 &&
                                        w.motion.spin_axis.allFinite() && w.motion.spin_point.allFinite()))
      return where + ": a spin needs a finite rate, a non-zero spin_axis and a finite spin_point";
    if (w.shape == WallShape::Polygon)
      if (const std::string problem = polygonProblem(w.vertices); !problem.empty()) return where + ": " + problem;
    if (w.shape == WallShape::Mesh) {
      const std::string msg = w.mesh.validate();
      if (!msg.empty()) return where + ": " + msg;
      if (!(w.smooth_angle_deg >= 0 && w.smooth_angle_deg < 90))
        return where + ": smooth_angle_deg must be in [0, 90) degrees";
    }
    if (!(w.active_until > w.active_from)) return where + ": active_until must be after active_from";
  }
  for (std::size_t i = 0; i < spheres.size(); ++i) {
    const SphereSpec& s = spheres[i];
    if (!(s.radius > 0)) {
      e << "sphere " << i << ": radius must be > 0 m";
      return e.str();
    }
    if (s.material < 0 || s.material >= nm) {
      e << "sphere " << i << ": unknown material index " << s.material;
      return e.str();
    }
    if (!s.position.allFinite() || !s.velocity.allFinite() || !s.omega.allFinite()) {
      e << "sphere " << i << ": position, velocity and omega must be finite";
      return e.str();
    }
  }
  for (std::size_t c = 0; c < clumps.size(); ++c) {
    const ClumpSpec& k = clumps[c];
    e.str("");
    e << "clump " << c << ": ";
    if (k.members.empty()) return e.str() + "has no member spheres";
    if (!(k.mass > 0)) return e.str() + "mass must be > 0 kg";
    if (!(k.principal_inertia.minCoeff() > 0) || !k.principal_inertia.allFinite())
      return e.str() + "principal inertia must be > 0 kg m^2";
    if (k.material < 0 || k.material >= nm) return e.str() + "unknown material index";
    if (!k.position.allFinite() || !k.velocity.allFinite() || !k.omega.allFinite() ||
        !k.orientation.coeffs().allFinite() || std::abs(k.orientation.norm() - 1.0) > 1e-9)
      return e.str() + "position, velocity and omega must be finite and the orientation a unit quaternion";
    for (const geometry::Sphere& m : k.members)
      if (!(m.radius > 0) || !m.centre.allFinite()) return e.str() + "member radius must be > 0 m";
  }
  return {};
}

namespace {

/// "" or why bond k cannot join balls a and b of a world of n balls.
std::string bondEndsProblem(std::size_t k, std::uint32_t a, std::uint32_t b, std::size_t n) {
  std::ostringstream e;
  if (a >= n || b >= n)
    e << "bond " << k << ": ball " << std::max(a, b) << " does not exist (the world has " << n << " balls)";
  else if (a == b)
    e << "bond " << k << ": joins ball " << a << " to itself";
  return e.str();
}

/// "" or what is wrong with the bonds of a world of `p`'s balls.
std::string validateBonds(const ParallelBondModel& bm, const ParticleState& p, const BondState& bonds) {
  if (bonds.size() == 0) return {};
  std::ostringstream e;
  constexpr auto kContact = static_cast<std::uint8_t>(BondKind::Contact);
  const bool any_parallel =
      std::any_of(bonds.kind.begin(), bonds.kind.end(), [](std::uint8_t k) { return k != kContact; });
  if (any_parallel && (!(bm.radius_multiplier > 0) || !std::isfinite(bm.radius_multiplier))) {
    e << "bonds.radius_multiplier = " << bm.radius_multiplier << ": must be > 0";
    return e.str();
  }
  if (any_parallel && (!(bm.normal_stiffness > 0) || !std::isfinite(bm.normal_stiffness))) {
    e << "bonds.normal_stiffness = " << bm.normal_stiffness << " Pa/m: must be > 0";
    return e.str();
  }
  if (any_parallel && (!(bm.shear_stiffness >= 0) || !std::isfinite(bm.shear_stiffness))) {
    e << "bonds.shear_stiffness = " << bm.shear_stiffness << " Pa/m: must be >= 0";
    return e.str();
  }
  const std::size_t n = p.size();
  std::vector<std::uint64_t> contact_pairs;  // a pair has one contact bond at most
  for (std::size_t k = 0; k < bonds.size(); ++k) {
    const std::uint32_t a = bonds.a[k], b = bonds.b[k];
    if (std::string bad = bondEndsProblem(k, a, b, n); !bad.empty()) return bad;
    if (!p.clump.empty() && p.clump[a] >= 0 && p.clump[a] == p.clump[b]) {
      e << "bond " << k << ": balls " << a << " and " << b << " are members of one rigid clump";
      return e.str();
    }
    if (bonds.kind[k] > kContact) {
      e << "bond " << k << ": kind " << int(bonds.kind[k]) << " (0 parallel, 1 contact)";
      return e.str();
    }
    const bool contact = bonds.kind[k] == kContact;
    if (!(bonds.tensile_strength[k] > 0) || !(bonds.shear_strength[k] > 0)) {
      e << "bond " << k << ": strengths must be > 0 " << (contact ? "N" : "Pa") << " (tensile "
        << bonds.tensile_strength[k] << ", shear " << bonds.shear_strength[k] << ")";
      return e.str();
    }
    if (contact) {
      if (!(bonds.spring_normal[k] > 0) || !std::isfinite(bonds.spring_normal[k]) ||
          !(bonds.spring_shear[k] >= 0) || !std::isfinite(bonds.spring_shear[k]) ||
          !std::isfinite(bonds.reference_overlap[k])) {
        e << "contact bond " << k << ": springs must be finite, normal > 0 N/m (" << bonds.spring_normal[k]
          << "), shear >= 0 N/m (" << bonds.spring_shear[k] << ")";
        return e.str();
      }
      contact_pairs.push_back((std::uint64_t(std::min(a, b)) << 32) | std::max(a, b));
      continue;
    }
    if (!(bonds.radius[k] > 0) || !bonds.normal[k].allFinite() || std::abs(bonds.normal[k].norm() - 1.0) > 1e-6) {
      e << "bond " << k << ": radius must be > 0 m and the normal a unit vector";
      return e.str();
    }
  }
  std::sort(contact_pairs.begin(), contact_pairs.end());
  if (const auto twice = std::adjacent_find(contact_pairs.begin(), contact_pairs.end()); twice != contact_pairs.end()) {
    e << "balls " << (*twice >> 32) << " and " << (*twice & 0xffffffffu) << " have two contact bonds (one at most)";
    return e.str();
  }
  return {};
}

}  // namespace

World::World(Model model, const std::vector<SphereSpec>& spheres, int threads)
    : World(std::move(model), spheres, {}, {}, threads) {}

World::World(Model model, const std::vector<SphereSpec>& spheres, const std::vector<ClumpSpec>& clumps,
             int threads)
    : World(std::move(model), spheres, clumps, {}, threads) {}

World::World(Model model, const std::vector<SphereSpec>& spheres, const std::vector<ClumpSpec>& clumps,
             const std::vector<BondSpec>& bond_specs, int threads)
    : impl_(std::make_unique<Impl>()) {
  const std::string msg = validateModel(model, spheres, clumps);
  if (!msg.empty()) throw std::invalid_argument(msg);
  Impl& w = *impl_;
  w.model = std::move(model);
  ParticleState& p = w.p;
  std::size_t members = 0;
  for (const ClumpSpec& c : clumps) members += c.members.size();
  const std::size_t n = spheres.size() + members;
  // Exact capacity: appending one ball at a time would leave up to half of
  // every field's allocation unused for the whole run.
#define ROCKLAB_RESERVE(type, name, unit, meaning) p.name.reserve(n);
  ROCKLAB_BALL_FIELDS(ROCKLAB_RESERVE)
#undef ROCKLAB_RESERVE
  // Velocities at t = 0: the first kick is a half kick.
  for (std::size_t i = 0; i < spheres.size(); ++i)
    appendFreeSphere(p, spheres[i], sphereMass(w.model.materials[spheres[i].material].density, spheres[i].radius), i);
#define ROCKLAB_RESIZE(type, name, unit, meaning) p.name.resize(n);
  ROCKLAB_BALL_FIELDS(ROCKLAB_RESIZE)
#undef ROCKLAB_RESIZE
  if (!clumps.empty()) {
    ClumpState& k = p.clumps;
    p.clump.assign(n, -1);
    k.member_begin.push_back(0);
    std::size_t i = spheres.size();
    for (std::size_t c = 0; c < clumps.size(); ++c) {
      const ClumpSpec& s = clumps[c];
      k.position.push_back(s.position);
      k.velocity.push_back(s.velocity);
      k.orientation.push_back(s.orientation.normalized());
      k.angular_momentum.push_back(detail::angularMomentum(k.orientation.back(), s.principal_inertia, s.omega));
      k.mass.push_back(s.mass);
      k.inertia.push_back(s.principal_inertia);
      k.id.push_back(n + c);  // ids after the balls': one id space for every body
      for (const geometry::Sphere& m : s.members) {
        p.radius[i] = m.radius;
        p.mass[i] = s.mass;  // a member's dashpots and time-step criterion see the whole body
        p.inv_mass[i] = 1.0 / s.mass;
        p.inv_inertia[i] = 1.0 / s.principal_inertia.minCoeff();
        p.material[i] = s.material;
        p.id[i] = i;
        p.clump[i] = static_cast<std::int32_t>(c);
        k.member_ball.push_back(static_cast<std::uint32_t>(i));
        k.member_offset.push_back(m.centre);
        ++i;
      }
      k.member_begin.push_back(static_cast<std::uint32_t>(k.member_ball.size()));
      w.placeMembers(c);
    }
  }
  // The ends first: installing a bond reads its balls' radii.
  for (std::size_t k = 0; k < bond_specs.size(); ++k)
    if (std::string bad = bondEndsProblem(k, bond_specs[k].a, bond_specs[k].b, n); !bad.empty())
      throw std::invalid_argument(bad);
  w.installBonds(bond_specs);
  if (const std::string bad = validateBonds(w.model.bonds, p, w.bonds.state); !bad.empty())
    throw std::invalid_argument(bad);
  w.audit = auditTimestep(w.model, p, w.bonds.state);
  w.dt = w.audit.chosen;
  w.initialise(threads);
  w.relax.pending = w.model.relaxation.steps > 0;
}

World::World(Model model, WorldState state, int threads) : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.model = std::move(model);
  const std::string msg = validateModel(w.model, {});
  if (!msg.empty()) throw std::invalid_argument(msg);
  // Every value before any is used: an index out of range reads past a table,
  // a zero radius hangs the neighbour search (the caller names the file).
  if (const std::string bad = detail::stateProblem(w.model, state); !bad.empty()) throw std::invalid_argument(bad);
  w.p = std::move(state.particles);
  if (const std::string bad = validateBonds(w.model.bonds, w.p, state.bonds); !bad.empty())
    throw std::invalid_argument("bonds: " + bad);
  w.bonds.state = std::move(state.bonds);
  w.indexBonds();
  w.time = state.time;
  w.step = state.step;
  w.half_kick_pending = state.half_kick_pending;
  w.guard.wall_work_carried = state.moving_wall_work;
  if (w.p.size() > 0) w.audit = auditTimestep(w.model, w.p, w.bonds.state);  // nothing to audit in an empty world
  w.audit.chosen = state.dt;  // the run continues with the step it had
  w.dt = state.dt;
  w.initialise(threads);
  // Contact history: build the lists now and take the saved shear forces.
  w.prepareStage();
  w.rebuildNeighbours();
  for (std::size_t row = 0; row < state.pair_history.size(); ++row) {
    const PairHistory& h = state.pair_history[row];
    const auto b = w.nb.pairs.partner.begin() + w.nb.pairs.row_offset[h.i];
    const auto e = w.nb.pairs.partner.begin() + w.nb.pairs.row_offset[h.i + 1];
    const auto it = std::lower_bound(b, e, h.j);
    if (it == e || *it != h.j)
      throw std::invalid_argument("pairs row " + std::to_string(row) + ": balls " + std::to_string(h.i) + " and " +
                                  std::to_string(h.j) + " (allowed: a pair within contact range, as saved)");
    w.history.pair_shear[it - w.nb.pairs.partner.begin()] = h.shear;
    if (h.relax_offset > 0) {
      if (!w.relax.active()) w.relax.start(w.nb.pairs.size(), w.nb.wall_index.size());
      w.relax.pair[it - w.nb.pairs.partner.begin()] = h.relax_offset;
    }
  }
  for (std::size_t row = 0; row < state.wall_history.size(); ++row) {
    const WallHistory& h = state.wall_history[row];
    if (!w.walls[h.wall].active) continue;  // the wall was removed: its contacts went with it
    bool found = false;
    for (std::uint32_t c = w.nb.wall_offset[h.particle]; c < w.nb.wall_offset[h.particle + 1]; ++c)
      if (w.nb.wall_index[c] == h.wall && w.nb.wall_slot[c] == h.slot) {
        w.history.wall_shear[c] = h.shear;
        if (!w.history.wall_normal.empty()) w.history.wall_normal[c] = h.normal;
        if (h.relax_offset > 0) {
          if (!w.relax.active()) w.relax.start(w.nb.pairs.size(), w.nb.wall_index.size());
          w.relax.wall[c] = h.relax_offset;
        }
        found = true;
      }
    if (!found)
      throw std::invalid_argument("walls row " + std::to_string(row) + ": ball " + std::to_string(h.particle) +
                                  " and wall '" + w.model.walls[h.wall].name + "'" +
                                  (h.slot > 0 ? " (contact slot " + std::to_string(h.slot) + ")" : "") +
                                  " (allowed: a ball within contact range of the wall, as saved)");
  }
}

World::~World() = default;

void World::Impl::initialise(int requested_threads) {
  threads = requested_threads > 0 ? requested_threads : omp_get_max_threads();
  guard.check_travel = dt > audit.automatic;  // forced (timestep.allow_unsafe); dt is set by now
  has_clumps = p.clumps.size() > 0;
  has_mesh_walls = std::any_of(model.walls.begin(), model.walls.end(),
                               [](const Wall& w) { return w.shape == WallShape::Mesh; });
  buildPairProps();
  walls.resize(model.walls.size());
  for (std::size_t k = 0; k < walls.size(); ++k) walls[k].setup(model.walls[k]);
  guard.wall_moving.assign(walls.size(), 0);
  bool any_moving = false;
  for (std::size_t k = 0; k < walls.size(); ++k) {
    guard.wall_moving[k] = model.walls[k].motion.isStatic() ? 0 : 1;
    any_moving = any_moving || guard.wall_moving[k];
  }
  if (any_moving) {
    guard.wall_work.assign(p.size(), 0.0);
    guard.wall_work_gross.assign(p.size(), 0.0);
  }
  // Gravity in force at the current time.
  gravity = model.gravity;
  for (const GravityChange& g : model.gravity_changes)
    if (g.time <= time) gravity = g.vector;
  if (model.skin > 0) {
    nb.skin = model.skin;
  } else {
    double sum = 0;
    for (double r : p.radius) sum += r;
    nb.skin = p.size() ? 0.2 * sum / static_cast<double>(p.size()) : 1e-3;
  }
  const std::size_t n = p.size();
  scratch.acc_force.assign(n, Vec3::Zero());
  scratch.acc_torque.assign(n, Vec3::Zero());
  nb.need_rebuild = true;
}

void World::Impl::buildPairProps() {
  nm = model.materials.size();
  ball_ball.resize(nm * nm);
  ball_wall.resize(nm * nm);
  for (std::size_t a = 0; a < nm; ++a)
    for (std::size_t b = 0; b < nm; ++b) {
      ball_ball[a * nm + b] = detail::ballBallProps(model.materials[a], model.materials[b], model.contact.friction_rule);
      ball_wall[a * nm + b] = detail::ballWallProps(model.materials[a], model.materials[b], model.contact.friction_rule);
    }
}

/// Sets the members' positions, velocities and spins from their clump's state.
double World::Impl::placeMembers(std::size_t c) {
  const ClumpState& k = p.clumps;
  return placeMembers(c, k.orientation[c], k.position[c], k.velocity[c], k.angular_momentum[c]);
}

double World::Impl::placeMembers(std::size_t c, const Quat& q, const Vec3& centre, const Vec3& v, const Vec3& L) {
  const ClumpState& k = p.clumps;
  // One rotation matrix for the body's members and spin: cheaper than turning
  // each vector by the quaternion.
  const geometry::Mat3 R = q.toRotationMatrix();
  const Vec3 w = detail::angularVelocity(R, k.inertia[c], L);
  double max_disp2 = 0.0;
  for (std::uint32_t m = k.member_begin[c]; m < k.member_begin[c + 1]; ++m) {
    const std::uint32_t i = k.member_ball[m];
    const Vec3 arm = R * k.member_offset[m];
    const Vec3 x = centre + arm;
    // From the registers, not read back from the stores (a store-forwarding stall).
    if (!nb.ref_position.empty()) max_disp2 = std::max(max_disp2, (x - nb.ref_position[i]).squaredNorm());
    p.position[i] = x;
    p.velocity[i] = v + w.cross(arm);
    p.omega[i] = w;
  }
  return max_disp2;
}

}  // namespace rocklab::sim
