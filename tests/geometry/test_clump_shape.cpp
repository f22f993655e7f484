#include <catch2/catch.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>

#include "rocklab/geometry/clump_shape.h"

using namespace rocklab::geometry;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kRho = 2650.0;  // kg/m^3, granite

double sphereVolume(double r) { return 4.0 / 3.0 * kPi * r * r * r; }

// Relative accuracy to demand of a Union result: twice the volume's own error estimate.
double unionTolerance(const ClumpMassProperties& p) { return 2.0 * p.union_volume_error / p.union_volume; }

// Largest |a_ij - b_ij| relative to the largest |b_ij|.
double relativeDifference(const Mat3& a, const Mat3& b) { return (a - b).cwiseAbs().maxCoeff() / b.cwiseAbs().maxCoeff(); }

// Inertia tensor of a body with principal moments `axial` about unit axis `e` and `perpendicular`
// about every axis normal to it.
Mat3 axisymmetricInertia(const Vec3& e, double axial, double perpendicular) {
  return perpendicular * Mat3::Identity() + (axial - perpendicular) * e * e.transpose();
}

// Composite Simpson rule (exact enough for the low-order polynomials used here).
template <class F>
double simpson(F f, double a, double b, int n = 2000) {
  const double h = (b - a) / n;
  double s = f(a) + f(b);
  for (int k = 1; k < n; ++k) s += f(a + k * h) * (k % 2 ? 4.0 : 2.0);
  return s * h / 3.0;
}

std::vector<Sphere> transformed(const std::vector<Sphere>& body, const BodyPose& pose) {
  std::vector<Sphere> world;
  for (const Sphere& s : body) world.push_back({pose.position + pose.orientation * s.centre, s.radius});
  return world;
}

std::string writeFile(const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::temp_directory_path() / ("rocklab_test_clump_" + name)).string();
  std::ofstream(path) << text;
  return path;
}

}  // namespace

TEST_CASE("clump mass: a single sphere under every distribution", "[geometry][clump]") {
  const double r = 0.01;
  const Vec3 c(0.3, -0.2, 0.1);
  const double v = sphereVolume(r), m = kRho * v;
  const std::vector<Sphere> one{{c, r}};
  const auto sum = clumpMassProperties(one, kRho, ClumpMassDistribution::Sum);
  // Sum is exact: V = 4/3 π r³, I = 2/5 m r² about every axis.
  CHECK(sum.mass == Approx(m).epsilon(1e-14));
  CHECK(sum.volume == Approx(v).epsilon(1e-14));
  CHECK((sum.centre_of_mass - c).norm() < 1e-15);
  CHECK(relativeDifference(sum.inertia, 0.4 * m * r * r * Mat3::Identity()) < 1e-14);
  // The union quadrature: volume within its error estimate, which is small.
  CHECK(std::abs(sum.union_volume - v) <= sum.union_volume_error);
  CHECK(sum.union_volume_error < 1e-3 * v);
  for (auto d : {ClumpMassDistribution::EqualMass, ClumpMassDistribution::Union}) {
    const auto p = clumpMassProperties(one, kRho, d);
    const double tol = unionTolerance(p);
    CHECK(p.union_volume == sum.union_volume);
    CHECK(p.mass == Approx(m).epsilon(tol));
    CHECK(p.volume == Approx(v).epsilon(tol));
    CHECK((p.centre_of_mass - c).norm() < 1e-12 * r);
    CHECK(relativeDifference(p.inertia, sum.inertia) < tol);
    REQUIRE(p.member_mass.size() == 1);
    CHECK(p.member_mass[0] == Approx(p.mass).epsilon(1e-15));
  }
}

TEST_CASE("clump mass: two touching equal spheres", "[geometry][clump]") {
  // Line of centres along e, midpoint g: union = sum, I_axial = 2(2/5 m_s r²),
  // I_perpendicular = 2(2/5 m_s r² + m_s r²).
  const double r = 0.005;
  const Vec3 e = Vec3(1, 2, 2) / 3.0, g(0.01, -0.02, 0.03);
  const std::vector<Sphere> pair{{g - r * e, r}, {g + r * e, r}};
  const double ms = kRho * sphereVolume(r);
  const Mat3 exact = axisymmetricInertia(e, 2 * 0.4 * ms * r * r, 2 * (0.4 * ms * r * r + ms * r * r));
  for (auto d : {ClumpMassDistribution::Sum, ClumpMassDistribution::EqualMass, ClumpMassDistribution::Union}) {
    const auto p = clumpMassProperties(pair, kRho, d);
    const double tol = d == ClumpMassDistribution::Sum ? 1e-13 : unionTolerance(p);
    CHECK(std::abs(p.union_volume - 2 * sphereVolume(r)) <= p.union_volume_error);
    CHECK(p.mass == Approx(2 * ms).epsilon(tol));
    CHECK((p.centre_of_mass - g).norm() < 1e-12 * r);
    CHECK(relativeDifference(p.inertia, exact) < tol);
    // Smallest principal moment about the line of centres.
    CHECK(p.principal_moments[0] == Approx(2 * 0.4 * ms * r * r).epsilon(tol));
    CHECK(std::abs(p.principal_axes.col(0).dot(e)) == Approx(1.0).epsilon(1e-9));
  }
}

TEST_CASE("clump mass: overlapping equal pair - lens volume and double counting", "[geometry][clump]") {
  const double r = 0.004, dist = 1.2 * r, rho = 1000.0;
  const Vec3 g(0.001, 0.002, -0.003), e = Vec3(2, -1, 2) / 3.0;
  const std::vector<Sphere> pair{{g - 0.5 * dist * e, r}, {g + 0.5 * dist * e, r}};
  const double vs = sphereVolume(r), ms = rho * vs;
  // Lens: two caps of height r − d/2; V = π(4r + d)(2r − d)²/12.
  const double lens = kPi * (4 * r + dist) * (2 * r - dist) * (2 * r - dist) / 12.0;
  const double v_union = 2 * vs - lens;
  // Lens moments about its centre (the midpoint): slices at u = z + d/2 in [d/2, r], radius² r² − u².
  const double lens_axial = 2 * rho * simpson([&](double u) { return kPi * std::pow(r * r - u * u, 2) / 2; }, dist / 2, r);
  const double lens_perp = 2 * rho * simpson([&](double u) {
    const double a2 = r * r - u * u, z = u - dist / 2;
    return kPi * a2 * a2 / 4 + kPi * a2 * z * z;
  }, dist / 2, r);
  CHECK(lens_axial > 0);
  const double sum_axial = 2 * 0.4 * ms * r * r, sum_perp = 2 * (0.4 * ms * r * r + ms * dist * dist / 4);

  const auto sum = clumpMassProperties(pair, rho, ClumpMassDistribution::Sum);
  const auto eq = clumpMassProperties(pair, rho, ClumpMassDistribution::EqualMass);
  const auto uni = clumpMassProperties(pair, rho, ClumpMassDistribution::Union);
  INFO("union volume " << uni.union_volume << " exact " << v_union << " error estimate " << uni.union_volume_error);
  CHECK(std::abs(uni.union_volume - v_union) <= uni.union_volume_error);
  CHECK(uni.union_volume_error < 1e-3 * v_union);
  // Sum counts the lens twice; Union and EqualMass once.
  CHECK(sum.volume == Approx(2 * vs).epsilon(1e-14));
  CHECK(sum.mass == Approx(2 * ms).epsilon(1e-14));
  CHECK(sum.mass - uni.mass == Approx(rho * lens).epsilon(unionTolerance(uni) * v_union / lens));
  CHECK(uni.volume == Approx(v_union).epsilon(unionTolerance(uni)));
  CHECK(eq.mass == uni.mass);
  // Centre of mass at the midpoint for every distribution.
  for (const auto* p : {&sum, &eq, &uni}) CHECK((p->centre_of_mass - g).norm() < 1e-12 * r);
  // Sum: Eq 2-42/2-43 exactly. EqualMass: the same spheres, scaled to the union mass.
  CHECK(relativeDifference(sum.inertia, axisymmetricInertia(e, sum_axial, sum_perp)) < 1e-13);
  CHECK(relativeDifference(eq.inertia, sum.inertia * (eq.mass / sum.mass)) < 1e-13);
  // Union = the two spheres minus the lens once.
  CHECK(relativeDifference(uni.inertia, axisymmetricInertia(e, sum_axial - lens_axial, sum_perp - lens_perp)) <
        unionTolerance(uni));
  CHECK(uni.member_mass[0] == Approx(uni.mass / 2).epsilon(1e-15));
}

TEST_CASE("four-ball clump: union volume and Eq 4-2", "[geometry][clump]") {
  const double r = 7.35e-3;
  const auto members = fourBallClump(r);
  REQUIRE(members.size() == 4);
  // Rhombus of side r: five pairs at distance r, one at √3 r; centres mean at the origin.
  int short_pairs = 0, long_pairs = 0;
  Vec3 mean = Vec3::Zero();
  for (std::size_t i = 0; i < 4; ++i) {
    mean += members[i].centre / 4.0;
    CHECK(members[i].radius == r);
    CHECK(members[i].centre.z() == 0.0);
    for (std::size_t j = i + 1; j < 4; ++j) {
      const double d = (members[i].centre - members[j].centre).norm();
      short_pairs += std::abs(d - r) < 1e-12 * r;
      long_pairs += std::abs(d - std::sqrt(3.0) * r) < 1e-12 * r;
    }
  }
  CHECK(short_pairs == 5);
  CHECK(long_pairs == 1);
  CHECK(mean.norm() < 1e-15);

  const auto p = clumpMassProperties(members, kRho, ClumpMassDistribution::Union);
  const double r3 = r * r * r;
  INFO("union volume / r^3 = " << p.union_volume / r3 << " +- " << p.union_volume_error / r3);
  // experiments.md §c: true union ≈ 11.554 r³ (0.0005 for the printed rounding).
  CHECK(std::abs(p.union_volume / r3 - 11.554) <= p.union_volume_error / r3 + 0.0005);
  CHECK(p.union_volume_error < 0.005 * p.union_volume);
  CHECK(fourBallVolumeEq42(r) / r3 == Approx(10.445).margin(0.0005));
  CHECK(fourBallVolumeEq42(r) / r3 == Approx(20 * kPi / 9 + 2 * std::sqrt(3.0)).epsilon(1e-15));
  // Sizing: r for a 20 mm equivalent sphere (the study's r = 7.35 mm gives 19.9 mm).
  const double r20 = fourBallRadiusForEquivalentDiameter(0.02);
  CHECK(fourBallVolumeEq42(r20) == Approx(kPi / 6 * 0.02 * 0.02 * 0.02).epsilon(1e-14));
  CHECK(r20 == Approx(7.374e-3).margin(1e-6));
  CHECK(std::cbrt(6 / kPi * fourBallVolumeEq42(7.35e-3)) == Approx(0.0199).margin(5e-5));
  // Sum counts every overlap: 4 · 4/3 π r³ = 16.755 r³.
  const auto sum = clumpMassProperties(members, kRho, ClumpMassDistribution::Sum);
  CHECK(sum.volume / r3 == Approx(16.755).margin(0.0005));
}

TEST_CASE("four-ball clump: principal axes of a planar clump", "[geometry][clump]") {
  const auto members = fourBallClump(0.007);
  for (auto d : {ClumpMassDistribution::Sum, ClumpMassDistribution::EqualMass, ClumpMassDistribution::Union}) {
    const auto p = clumpMassProperties(members, kRho, d);
    // The rhombus is point-symmetric about the mean of its centres.
    CHECK(p.centre_of_mass.norm() < 1e-12 * 0.007);
    // Ascending, right-handed, orthonormal.
    CHECK(p.principal_moments[0] <= p.principal_moments[1]);
    CHECK(p.principal_moments[1] <= p.principal_moments[2]);
    CHECK(p.principal_axes.determinant() == Approx(1.0).epsilon(1e-12));
    CHECK((p.principal_axes.transpose() * p.principal_axes - Mat3::Identity()).norm() < 1e-12);
    CHECK((p.principal_axes * p.principal_moments.asDiagonal() * p.principal_axes.transpose() - p.inertia).norm() <
          1e-12 * p.inertia.norm());
    // Largest moment about the plane normal; triangle inequality I_3 <= I_1 + I_2 (strict:
    // the members have thickness, I_1 + I_2 − I_3 = 2∫ z² dm).
    CHECK(std::abs(p.principal_axes.col(2).z()) == Approx(1.0).epsilon(1e-12));
    CHECK(p.principal_moments[2] < p.principal_moments[0] + p.principal_moments[1]);
    CHECK(p.inertia(0, 2) == Approx(0.0).margin(1e-12 * p.inertia.norm()));
    CHECK(p.inertia(1, 2) == Approx(0.0).margin(1e-12 * p.inertia.norm()));
  }
}

TEST_CASE("union mass properties rotate with the clump", "[geometry][clump]") {
  // A rotated clump meets the quadrature grid differently: the results must agree to
  // within the quadrature error, and the inertia must transform as R I Rᵀ.
  const auto members = fourBallClump(0.007);
  Rng rng(17);
  const Mat3 rot = randomRotation(rng).toRotationMatrix();
  std::vector<Sphere> turned = members;
  for (Sphere& s : turned) s.centre = rot * s.centre + Vec3(0.05, 0.0, -0.02);
  const auto a = clumpMassProperties(members, kRho, ClumpMassDistribution::Union);
  const auto b = clumpMassProperties(turned, kRho, ClumpMassDistribution::Union);
  CHECK(std::abs(a.union_volume - b.union_volume) <= a.union_volume_error + b.union_volume_error);
  CHECK((b.centre_of_mass - Vec3(0.05, 0.0, -0.02)).norm() < 1e-4 * 0.007);
  CHECK(relativeDifference(b.inertia, rot * a.inertia * rot.transpose()) < unionTolerance(a) + unionTolerance(b));
  CHECK((b.principal_moments - a.principal_moments).norm() <
        (unionTolerance(a) + unionTolerance(b)) * a.principal_moments.norm());
}

TEST_CASE("total_mass rescales mass and inertia linearly", "[geometry][clump]") {
  const double r = 7.35e-3, pebble = kRho * kPi / 6 * 0.02 * 0.02 * 0.02;
  const auto members = fourBallClump(r);
  for (auto d : {ClumpMassDistribution::Sum, ClumpMassDistribution::EqualMass, ClumpMassDistribution::Union}) {
    const auto p = clumpMassProperties(members, kRho, d);
    const auto q = clumpMassProperties(members, kRho, d, pebble);
    const double scale = pebble / p.mass;
    CHECK(q.mass == Approx(pebble).epsilon(1e-15));
    CHECK(q.volume == Approx(pebble / kRho).epsilon(1e-15));
    CHECK(q.union_volume == p.union_volume);
    CHECK(relativeDifference(q.inertia, scale * p.inertia) < 1e-14);
    CHECK((q.principal_moments - scale * p.principal_moments).norm() < 1e-13 * q.principal_moments.norm());
    CHECK(q.centre_of_mass == p.centre_of_mass);
    double member_sum = 0;
    for (double m : q.member_mass) member_sum += m;
    CHECK(member_sum == Approx(pebble).epsilon(1e-14));
    for (double m : q.member_mass) CHECK(m == Approx(pebble / 4).epsilon(1e-14));  // four equal members
  }
  CHECK_THROWS_AS(clumpMassProperties({}, kRho, ClumpMassDistribution::Sum), std::invalid_argument);
  CHECK_THROWS_AS(clumpMassProperties(members, 0.0, ClumpMassDistribution::Sum), std::invalid_argument);
}

TEST_CASE("clump files: members are read and errors name the line", "[geometry][clump]") {
  const std::string good = writeFile("good.txt",
                                     "# four-ball clump, metres\n"
                                     "\n"
                                     "0 0 0 0.5   # first\n"
                                     "  1.5e-1\t-2 +3 1e-3\r\n");
  const auto members = readClumpFile(good);
  REQUIRE(members.size() == 2);
  CHECK(members[0].centre == Vec3(0, 0, 0));
  CHECK(members[0].radius == 0.5);
  CHECK(members[1].centre == Vec3(0.15, -2, 3));
  CHECK(members[1].radius == 1e-3);

  using Catch::Contains;
  const std::string bad_number = writeFile("bad_number.txt", "0 0 0 1\n# c\n1 2 abc 1\n");
  CHECK_THROWS_WITH(readClumpFile(bad_number), Contains(bad_number) && Contains("line 3") && Contains("'abc'"));
  const std::string trailing = writeFile("trailing.txt", "0 0 0 1x\n");
  CHECK_THROWS_WITH(readClumpFile(trailing), Contains("line 1") && Contains("'1x'"));
  const std::string bad_radius = writeFile("bad_radius.txt", "0 0 0 1\n\n1 0 0 -0.5\n");
  CHECK_THROWS_WITH(readClumpFile(bad_radius), Contains("line 3") && Contains("radius -0.5 must be > 0"));
  const std::string zero_radius = writeFile("zero_radius.txt", "0 0 0 0\n");
  CHECK_THROWS_WITH(readClumpFile(zero_radius), Contains("line 1") && Contains("radius"));
  const std::string fields = writeFile("fields.txt", "0 0 0 1\n0 0 1\n");
  CHECK_THROWS_WITH(readClumpFile(fields), Contains("line 2") && Contains("expected 4 fields") && Contains("found 3"));
  const std::string empty = writeFile("empty.txt", "# nothing\n\n");
  CHECK_THROWS_WITH(readClumpFile(empty), Contains(empty) && Contains("no members"));
  CHECK_THROWS_WITH(readClumpFile("/nonexistent/clump.txt"), Contains("/nonexistent/clump.txt") && Contains("cannot open"));
  CHECK_THROWS_AS(readClumpFile(bad_number), std::runtime_error);
  for (const auto& path : {good, bad_number, trailing, bad_radius, zero_radius, fields, empty}) std::filesystem::remove(path);
}

TEST_CASE("random rotations are orthonormal and uniform on average", "[geometry][clump]") {
  Rng rng(23), again(23);
  const int n = 20000;
  Vec3 mean_x = Vec3::Zero(), mean_z = Vec3::Zero();
  Mat3 mean = Mat3::Zero();
  for (int k = 0; k < n; ++k) {
    const Quat q = randomRotation(rng);
    CHECK(randomRotation(again).coeffs() == q.coeffs());
    const Mat3 rot = q.toRotationMatrix();
    REQUIRE((rot.transpose() * rot - Mat3::Identity()).norm() < 1e-14);
    REQUIRE(rot.determinant() == Approx(1.0).epsilon(1e-14));
    mean_x += rot * Vec3::UnitX() / n;
    mean_z += rot * Vec3::UnitZ() / n;
    mean += rot / n;
  }
  // A rotated unit vector is uniform on the sphere: each component has variance 1/3, so the
  // mean's components have standard deviation 1/√(3n) ≈ 0.004; allow five of them.
  const double limit = 5.0 / std::sqrt(3.0 * n);
  CHECK(mean_x.cwiseAbs().maxCoeff() < limit);
  CHECK(mean_z.cwiseAbs().maxCoeff() < limit);
  CHECK(mean.cwiseAbs().maxCoeff() < limit);
}

TEST_CASE("random bodies: seeded - inside the box - no overlaps", "[geometry][clump]") {
  const auto four = fourBallClump(0.005);
  const std::vector<Sphere> pair{{Vec3(-0.003, 0, 0), 0.004}, {Vec3(0.003, 0, 0), 0.004}};
  const std::vector<Sphere> single{{Vec3(0, 0, 0), 0.006}};
  std::vector<const std::vector<Sphere>*> shapes;
  for (int k = 0; k < 90; ++k) shapes.push_back(k % 3 == 0 ? &four : k % 3 == 1 ? &pair : &single);
  const std::vector<Sphere> existing{{Vec3(0.05, 0.05, 0.05), 0.02}, {Vec3(0.12, 0.03, 0.02), 0.01}};
  const Vec3 lo(0, 0, 0), hi(0.15, 0.1, 0.1);
  Rng a(5), b(5);
  const auto pa = randomNonOverlappingBodies(shapes, lo, hi, existing, a);
  const auto pb = randomNonOverlappingBodies(shapes, lo, hi, existing, b);
  REQUIRE(pa.size() == shapes.size());
  REQUIRE(pb.size() == pa.size());
  for (std::size_t k = 0; k < pa.size(); ++k) {
    CHECK(pa[k].position == pb[k].position);
    CHECK(pa[k].orientation.coeffs() == pb[k].orientation.coeffs());
  }
  // Every member of every body, tagged with its body (existing spheres: body -1).
  std::vector<std::pair<int, Sphere>> all;
  for (const Sphere& s : existing) all.emplace_back(-1, s);
  for (std::size_t k = 0; k < pa.size(); ++k)
    for (const Sphere& s : transformed(*shapes[k], pa[k])) all.emplace_back(static_cast<int>(k), s);
  int overlaps = 0, outside = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const Sphere& s = all[i].second;
    if (all[i].first >= 0)
      outside += ((s.centre.array() - s.radius) < lo.array() - 1e-12).any() ||
                 ((s.centre.array() + s.radius) > hi.array() + 1e-12).any();
    for (std::size_t j = i + 1; j < all.size(); ++j) {
      if (all[i].first == all[j].first) continue;  // members of one body overlap by design
      const Sphere& t = all[j].second;
      overlaps += (s.centre - t.centre).norm() < s.radius + t.radius - 1e-12;
    }
  }
  CHECK(overlaps == 0);
  CHECK(outside == 0);
  // Orientations are really random: not all the identity.
  CHECK(std::abs(pa[0].orientation.w()) < 1.0 - 1e-6);
}

TEST_CASE("random bodies: stop at the first body that does not fit", "[geometry][clump]") {
  const std::vector<Sphere> small{{Vec3::Zero(), 0.01}};
  const std::vector<Sphere> large{{Vec3::Zero(), 0.2}};
  Rng rng(1);
  const auto poses = randomNonOverlappingBodies({&small, &large, &small}, Vec3::Zero(), Vec3::Constant(0.1), {}, rng, 50);
  CHECK(poses.size() == 1);
  Rng rng2(1);
  CHECK(randomNonOverlappingBodies({}, Vec3::Zero(), Vec3::Constant(0.1), {}, rng2).empty());
}
