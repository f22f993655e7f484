// Measurements on demand from the contacts of the last step: the average
// stress of each ball (World::particleStress, dem-models.md §11) with its
// principal values (particle_stress.h), and the load on each wall
// (World::wallForces), and which balls touch (World::touchingContacts).
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <numbers>

#include "rocklab/sim/particle_stress.h"
#include "world_impl.h"

namespace rocklab::sim {

using geometry::Mat3;

PrincipalStresses principalStresses(const Mat3& stress) {
  const Mat3 symmetric = 0.5 * (stress + stress.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> solver(symmetric);
  PrincipalStresses s;  // the solver sorts ascending
  s.minor = solver.eigenvalues()[0];
  s.intermediate = solver.eigenvalues()[1];
  s.major = solver.eigenvalues()[2];
  s.minor_direction = solver.eigenvectors().col(0);
  return s;
}

double octahedralShearStress(const PrincipalStresses& s) {
  const double a = s.major - s.intermediate, b = s.intermediate - s.minor, c = s.minor - s.major;
  return std::sqrt(a * a + b * b + c * c) / 3.0;  // Eq 3-15 / 6-10 [R]
}

double octahedralShearStress(const Mat3& stress) {
  const Mat3 symmetric = 0.5 * (stress + stress.transpose());
  const double trace = symmetric.trace();
  // (s1-s2)^2 + (s2-s3)^2 + (s3-s1)^2 = 3 (s1^2 + s2^2 + s3^2) - (s1 + s2 + s3)^2
  const double sum_of_squares = std::max(0.0, 3.0 * symmetric.squaredNorm() - trace * trace);
  return std::sqrt(sum_of_squares) / 3.0;  // Eq 3-15 / 6-10 [R]
}

namespace {

/// -sym(x (x) F): a force F on the ball at x from its centre, compression positive.
inline Mat3 stressMoment(const Vec3& x, const Vec3& f) {
  const Mat3 m = x * f.transpose();
  return -0.5 * (m + m.transpose());
}

}  // namespace

/// Calls pair(i, j, point, force on i, overlap) for every touching ball pair and
/// wall(i, wall, point, force on i, overlap) for every touching ball-wall contact, with
/// the elastic contact force (normal spring at the overlap the law sees, and the
/// shear spring of the last step; no dashpots) of the state at the current time:
/// the balls where the last step moved them, the walls where their motion puts
/// them now (the stage-1 poses are a step old: a moving platen would read the
/// overlap of a step ago). The visitors also get the shear spring (force, N).
/// `by_geometry`: every listed pair and wall contact that overlaps counts, not
/// only those the last force pass flagged (a World from a saved state before its
/// first step has no flags yet).
template <class Law, class PairVisit, class WallVisit>
void World::Impl::forEachElasticContact(PairVisit&& pair, WallVisit&& wall, bool by_geometry) const {
  // A World built from spheres has no contact lists before its first step (it
  // builds them there): no contacts yet.
  if (nb.pairs.row_offset.size() != p.size() + 1) return;
  std::vector<detail::WallRuntime> walls_now = walls;
  for (std::size_t k = 0; k < walls_now.size(); ++k) walls_now[k].update(model.walls[k], time);
  for (std::size_t i = 0; i < p.size(); ++i) {
    for (std::uint32_t k = nb.pairs.row_offset[i]; k < nb.pairs.row_offset[i + 1]; ++k) {
      if (!by_geometry && !history.pair_touch[k]) continue;
      const std::uint32_t j = nb.pairs.partner[k];
      ContactPoint touch;
      if (!ballBallTouch(p.position[i], p.position[j], p.radius[i], p.radius[j], touch)) continue;
      const double overlap = pairOverlap(touch, k);
      if (overlap <= 0) continue;
      double secant, tangent;
      Law::normal(pairProps(i, j), overlap, effectiveRadius(p.radius[i], p.radius[j]), secant,
                  tangent);
      pair(i, j, touch.point, Vec3(history.pair_shear[k] - secant * overlap * touch.normal), overlap,
           history.pair_shear[k]);
    }
    forEachWallTouch(walls_now, i, [&](std::uint32_t c, std::uint32_t wk, const ContactPoint* touch) {
      if ((!by_geometry && !history.wall_touch[c]) || !touch) return;
      const double overlap = wallOverlap(*touch, c);
      if (overlap <= 0) return;
      double secant, tangent;
      Law::normal(wallProps(i, wk), overlap, p.radius[i], secant, tangent);
      wall(i, wk, touch->point, Vec3(history.wall_shear[c] - secant * overlap * touch->normal), overlap,
           history.wall_shear[c]);
    });
  }
}

template <class Law>
std::vector<Vec3> World::Impl::wallLoads() const {
  std::vector<Vec3> load(model.walls.size(), Vec3::Zero());
  forEachElasticContact<Law>([](std::size_t, std::uint32_t, const Vec3&, const Vec3&, double, const Vec3&) {},
                             [&](std::size_t, std::uint32_t wk, const Vec3&, const Vec3& on_ball, double, const Vec3&) {
                               load[wk] -= on_ball;  // the wall feels minus the force on the ball
                             });
  return load;
}

std::vector<Vec3> World::wallForces() const {
  return impl_->model.contact.law == ContactLaw::Linear
             ? impl_->wallLoads<detail::LinearLaw>()
             : impl_->wallLoads<detail::HertzMindlinLaw>();
}

template <class Law>
TouchingContacts World::Impl::touching() const {
  TouchingContacts t;
  // The energies as the energy log has them (stages/energy.cpp): one formula.
  forEachElasticContact<Law>(
      [&](std::size_t i, std::uint32_t j, const Vec3&, const Vec3&, double overlap, const Vec3& shear) {
        t.pairs.emplace_back(static_cast<std::uint32_t>(std::min<std::size_t>(i, j)),
                             static_cast<std::uint32_t>(std::max<std::size_t>(i, j)));
        t.pair_overlap.push_back(overlap);
        t.pair_energy.push_back(
            detail::elasticEnergy<Law>(pairProps(i, j), overlap, effectiveRadius(p.radius[i], p.radius[j]), shear));
      },
      [&](std::size_t i, std::uint32_t wk, const Vec3&, const Vec3&, double overlap, const Vec3& shear) {
        t.walls.emplace_back(static_cast<std::uint32_t>(i), wk);
        t.wall_overlap.push_back(overlap);
        t.wall_energy.push_back(detail::elasticEnergy<Law>(wallProps(i, wk), overlap, p.radius[i], shear));
      },
      !forces_evaluated);
  return t;
}

TouchingContacts World::touchingContacts() const {
  return impl_->model.contact.law == ContactLaw::Linear ? impl_->touching<detail::LinearLaw>()
                                                        : impl_->touching<detail::HertzMindlinLaw>();
}

template <class Law>
void World::Impl::contactStress(std::vector<Mat3>& sum) const {
  forEachElasticContact<Law>(
      [&](std::size_t i, std::uint32_t j, const Vec3& point, const Vec3& on_i, double, const Vec3&) {
        sum[i] += stressMoment(point - p.position[i], on_i);
        sum[j] += stressMoment(point - p.position[j], -on_i);
      },
      [&](std::size_t i, std::uint32_t, const Vec3& point, const Vec3& on_i, double, const Vec3&) {
        sum[i] += stressMoment(point - p.position[i], on_i);
      });
}

std::vector<Mat3> World::particleStress() const {
  const Impl& w = *impl_;
  const ParticleState& p = w.p;
  std::vector<Mat3> sum(p.size(), Mat3::Zero());
  if (w.model.contact.law == ContactLaw::Linear)
    w.contactStress<detail::LinearLaw>(sum);
  else
    w.contactStress<detail::HertzMindlinLaw>(sum);
  const BondState& b = w.bonds.state;
  for (std::size_t k = 0; k < b.size(); ++k) {
    if (!b.intact[k]) continue;
    const std::uint32_t i = b.a[k], j = b.b[k];
    const Vec3 point = bondPoint(p.position[i], p.radius[i], p.radius[j], b.normal[k],
                                 (p.position[j] - p.position[i]).norm());
    // The bond's elastic force on j (Eq 2-27; a contact bond's springs, no dashpots).
    const Vec3 on_j = b.normal_force[k] * b.normal[k] + b.shear_force[k];
    sum[j] += stressMoment(point - p.position[j], on_j);
    sum[i] += stressMoment(point - p.position[i], -on_j);
  }
  for (std::size_t i = 0; i < p.size(); ++i)
    sum[i] /= 4.0 / 3.0 * std::numbers::pi * std::pow(p.radius[i], 3);
  return sum;
}

}  // namespace rocklab::sim
