#pragma once
// Particle stress and octahedral shear stress (dem-models.md §11): the average
// stress of a ball from the forces at its contacts and bonds, its principal
// stresses, and q of Eq 3-15 / 6-10 [R], the trigger of the population-balance
// breakage (experiments.md §g.6). Compression is positive.
#include "rocklab/geometry/vec.h"

namespace rocklab::sim {

/// Principal stresses sigma1 >= sigma2 >= sigma3 (Pa, compression positive) and
/// the direction of the minor one (least compressive / most tensile: where the
/// PBM places fragments, §11).
struct PrincipalStresses {
  double major = 0.0, intermediate = 0.0, minor = 0.0;       // Pa
  geometry::Vec3 minor_direction = geometry::Vec3::UnitX();  // unit
};

/// Eigenvalues and the minor eigenvector of a symmetric stress tensor.
PrincipalStresses principalStresses(const geometry::Mat3& stress);

/// q = (1/3) sqrt((s1 - s2)^2 + (s2 - s3)^2 + (s3 - s1)^2) (Eq 3-15 / 6-10 [R]), Pa.
double octahedralShearStress(const PrincipalStresses& s);

/// The same q from the tensor's invariants, without its eigenvalues: the sum of
/// squared differences of the principal values is 3 tr(S^2) - (tr S)^2 of the
/// symmetric part S (a breakage check tests every ball's q and needs the
/// principal directions only of the balls that break).
double octahedralShearStress(const geometry::Mat3& stress);

}  // namespace rocklab::sim
