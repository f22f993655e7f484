#pragma once
// Clumps: rigid unions of spheres (dem-models.md §9). Mass properties under three
// mass distributions, the study's four-ball clump (experiments.md §c), clump files,
// random rotations and random non-overlapping placement of clumps.
//
// Mass properties. Eq 2-40…2-43 sum member spheres, so where members overlap the
// shared volume is counted twice and the density is not uniform. Ferellec and
// McDowell give every member the same mass instead. Neither is the rigid body a
// uniform material of the clump's shape would be, so the true union of the spheres
// is integrated as well: its volume is always reported, and the `Union` mode
// takes its centre of mass and inertia from it too.
//
// Union integration (column integration). An (x, y) grid of square cells spans the
// union's bounding box. Above each cell centre every sphere covers one exact
// z-interval; the intervals are merged and ∫1, ∫z, ∫z² dz are taken analytically.
// The (x, y) integral is the midpoint rule. The column length goes like the square
// root of the distance to a sphere's rim, so the error falls roughly as h^1.5 to h^2
// but fluctuates with how the grid meets the rims: |V(n) − V(n/2)| alone was below
// the true error for 29 of 150 random clumps at n = 256 (by up to 25x). The estimate
// is therefore |V(n) − V(n/2)| + |V(n/2) − V(n/4)|, which bounded the true error in
// all 150 (typically 20x above it). Only the volume's error is estimated; the
// centre of mass and inertia come from the same columns and converge alike.
#include <string>
#include <vector>

#include "rocklab/geometry/packing.h"
#include "rocklab/geometry/vec.h"

namespace rocklab::geometry {

/// How mass is spread over a clump's member spheres (dem-models.md §9).
enum class ClumpMassDistribution {
  Sum,        // Eq 2-40..2-43 as printed: each member rho*V_p, overlaps counted twice
  EqualMass,  // Ferellec–McDowell: every member the same mass; inertia = sum of member spheres
  Union,      // uniform density over the true union of the spheres (overlaps once)
};

struct ClumpMassProperties {
  double mass = 0;                // kg
  double volume = 0;              // m^3, the volume `mass` stands for (mass / density)
  double union_volume = 0;        // m^3, true union volume (always computed)
  double union_volume_error = 0;  // m^3, estimated absolute quadrature error of union_volume
  Vec3 centre_of_mass = Vec3::Zero();  // m, in the input frame
  Mat3 inertia = Mat3::Zero();    // kg m^2 about the centre of mass, input-frame axes (tensor with -products, Eq 2-43)
  Vec3 principal_moments = Vec3::Zero();  // kg m^2, ascending
  Mat3 principal_axes = Mat3::Identity();  // columns = principal axes (input frame), right-handed (det +1)
  // kg per member. Sum: rho V_p; EqualMass: mass / N. Union: the integration gives no
  // per-member mass, so this is mass * V_p / sum V_p (for reporting only; it is not
  // what the centre of mass and inertia were computed from).
  std::vector<double> member_mass;
};

/// Mass properties of a rigid union of spheres (density in kg/m^3). `total_mass` > 0
/// rescales the mass, inertia and member masses so the clump has the mass of the pebble
/// it stands for (the study's density correction); 0 = density * volume of the chosen
/// distribution (Sum: sum of member volumes; EqualMass and Union: union volume).
/// `volume` is always mass / density. `resolution` = quadrature cells across the largest
/// extent (>= 2). Throws std::invalid_argument for no members, a radius <= 0, density <= 0,
/// total_mass < 0 or resolution < 2.
ClumpMassProperties clumpMassProperties(const std::vector<Sphere>& members, double density,
                                        ClumpMassDistribution distribution, double total_mass = 0.0,
                                        int resolution = 256);

/// The four-ball clump of the study (experiments.md §c): four spheres of radius r in the
/// z = 0 plane at the corners of a 60°/120° rhombus of side r: (0,0,0), (r,0,0),
/// (r/2,√3r/2,0), (3r/2,√3r/2,0), then shifted so the mean of the centres is the origin.
std::vector<Sphere> fourBallClump(double member_radius);

/// Eq 4-2: V = (20π/9 + 2√3) r³ ≈ 10.445 r³ (the study's sizing volume; the true
/// union volume is ≈ 11.554 r³).
double fourBallVolumeEq42(double member_radius);

/// Member radius r such that fourBallVolumeEq42(r) equals the volume of a sphere of
/// diameter d_eq.
double fourBallRadiusForEquivalentDiameter(double d_eq);

/// Reads a clump file: one member per line "x y z r" (metres, whitespace separated;
/// '#' starts a comment; blank lines ignored). Throws std::runtime_error naming the
/// file, the line number and what is wrong (non-numeric, radius <= 0, wrong field
/// count, no members), as "clump file 'path' line N: ...".
std::vector<Sphere> readClumpFile(const std::string& path);

/// Uniformly random rotation (Shoemake's method) from the project's Rng; draws three
/// uniforms.
Quat randomRotation(Rng& rng);

/// Pose of a rigid body: world point = position + orientation * body point.
struct BodyPose {
  Vec3 position;
  Quat orientation;
};

/// Random non-overlapping placement of rigid bodies made of spheres (body frame, centred
/// near the origin) in the box [lo, hi] (every member kept inside), each with a random
/// orientation; shapes[k] is the body shape of body k. No member may overlap a member of
/// another body or `existing` (touching is allowed). Uses a hash grid like
/// randomNonOverlapping. Each attempt draws a new orientation, then a position. Returns
/// poses for bodies 0, 1, ... in order, stopping at the first body that cannot be placed
/// in `max_attempts` attempts (so pose k is always that of shapes[k]).
std::vector<BodyPose> randomNonOverlappingBodies(const std::vector<const std::vector<Sphere>*>& shapes,
                                                 const Vec3& lo, const Vec3& hi,
                                                 const std::vector<Sphere>& existing, Rng& rng,
                                                 int max_attempts = 1000);

}  // namespace rocklab::geometry
