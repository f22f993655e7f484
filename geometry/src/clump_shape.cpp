#include "rocklab/geometry/clump_shape.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <stdexcept>
#include <unordered_map>
#include <utility>

#include "rocklab/geometry/sphere_hash_grid.h"

namespace rocklab::geometry {

namespace {

constexpr double kPi = std::numbers::pi;

double sphereVolume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

// ∫1, ∫r and ∫r rᵀ dV over the union of spheres, with r measured from `ref`.
struct UnionMoments {
  double volume = 0;                 // m^3
  Vec3 first = Vec3::Zero();         // m^4
  Mat3 second = Mat3::Zero();        // m^5
};

// Column integration of the union (see the header): an (x, y) midpoint rule with
// `n` cells across the largest extent, exact merged z-intervals in each column.
UnionMoments integrateUnion(const std::vector<Sphere>& members, const Vec3& ref, int n) {
  // Bounding box of the union, and a square-celled grid centred on it.
  Vec3 lo = members.front().centre.array() - members.front().radius;
  Vec3 hi = members.front().centre.array() + members.front().radius;
  for (const Sphere& s : members) {
    lo = lo.cwiseMin((s.centre.array() - s.radius).matrix());
    hi = hi.cwiseMax((s.centre.array() + s.radius).matrix());
  }
  const Vec3 extent = hi - lo;
  const double h = extent.maxCoeff() / n;
  const int nx = std::max(1, static_cast<int>(std::ceil(extent.x() / h - 1e-9)));
  const int ny = std::max(1, static_cast<int>(std::ceil(extent.y() / h - 1e-9)));
  const double x0 = 0.5 * (lo.x() + hi.x()) - 0.5 * nx * h - ref.x();  // grid corner, relative to ref
  const double y0 = 0.5 * (lo.y() + hi.y()) - 0.5 * ny * h - ref.y();

  // Column sums: ∫L, ∫xL, ∫yL, ∫Z1, ∫x²L, ∫y²L, ∫Z2, ∫xyL, ∫xZ1, ∫yZ1 (per unit cell area),
  // with L = ∫dz, Z1 = ∫z dz, Z2 = ∫z² dz over the column.
  double v = 0, sx = 0, sy = 0, sz = 0, sxx = 0, syy = 0, szz = 0, sxy = 0, sxz = 0, syz = 0;
  struct RowSphere {
    double cx, cz, r2_minus_dy2;  // centre x and z relative to ref; r² − (y − cy)²
  };
  std::vector<RowSphere> row;
  std::vector<std::pair<double, double>> intervals;
  for (int j = 0; j < ny; ++j) {
    const double y = y0 + (j + 0.5) * h;
    // Spheres this row of columns passes through.
    row.clear();
    for (const Sphere& s : members) {
      const double dy = y - (s.centre.y() - ref.y());
      const double q = s.radius * s.radius - dy * dy;
      if (q > 0) row.push_back({s.centre.x() - ref.x(), s.centre.z() - ref.z(), q});
    }
    if (row.empty()) continue;
    for (int i = 0; i < nx; ++i) {
      const double x = x0 + (i + 0.5) * h;
      // Exact z-interval of each sphere above (x, y).
      intervals.clear();
      for (const RowSphere& s : row) {
        const double q = s.r2_minus_dy2 - (x - s.cx) * (x - s.cx);
        if (q <= 0) continue;
        const double half = std::sqrt(q);
        intervals.emplace_back(s.cz - half, s.cz + half);
      }
      if (intervals.empty()) continue;
      // Merge the intervals and integrate 1, z, z² over each piece analytically.
      std::sort(intervals.begin(), intervals.end());
      double len = 0, z1 = 0, z2 = 0;
      auto add = [&](double a, double b) {
        len += b - a;
        z1 += 0.5 * (b * b - a * a);
        z2 += (b * b * b - a * a * a) / 3.0;
      };
      double a = intervals.front().first, b = intervals.front().second;
      for (std::size_t k = 1; k < intervals.size(); ++k) {
        if (intervals[k].first > b) {
          add(a, b);
          a = intervals[k].first;
          b = intervals[k].second;
        } else {
          b = std::max(b, intervals[k].second);
        }
      }
      add(a, b);
      v += len;
      sx += x * len;
      sy += y * len;
      sz += z1;
      sxx += x * x * len;
      syy += y * y * len;
      szz += z2;
      sxy += x * y * len;
      sxz += x * z1;
      syz += y * z1;
    }
  }
  const double area = h * h;
  UnionMoments m;
  m.volume = v * area;
  m.first = Vec3(sx, sy, sz) * area;
  m.second << sxx, sxy, sxz,  //
      sxy, syy, syz,          //
      sxz, syz, szz;
  m.second *= area;
  return m;
}


}  // namespace

ClumpMassProperties clumpMassProperties(const std::vector<Sphere>& members, double density,
                                        ClumpMassDistribution distribution, double total_mass,
                                        int resolution) {
  if (members.empty()) throw std::invalid_argument("clumpMassProperties: no members");
  for (std::size_t p = 0; p < members.size(); ++p)
    if (!(members[p].radius > 0))
      throw std::invalid_argument("clumpMassProperties: member " + std::to_string(p) + " has radius <= 0");
  if (!(density > 0)) throw std::invalid_argument("clumpMassProperties: density must be > 0");
  if (!(total_mass >= 0)) throw std::invalid_argument("clumpMassProperties: total_mass must be >= 0");
  if (resolution < 2) throw std::invalid_argument("clumpMassProperties: resolution must be >= 2");

  ClumpMassProperties out;
  const std::size_t count = members.size();
  double member_volume_sum = 0;
  Vec3 ref = Vec3::Zero();  // mean of the centres: integration origin, keeps the moments small
  for (const Sphere& s : members) {
    member_volume_sum += sphereVolume(s.radius);
    ref += s.centre;
  }
  ref /= static_cast<double>(count);

  // True union volume. Error estimate |V(n) − V(n/2)| + |V(n/2) − V(n/4)|: the first
  // difference alone is sometimes small by chance (see the header); V(n/4) costs 1/16 more.
  const UnionMoments fine = integrateUnion(members, ref, resolution);
  const double half = integrateUnion(members, ref, std::max(1, resolution / 2)).volume;
  const double quarter = integrateUnion(members, ref, std::max(1, resolution / 4)).volume;
  out.union_volume = fine.volume;
  out.union_volume_error = std::abs(fine.volume - half) + std::abs(half - quarter);

  if (distribution == ClumpMassDistribution::Union) {
    // Uniform density over the union: m = rho V, x_G = ∫r dV / V,
    // I = rho ∫ (|d|² 1 − d dᵀ) dV with d = r − x_G.
    out.mass = density * fine.volume;
    const Vec3 c = fine.first / fine.volume;
    const Mat3 central = fine.second - fine.volume * c * c.transpose();  // ∫ d dᵀ dV
    out.centre_of_mass = ref + c;
    out.inertia = density * (central.trace() * Mat3::Identity() - central);
    out.member_mass.reserve(count);
    for (const Sphere& s : members) out.member_mass.push_back(out.mass * sphereVolume(s.radius) / member_volume_sum);
  } else {
    // Member masses: Sum gives each member rho V_p; EqualMass spreads rho V_union evenly.
    out.member_mass.reserve(count);
    for (const Sphere& s : members)
      out.member_mass.push_back(distribution == ClumpMassDistribution::Sum
                                    ? density * sphereVolume(s.radius)
                                    : density * fine.volume / static_cast<double>(count));
    // Eq 2-40 m = Σ m_p; Eq 2-41 x_G = Σ m_p x_p / m.
    Vec3 weighted = Vec3::Zero();
    for (std::size_t p = 0; p < count; ++p) {
      out.mass += out.member_mass[p];
      weighted += out.member_mass[p] * (members[p].centre - ref);
    }
    const Vec3 c = weighted / out.mass;
    out.centre_of_mass = ref + c;
    // Eq 2-42 diagonal I_ii = Σ m_p [Σ_{j≠i} d_j² + 2/5 R_p²] and Eq 2-43 products
    // I_ij = Σ m_p d_i d_j entering with a minus sign: I = Σ m_p [(|d|² + 2/5 R²) 1 − d dᵀ].
    for (std::size_t p = 0; p < count; ++p) {
      const Vec3 d = members[p].centre - ref - c;
      const double r = members[p].radius;
      out.inertia += out.member_mass[p] *
                     ((d.squaredNorm() + 0.4 * r * r) * Mat3::Identity() - d * d.transpose());
    }
  }

  // Density correction: the clump gets the pebble's mass, its shape's mass distribution.
  if (total_mass > 0) {
    const double scale = total_mass / out.mass;
    out.mass = total_mass;
    out.inertia *= scale;
    for (double& m : out.member_mass) m *= scale;
  }
  out.volume = out.mass / density;

  // Principal moments (ascending) and axes, made right-handed.
  out.inertia = 0.5 * (out.inertia + out.inertia.transpose());
  const Eigen::SelfAdjointEigenSolver<Mat3> eigen(out.inertia);
  out.principal_moments = eigen.eigenvalues();
  out.principal_axes = eigen.eigenvectors();
  if (out.principal_axes.determinant() < 0) out.principal_axes.col(2) *= -1.0;
  return out;
}

std::vector<Sphere> fourBallClump(double member_radius) {
  const double r = member_radius;
  const double s = std::numbers::sqrt3 / 2.0 * r;
  std::vector<Sphere> members{{Vec3(0, 0, 0), r}, {Vec3(r, 0, 0), r}, {Vec3(0.5 * r, s, 0), r},
                              {Vec3(1.5 * r, s, 0), r}};
  const Vec3 mean(0.75 * r, 0.5 * s, 0);  // mean of the four centres
  for (Sphere& m : members) m.centre -= mean;
  return members;
}

double fourBallVolumeEq42(double member_radius) {
  // Eq 4-2: V = ∫_{−r}^{r} (5π/3 + 3√3/2)(r² − x²) dx = (20π/9 + 2√3) r³.
  return (20.0 * kPi / 9.0 + 2.0 * std::numbers::sqrt3) * member_radius * member_radius * member_radius;
}

double fourBallRadiusForEquivalentDiameter(double d_eq) {
  // π d³/6 = (20π/9 + 2√3) r³.
  return d_eq * std::cbrt(kPi / 6.0 / fourBallVolumeEq42(1.0));
}

std::vector<Sphere> readClumpFile(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error("clump file '" + path + "': cannot open");
  auto fail = [&](int line, const std::string& what) {
    return std::runtime_error("clump file '" + path + "' line " + std::to_string(line) + ": " + what);
  };
  std::vector<Sphere> members;
  std::string text;
  for (int line = 1; std::getline(in, text); ++line) {
    // Strip the comment, then split on whitespace.
    if (const auto hash = text.find('#'); hash != std::string::npos) text.erase(hash);
    std::istringstream fields(text);
    std::vector<std::string> tokens;
    for (std::string token; fields >> token;) tokens.push_back(token);
    if (tokens.empty()) continue;
    if (tokens.size() != 4)
      throw fail(line, "expected 4 fields \"x y z r\", found " + std::to_string(tokens.size()));
    std::array<double, 4> value{};
    for (std::size_t k = 0; k < 4; ++k) {
      const std::string& t = tokens[k];
      // from_chars rejects a leading '+', which strtod and C++ streams accept.
      const bool plus = t.size() > 1 && t[0] == '+' && t[1] != '-' && t[1] != '+';
      const char* first = t.data() + (plus ? 1 : 0);
      const auto [end, error] = std::from_chars(first, t.data() + t.size(), value[k]);
      if (error != std::errc() || end != t.data() + t.size() || !std::isfinite(value[k]))
        throw fail(line, "field " + std::to_string(k + 1) + " '" + t + "' is not a finite number");
    }
    if (!(value[3] > 0)) throw fail(line, "radius " + tokens[3] + " must be > 0");
    members.push_back({Vec3(value[0], value[1], value[2]), value[3]});
  }
  if (members.empty()) throw std::runtime_error("clump file '" + path + "': no members");
  return members;
}

Quat randomRotation(Rng& rng) {
  // Shoemake (1992): with u1, u2, u3 uniform on [0, 1), the unit quaternion
  // (√(1−u1) sin 2πu2, √(1−u1) cos 2πu2, √u1 sin 2πu3, √u1 cos 2πu3) is uniform on S³.
  const double u1 = rng.uniform(), u2 = rng.uniform(), u3 = rng.uniform();
  const double a = std::sqrt(1.0 - u1), b = std::sqrt(u1);
  const double t2 = 2.0 * kPi * u2, t3 = 2.0 * kPi * u3;
  Quat q(b * std::cos(t3), a * std::sin(t2), a * std::cos(t2), b * std::sin(t3));  // (w, x, y, z)
  q.normalize();
  return q;
}

std::vector<BodyPose> randomNonOverlappingBodies(const std::vector<const std::vector<Sphere>*>& shapes,
                                                 const Vec3& lo, const Vec3& hi,
                                                 const std::vector<Sphere>& existing, Rng& rng,
                                                 int max_attempts) {
  double r_max = 0;
  for (std::size_t k = 0; k < shapes.size(); ++k) {
    if (shapes[k] == nullptr || shapes[k]->empty())
      throw std::invalid_argument("randomNonOverlappingBodies: shape " + std::to_string(k) + " has no members");
    for (const Sphere& s : *shapes[k]) r_max = std::max(r_max, s.radius);
  }
  for (const Sphere& s : existing) r_max = std::max(r_max, s.radius);
  std::vector<BodyPose> poses;
  if (shapes.empty()) return poses;
  SphereHashGrid grid{2.0 * r_max, {}};
  for (const Sphere& s : existing) grid.insert(s);

  poses.reserve(shapes.size());
  std::vector<Sphere> world;  // members of the candidate body, world frame
  for (const std::vector<Sphere>* shape : shapes) {
    bool ok = false;
    for (int attempt = 0; attempt < max_attempts && !ok; ++attempt) {
      // Orientation first; then the positions that keep every member inside the box.
      const Quat orientation = randomRotation(rng);
      const Mat3 worldFromBody = orientation.toRotationMatrix();
      Vec3 body_lo = Vec3::Constant(std::numeric_limits<double>::infinity());
      Vec3 body_hi = -body_lo;
      world.clear();
      for (const Sphere& s : *shape) {
        const Vec3 c = worldFromBody * s.centre;
        body_lo = body_lo.cwiseMin((c.array() - s.radius).matrix());
        body_hi = body_hi.cwiseMax((c.array() + s.radius).matrix());
        world.push_back({c, s.radius});
      }
      const Vec3 p_lo = lo - body_lo, p_hi = hi - body_hi;
      if ((p_lo.array() > p_hi.array()).any()) continue;  // does not fit this way round
      const Vec3 position(rng.uniform(p_lo.x(), p_hi.x()), rng.uniform(p_lo.y(), p_hi.y()),
                          rng.uniform(p_lo.z(), p_hi.z()));
      for (Sphere& s : world) s.centre += position;
      if (std::any_of(world.begin(), world.end(),
                      [&](const Sphere& s) { return grid.overlaps(s.centre, s.radius); }))
        continue;
      for (const Sphere& s : world) grid.insert(s);
      poses.push_back({position, orientation});
      ok = true;
    }
    if (!ok) break;
  }
  return poses;
}

}  // namespace rocklab::geometry
