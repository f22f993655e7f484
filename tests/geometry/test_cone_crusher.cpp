// Cone-crusher chamber (experiments.md §g.2) and mantle motion (§g.3).
#include <catch2/catch.hpp>

#include <cmath>
#include <map>
#include <numbers>
#include <string>

#include "rocklab/geometry/cone_crusher.h"
#include "rocklab/geometry/frustum_mesh.h"
#include "rocklab/geometry/mantle_motion.h"

using namespace rocklab::geometry;

namespace {

constexpr double kMm = 1e-3;

ConeCrusherSpec baseline(double css_mm = 15, double bite_deg = 20) {
  ConeCrusherSpec s;
  s.css = css_mm * kMm;
  s.bite_angle_deg = bite_deg;
  return s;
}

/// Edges by how many triangles use them (undirected).
std::map<std::pair<std::uint32_t, std::uint32_t>, int> edgeUse(const TriangleMesh& m) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> use;
  for (const auto& t : m.triangles)
    for (int k = 0; k < 3; ++k) ++use[std::minmax(t[k], t[(k + 1) % 3])];
  return use;
}

double distanceFromLine(const Vec3& p, const Vec3& point, const Vec3& unit_dir) {
  const Vec3 d = p - point;
  return (d - d.dot(unit_dir) * unit_dir).norm();
}

}  // namespace

TEST_CASE("cone crusher: the worked table of §g.2 (equations as printed)", "[geometry][crusher]") {
  struct Row {
    double css, bite, l, R_bot_c, R_mid_c, R_top_c, R_top_m, O_top_c_y;
  };
  const Row rows[] = {{15, 20, 116.95, 164.64, 128.07, 74.97, 36.39, 149.28},
                      {12, 18, 139.15, 162.59, 126.02, 58.56, 20.45, 164.58},
                      {18, 22, 98.77, 166.68, 130.11, 88.37, 49.41, 136.78}};
  const double tol = 0.01 * kMm;  // the table's last digit
  for (const Row& r : rows) {
    INFO("CSS " << r.css << " mm, beta " << r.bite << " deg");
    const ConeCrusherGeometry g = coneCrusherGeometry(baseline(r.css, r.bite));
    CHECK(g.l_upper_c == Approx(r.l * kMm).margin(tol));
    CHECK(g.l_m == Approx(r.l * kMm).margin(tol));
    CHECK(g.R_bot_c == Approx(r.R_bot_c * kMm).margin(tol));
    CHECK(g.R_mid_c == Approx(r.R_mid_c * kMm).margin(tol));
    CHECK(g.R_top_c == Approx(r.R_top_c * kMm).margin(tol));
    CHECK(g.R_top_m == Approx(r.R_top_m * kMm).margin(tol));
    CHECK(g.O_top_c.y == Approx(r.O_top_c_y * kMm).margin(tol));
    CHECK(g.h_eq61 == Approx(64.46 * kMm).margin(tol));
    CHECK(g.R_bot_m == Approx(150 * kMm).margin(tol));
    CHECK(g.O_bot_m.x == Approx(4.497 * kMm).margin(0.001 * kMm));
    CHECK(g.O_bot_m.y == Approx(-0.157 * kMm).margin(0.001 * kMm));
  }
}

TEST_CASE("cone crusher: the [R] x of O_top_m, the mantle tilt and the pivot readings", "[geometry][crusher]") {
  const ConeCrusherGeometry g = coneCrusherGeometry(baseline());
  CHECK(g.O_top_m.x == g.O_top_m_x_corrected);
  CHECK(g.O_top_m_x_corrected == Approx(1.09 * kMm).margin(0.01 * kMm));  // "~1.1 mm"
  CHECK(g.O_top_m_x_printed == Approx(38.60 * kMm).margin(0.01 * kMm));   // "~38.6 mm"
  CHECK(g.mantle_tilt * 180 / std::numbers::pi == Approx(1.81).margin(0.01));  // "~1.8 deg"
  CHECK(g.mantle_axis.norm() == Approx(1.0));

  ConeCrusherSpec printed = baseline();
  printed.mantle_top_x = MantleTopX::Printed;
  const ConeCrusherGeometry p = coneCrusherGeometry(printed);
  CHECK(p.O_top_m.x == Approx(38.60 * kMm).margin(0.01 * kMm));
  CHECK(p.mantle_tilt < -0.1);  // the printed x leans the mantle ~19 deg the wrong way

  // (A): pivot at s / sin(gamma) on the axis; (B): Eq 6-1's h, bottom centre s/2 off the axis.
  CHECK(g.pivot_distance == Approx(0.0045 / std::sin(2 * std::numbers::pi / 180)));
  CHECK(g.pivot_distance == Approx(128.94 * kMm).margin(0.01 * kMm));
  ConeCrusherSpec b = baseline();
  b.pivot = PivotPlacement::Eq61;
  const ConeCrusherGeometry gb = coneCrusherGeometry(b);
  CHECK(gb.pivot_distance == Approx(64.46 * kMm).margin(0.01 * kMm));
  CHECK(gb.O_bot_m.x == Approx(g.O_bot_m.x / 2));
  CHECK(gb.R_bot_c == Approx(g.R_bot_c - 2.25 * kMm * std::cos(2 * std::numbers::pi / 180)));
  // The open side opens with the bottom offset: twice as much in (A) (e = s) as in (B) (e = s/2).
  CHECK((g.open_side_setting - g.closed_side_gap) / (gb.open_side_setting - gb.closed_side_gap) ==
        Approx(2).epsilon(0.02));
  // As printed, the mantle's tilted bottom disc lifts its closed-side edge ~4.6 mm above the
  // concave's reference: the chamber's real smallest gap is below the nominal CSS (docs/crusher.md).
  CHECK(g.mantle_bottom_edge.y == Approx(4.57 * kMm).margin(0.01 * kMm));
  CHECK(g.closed_side_gap < g.spec.css);
}

TEST_CASE("cone crusher: the gaps of the section are those of the meshes", "[geometry][crusher]") {
  const ConeCrusherGeometry g = coneCrusherGeometry(baseline());
  const ConeCrusherMeshes m = coneCrusherMeshes(g);
  // Closed side: the smallest distance from the lower concave's closed-side generator to the mantle mesh.
  double closed = 1;
  for (int k = 0; k <= 400; ++k) {
    const double f = k / 400.0;
    const Vec3 p((1 - f) * g.R_bot_c + f * g.R_mid_c, 0, (1 - f) * g.O_bot_c.y + f * g.O_mid_c.y);
    closed = std::min(closed, (m.mantle.closestPoint(p) - p).norm());
  }
  CHECK(closed == Approx(g.closed_side_gap).margin(1e-6));
  // Open side: the mantle half a gyration later (turned by pi about the crusher axis), from the concave's lip.
  const Mat3 half = Eigen::AngleAxisd(std::numbers::pi, Vec3::UnitZ()).toRotationMatrix();
  TriangleMesh turned = m.mantle;
  for (Vec3& v : turned.vertices) v = half * v;
  const Vec3 lip(g.R_bot_c, 0, g.O_bot_c.y);
  CHECK((turned.closestPoint(lip) - lip).norm() == Approx(g.open_side_setting).margin(1e-6));
  CHECK(g.open_side_setting > g.closed_side_gap + 2 * g.spec.throw_ * std::sin(43 * std::numbers::pi / 180));
}

TEST_CASE("cone crusher: the frustum walls are closed around, open at their ends, radii as specified",
          "[geometry][crusher]") {
  const ConeCrusherGeometry g = coneCrusherGeometry(baseline());
  const ConeCrusherMeshes m = coneCrusherMeshes(g);
  const int n = g.spec.segments;
  struct Wall {
    const char* name;
    const TriangleMesh* mesh;
    Vec3 bottom, top;
    double r_bottom, r_top;
    bool outward;
  };
  const Wall walls[] = {
      {"mantle", &m.mantle, g.O_bot_m.world(), g.O_top_m.world(), g.R_bot_m, g.R_top_m, true},
      {"lower concave", &m.lower_concave, g.O_bot_c.world(), g.O_mid_c.world(), g.R_bot_c, g.R_mid_c, false},
      {"upper concave", &m.upper_concave, g.O_mid_c.world(), g.O_top_c.world(), g.R_mid_c, g.R_top_c, false},
      {"cap", &m.mantle_cap, g.O_top_m.world(), mantleCapApex(g), g.R_top_m, 0.0, true}};
  for (const Wall& w : walls) {
    INFO(w.name);
    CHECK(w.mesh->validate().empty());
    const bool cone = w.r_top == 0;
    CHECK(w.mesh->triangleCount() == static_cast<std::size_t>(cone ? n : 2 * n));
    int open = 0;
    for (const auto& [edge, uses] : edgeUse(*w.mesh)) {
      CHECK(uses <= 2);
      open += uses == 1;
    }
    CHECK(open == (cone ? n : 2 * n));  // the end rings only: the seam is shared
    const Vec3 axis = (w.top - w.bottom).normalized();
    for (int k = 0; k < n; ++k) {
      CHECK(distanceFromLine(w.mesh->vertices[k], w.bottom, axis) == Approx(w.r_bottom).epsilon(1e-12));
      CHECK((w.mesh->vertices[k] - w.bottom).dot(axis) == Approx(0).margin(1e-12));
      if (!cone) CHECK(distanceFromLine(w.mesh->vertices[n + k], w.top, axis) == Approx(w.r_top).epsilon(1e-12));
    }
    // Normals face the chamber: away from the crusher axis for the mantle and cap, toward it for the concaves.
    for (const auto& t : w.mesh->triangles) {
      const Vec3 a = w.mesh->vertices[t[0]], b = w.mesh->vertices[t[1]], c = w.mesh->vertices[t[2]];
      const Vec3 centre = (a + b + c) / 3, normal = (b - a).cross(c - a);
      const Vec3 radial = centre - w.bottom - (centre - w.bottom).dot(axis) * axis;
      CHECK((normal.dot(radial) > 0) == w.outward);
    }
  }
  // The first generator lies in the closed-side section: the mantle's bottom edge there is exact.
  CHECK((m.mantle.vertices[0] - g.mantle_bottom_edge.world()).norm() < 1e-15);
  CHECK((m.lower_concave.vertices[0] - Vec3(g.R_bot_c, 0, g.O_bot_c.y)).norm() < 1e-15);
}

TEST_CASE("cone crusher: bad geometry is refused, naming the parameter, its value and what is allowed",
          "[geometry][crusher]") {
  auto refusal = [](ConeCrusherSpec s) -> std::pair<std::string, std::string> {
    try {
      coneCrusherGeometry(s);
    } catch (const ConeCrusherError& e) {
      return {e.parameter, e.what()};
    }
    return {"", "accepted"};
  };
  ConeCrusherSpec s = baseline();
  s.css = 0.060;
  CHECK(refusal(s) == std::pair<std::string, std::string>{
                          "css", "cone crusher: css (CSS) = 60 mm: must be less than the feed opening F = 55 mm "
                                 "(the chamber narrows from F down to CSS)"});
  s = baseline();
  s.css = s.feed_opening;
  CHECK(refusal(s).first == "css");
  s = baseline();
  s.bite_angle_deg = -5;
  CHECK(refusal(s).second == "cone crusher: bite_angle_deg (beta) = -5 deg: must be > 0 deg and < 90 deg");
  s = baseline();
  s.eccentric_angle_deg = 50;
  CHECK_THAT(refusal(s).second, Catch::Contains("eccentric_angle_deg (gamma) = 50 deg: must be > 0 deg and < 45 deg"));
  s = baseline();
  s.cone_angle_deg = 0;
  CHECK(refusal(s).first == "cone_angle_deg");
  s = baseline();
  s.throw_ = std::nan("");
  CHECK(refusal(s).first == "throw");
  s = baseline();
  s.feed_opening = 0.2;  // the upper concave closes before reaching F
  CHECK(refusal(s).first == "bite_angle_deg");
  CHECK_THAT(refusal(s).second, Catch::Contains("R_top_c = ") && Catch::Contains("(Eq 6-6): must be > 0"));
  s = baseline();
  s.parallel_length = 0.3;
  CHECK_THAT(refusal(s).second, Catch::Contains("R_mid_c = ") && Catch::Contains("(Eq 6-5)"));
  s = baseline();
  s.segments = 2;
  CHECK(refusal(s).first == "segments");
  CHECK_THROWS_AS(frustumMesh({Vec3::Zero(), Vec3::UnitZ(), 1.0, -0.1}), std::invalid_argument);
}

TEST_CASE("mantle motion: closed form after 1000 revolutions, rolling closed side, retrograde net spin",
          "[geometry][crusher]") {
  const ConeCrusherGeometry g = coneCrusherGeometry(baseline());
  const MantleMotion m = mantleMotion(g, 300, SpinSense::Opposite);
  REQUIRE(m.eccentric_speed == Approx(31.4159).epsilon(1e-5));
  CHECK(m.spin_speed / m.eccentric_speed == Approx(154.5 / 150));  // Eq 6-9: (R + s)/R = 1.03
  const double period = 2 * std::numbers::pi / m.eccentric_speed;
  const Vec3 edge = g.mantle_bottom_edge.world();

  SECTION("the gyration alone returns to its start after N = 1000 revolutions") {
    MantleMotion gyration = m;
    gyration.spin_sense = SpinSense::None;
    const RigidPose p = mantlePoseAt(gyration, 1000 * period);
    CHECK((p.rotation - Mat3::Identity()).norm() < 1e-11);  // 1000 turns: an ulp of 1000 x 2 pi
    CHECK(p.translation.norm() < 1e-12);
    CHECK((mantlePoseAt(gyration, 0.5 * period).place(edge) - Vec3(-edge.x(), -edge.y(), edge.z())).norm() < 1e-15);
  }
  SECTION("with the spin: the axis is back and the mantle turned by the closed form -N 2 pi s/R") {
    const int N = 1000;
    const RigidPose p = mantlePoseAt(m, N * period);
    CHECK((p.rotation * m.axis - m.axis).norm() < 1e-11);
    CHECK((p.place(m.axis_point) - m.axis_point).norm() < 1e-12);
    const Eigen::AngleAxisd turned(p.rotation);
    const double signed_angle = turned.angle() * (turned.axis().dot(m.axis) > 0 ? 1 : -1);
    const long double net_turns = -static_cast<long double>(N) * (154.5L / 150.0L);  // spin turns; gyration adds whole ones
    long double expected = 2 * std::numbers::pi_v<long double> * (net_turns - std::floor(net_turns));
    if (expected > std::numbers::pi_v<long double>) expected -= 2 * std::numbers::pi_v<long double>;
    CHECK(signed_angle == Approx(static_cast<double>(expected)).margin(1e-9));
    // One revolution: a pure turn about the mantle axis by -2 pi s/R, i.e. a net rate -(s/R) omega_ecc.
    const Eigen::AngleAxisd one(mantlePoseAt(m, period).rotation);
    CHECK(one.angle() * (one.axis().dot(m.axis) > 0 ? 1 : -1) == Approx(-2 * std::numbers::pi * 4.5 / 150).epsilon(1e-9));
    const Vec3 w = mantleAngularVelocityAt(m, 0.123);
    CHECK(w.dot(mantlePoseAt(m, 0.123).rotation * m.axis) == Approx(-4.5 / 150 * m.eccentric_speed).epsilon(0.02));
  }
  SECTION("the closed-side bottom edge rolls (no tangential velocity) only with the opposite spin") {
    for (double t : {0.0, 0.0371, 0.25 * period, 7.77}) {
      INFO("t = " << t);
      // The closed side turns with the gyration; the material there changes (the spin).
      const Vec3 x = Eigen::AngleAxisd(turnAngle(m.eccentric_speed, t), Vec3::UnitZ()) * edge;
      const double scale = m.eccentric_speed * g.R_bot_m;  // 4.7 m/s
      CHECK(mantleVelocityAt(m, t, x).norm() < 1e-3 * scale);  // cos(gamma) of Eq 6-9's R + s: 0.05 %
      MantleMotion same = m;
      same.spin_sense = SpinSense::Same;
      CHECK(mantleVelocityAt(same, t, x).norm() > 1.9 * scale);
    }
  }
  SECTION("the velocity field is the time derivative of the pose") {
    const Vec3 x0 = g.mantle_top_edge.world() + Vec3(0, 0.01, 0.02);
    const double t = 1.234, dt = 1e-6;
    const Vec3 fd = (mantlePoseAt(m, t + dt).place(x0) - mantlePoseAt(m, t - dt).place(x0)) / (2 * dt);
    CHECK((fd - mantleVelocityAt(m, t, mantlePoseAt(m, t).place(x0))).norm() < 1e-6);
  }
}
