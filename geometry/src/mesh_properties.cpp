#include "rocklab/geometry/mesh_properties.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numbers>

namespace rocklab::geometry {

namespace {

// Eberly's subexpressions for one coordinate w of the three corners.
struct Sub {
  double f1, f2, f3, g0, g1, g2;
};

Sub subexpressions(double w0, double w1, double w2) {
  Sub s{};
  const double temp0 = w0 + w1;
  s.f1 = temp0 + w2;
  const double temp1 = w0 * w0;
  const double temp2 = temp1 + w1 * temp0;
  s.f2 = temp2 + w2 * s.f1;
  s.f3 = w0 * temp1 + w1 * temp2 + w2 * s.f2;
  s.g0 = s.f2 + w0 * (s.f1 + w0);
  s.g1 = s.f2 + w1 * (s.f1 + w1);
  s.g2 = s.f2 + w2 * (s.f1 + w2);
  return s;
}

}  // namespace

MeshMassProperties meshMassProperties(const TriangleMesh& mesh, double density) {
  const AABB box = mesh.bounds();
  const Vec3 origin = 0.5 * (box.lo + box.hi);
  // Integrals of 1, x, y, z, x², y², z², xy, yz, zx over the solid (about `origin`).
  double in[10] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  double area = 0;
  for (const auto& t : mesh.triangles) {
    const Vec3 p0 = mesh.vertices[t[0]] - origin, p1 = mesh.vertices[t[1]] - origin, p2 = mesh.vertices[t[2]] - origin;
    const Vec3 d = (p1 - p0).cross(p2 - p0);  // 2 * area * outward normal
    area += 0.5 * d.norm();
    const Sub x = subexpressions(p0.x(), p1.x(), p2.x());
    const Sub y = subexpressions(p0.y(), p1.y(), p2.y());
    const Sub z = subexpressions(p0.z(), p1.z(), p2.z());
    in[0] += d.x() * x.f1;
    in[1] += d.x() * x.f2;
    in[2] += d.y() * y.f2;
    in[3] += d.z() * z.f2;
    in[4] += d.x() * x.f3;
    in[5] += d.y() * y.f3;
    in[6] += d.z() * z.f3;
    in[7] += d.x() * (p0.y() * x.g0 + p1.y() * x.g1 + p2.y() * x.g2);
    in[8] += d.y() * (p0.z() * y.g0 + p1.z() * y.g1 + p2.z() * y.g2);
    in[9] += d.z() * (p0.x() * z.g0 + p1.x() * z.g1 + p2.x() * z.g2);
  }
  const double mult[10] = {1.0 / 6, 1.0 / 24, 1.0 / 24, 1.0 / 24, 1.0 / 60, 1.0 / 60, 1.0 / 60, 1.0 / 120, 1.0 / 120, 1.0 / 120};
  for (int k = 0; k < 10; ++k) in[k] *= mult[k];

  MeshMassProperties out;
  out.volume = in[0];
  out.area = area;
  out.mass = density * in[0];
  const Vec3 c(in[1] / in[0], in[2] / in[0], in[3] / in[0]);  // centroid relative to origin
  out.centroid = origin + c;
  // Second moments about the centroid (parallel-axis shift), per unit density.
  const double v = in[0];
  const double xx = in[4] - v * c.x() * c.x(), yy = in[5] - v * c.y() * c.y(), zz = in[6] - v * c.z() * c.z();
  const double xy = in[7] - v * c.x() * c.y(), yz = in[8] - v * c.y() * c.z(), zx = in[9] - v * c.z() * c.x();
  Mat3 inertia;
  inertia << yy + zz, -xy, -zx,  //
      -xy, zz + xx, -yz,         //
      -zx, -yz, xx + yy;
  out.inertia = density * inertia;
  Eigen::SelfAdjointEigenSolver<Mat3> eig(out.inertia);
  out.principal_moments = eig.eigenvalues();  // ascending
  out.principal_axes = eig.eigenvectors();
  if (out.principal_axes.determinant() < 0) out.principal_axes.col(2) *= -1.0;
  return out;
}

ShapeDescriptors shapeDescriptors(const TriangleMesh& mesh, const MeshMassProperties& props) {
  Vec3 lo = Vec3::Constant(INFINITY), hi = Vec3::Constant(-INFINITY);
  for (const Vec3& p : mesh.vertices) {
    const Vec3 q = props.principal_axes.transpose() * (p - props.centroid);
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  std::array<double, 3> dims{hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z()};
  std::sort(dims.begin(), dims.end(), std::greater<>());
  ShapeDescriptors d;
  d.long_dim = dims[0];
  d.intermediate_dim = dims[1];
  d.short_dim = dims[2];
  d.elongation = dims[1] / dims[0];
  d.flatness = dims[2] / dims[1];
  d.equivalent_diameter = std::cbrt(6.0 * props.volume / std::numbers::pi);
  d.sphericity = std::cbrt(std::numbers::pi) * std::pow(6.0 * props.volume, 2.0 / 3.0) / props.area;
  d.sieve_size = std::sqrt(0.5 * (dims[1] * dims[1] + dims[2] * dims[2]));
  return d;
}

TriangleMesh toPrincipalFrame(const TriangleMesh& mesh, const MeshMassProperties& props) {
  TriangleMesh out = mesh;
  for (Vec3& p : out.vertices) p = props.principal_axes.transpose() * (p - props.centroid);
  return out;
}

TriangleMesh scaled(const TriangleMesh& mesh, double factor) {
  TriangleMesh out = mesh;
  for (Vec3& p : out.vertices) p *= factor;
  return out;
}

}  // namespace rocklab::geometry
