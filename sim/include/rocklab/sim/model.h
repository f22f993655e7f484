#pragma once
// The constant part of a simulation (MuJoCo's "model"): materials, contact law,
// walls, gravity schedule and engine settings. A World holds a Model and the
// mutable state; nothing here changes while a run steps.
#include <limits>
#include <string>
#include <vector>

#include "rocklab/geometry/packing.h"  // geometry::Sphere
#include "rocklab/geometry/triangle_mesh.h"
#include "rocklab/geometry/vec.h"
#include "rocklab/sim/bonds.h"

namespace rocklab::sim {

/// Properties of one material (a ball or a wall carries one).
struct Material {
  std::string name;
  double density = 2730.0;      // kg/m^3 (balls only)
  double kn = 1e9;              // N/m   normal stiffness of this entity (linear law, Eq 2-20)
  double ks = 1e9;              // N/m   shear stiffness of this entity (linear law, Eq 2-21)
  double friction = 0.37;       // -     Coulomb coefficient; a pair uses the smaller (ref §5)
  double shear_modulus = 0.0;   // Pa    G (Hertz–Mindlin, Eq 2-22)
  double poisson = 0.2;         // -     nu (Hertz–Mindlin)
  // The material this one was made from during a run (a breakage's fragment class
  // is a copy of its feed's), an earlier row of the same table; -1 for a scene's own.
  // A renderer draws it in that material's colour; run.h5 stores it (/materials).
  int made_from = -1;
};

enum class ContactLaw { Linear, HertzMindlin };

/// Mass used in the critical damping of a ball–ball dashpot (Eq 2-18).
enum class DampingMass {
  Average,  // the study's choice: (m_A + m_B) / 2
  Reduced,  // the usual two-body value: m_A m_B / (m_A + m_B)
};

/// Friction coefficient of a contact between two materials (ball-ball, ball-wall).
enum class FrictionRule {
  Min,   // the study's Eq 2-39: the smaller of the two
  Max,   // the larger: a base measured against the pebbles acts at its own value
  Mean,  // the arithmetic mean
};

struct ContactModel {
  ContactLaw law = ContactLaw::Linear;
  FrictionRule friction_rule = FrictionRule::Min;
  double damping_normal = 0.0;  // -  beta_n, critical damping ratio of the normal dashpot (Eq 2-17)
  double damping_shear = 0.0;   // -  beta_s, same for the shear dashpot
  DampingMass damping_mass = DampingMass::Average;
  double local_damping = 0.0;   // -  alpha of Cundall's local damping (Eq 2-15, sign form)
};

/// Prescribed motion of a wall: x(t) = pivot + T(t) + R(t) (x0 - pivot), with
/// T(t) = velocity t + amplitude sin(2 pi frequency t) and R(t) the rotation by
/// angular_velocity t about the pivot.
///
/// A spin about a body axis (spin_rate about spin_axis through spin_point, both in
/// the rest frame) moves the wall's material but not its surface: it is for a
/// surface of revolution about that axis (the cone crusher's mantle, Eq 6-9),
/// which the spin maps onto itself. It enters only the wall velocity,
///   v(x) = dT/dt + omega x (x - pivot - T) + spin_rate (R a) x (x - x_a),
///   x_a = pivot + T + R (spin_point - pivot),
/// never the pose: turning the mesh would make its tessellation wobble and force
/// neighbour rebuilds for a surface that does not move. At a contact only the
/// spin's tangential part counts (WallPose::contactVelocityAt): on the true
/// surface of revolution it has no other, on its facets the normal part is an
/// artefact the overlap never sees.
struct WallMotion {
  geometry::Vec3 velocity = geometry::Vec3::Zero();          // m/s
  geometry::Vec3 angular_velocity = geometry::Vec3::Zero();  // rad/s
  geometry::Vec3 pivot = geometry::Vec3::Zero();             // m
  geometry::Vec3 amplitude = geometry::Vec3::Zero();         // m, oscillation
  double frequency = 0.0;                                    // Hz, oscillation
  double spin_rate = 0.0;                                    // rad/s, signed, about spin_axis
  geometry::Vec3 spin_axis = geometry::Vec3::UnitZ();        // unit, rest frame
  geometry::Vec3 spin_point = geometry::Vec3::Zero();        // m, on the spin axis, rest frame
  /// A wall whose material does not move (a spinning wall moves: it does work).
  bool isStatic() const { return !surfaceMoves() && spin_rate == 0.0; }
  /// Whether the surface moves (a spin alone leaves it where it is).
  bool surfaceMoves() const {
    return !(velocity.isZero(0) && angular_velocity.isZero(0) && (amplitude.isZero(0) || frequency == 0.0));
  }
};

enum class WallShape { Plane, Polygon, Mesh };

struct Wall {
  std::string name;
  WallShape shape = WallShape::Plane;
  // Plane: a point and the unit normal pointing into the region where balls live.
  geometry::Vec3 point = geometry::Vec3::Zero();
  geometry::Vec3 normal = geometry::Vec3::UnitZ();
  // Polygon: convex, planar, vertices in order. Mesh: triangles.
  std::vector<geometry::Vec3> vertices;
  geometry::TriangleMesh mesh;
  // Mesh: faces meeting at less than this stand for one smooth surface, which a
  // ball touches once (geometry::TriangleMeshIndex::touches says why): the
  // tessellation of a curved wall, as LIGGGHTS's mesh `curvature`. Sharper
  // creases are corners, each face its own contact. [0, 90) degrees.
  double smooth_angle_deg = 10.0;
  int material = 0;
  WallMotion motion;
  double active_from = -std::numeric_limits<double>::infinity();   // s
  double active_until = std::numeric_limits<double>::infinity();   // s
  bool activeAt(double t) const { return t >= active_from && t < active_until; }
};

/// Gravity switches to `vector` at `time` (a chute tilts by turning gravity).
struct GravityChange {
  double time = 0.0;                                // s
  geometry::Vec3 vector = geometry::Vec3::Zero();  // m/s^2
};

struct TimestepSettings {
  // -  dt = safety_factor * dt_crit (spring criterion of one contact). 0.4, not the
  // usual 0.5: a settled pile with the study's dashpots (beta 0.11, ks = kn) is
  // just unstable at 0.5 (contact-network step ratio 1.04: it creeps, friction 10
  // by 1 % of a radius in 2e4 steps) and quiet at 0.4 (ratio 0.90), tests/stability.
  double safety_factor = 0.4;
  double dt = 0.0;             // s  requested step; 0 = automatic; may only lower the automatic one
  double impact_velocity = 5.0;  // m/s  used for the Hertz contact-time line of the audit
  bool allow_unsafe = false;     // accept a dt above the automatic one (stability tests only)
};

struct WatchdogSettings {
  double max_overlap_fraction = 0.5;  // -  overlap / smaller radius that stops the run
  double max_energy_growth = 0.1;     // -  allowed rise of mechanical energy, fraction of its scale
  int check_interval = 100;           // steps between energy checks
  // Step check of the whole contact network (contact_spectrum.h): every
  // network_interval steps, this many power iterations on its fastest mode; the
  // run stops when the step is above that mode's stable step (a pile creeping
  // silently past the per-contact critical step). 0 iterations = off. A step
  // forced above the automatic one (timestep.allow_unsafe) is checked every
  // check_interval steps instead: its single contacts may be unstable too, and
  // a fragment hopping on one touches only now and then (every 500 steps missed
  // it). Cost of 2 iterations every 100 steps: 16 % of the dense benchmark's
  // stepping time (3 % on the hopper); every 1000: a tenth of that.
  int network_iterations = 2;
  int network_interval = 1000;  // steps
};

/// Relaxation of the overlaps a World starts with ("freeze" in the spirit of the
/// study's procedure, experiments.md §g, but only its overlap part): balls created
/// overlapping — fragments placed by breakage replacement overlap their
/// neighbours by up to half a radius — would otherwise release the artificial
/// elastic energy of that overlap within one contact period (a fragment at
/// 1e9 N/m leaves at hundreds of m/s). With `steps` > 0 every contact that
/// touches when the World is built from spheres/clumps keeps its initial overlap
/// as an offset that shrinks to zero over `steps` steps (smoothstep in time: no
/// jerk at either end, peak rate 1.5 x offset / (steps dt)); the contact law
/// sees (overlap - offset) and pushes only when that is > 0, so the bodies are
/// eased apart and the stored energy is never released. Contacts made later are
/// untouched; a pair that separates loses its offset. While relaxing, the energy
/// watchdog is suspended (the shrinking offset does work) and the overlap
/// watchdog measures the overlap beyond the offset. 0 = off (default).
struct OverlapRelaxation {
  int steps = 0;  // steps over which initial overlaps are relaxed; 0 = off
};

struct Model {
  std::vector<Material> materials;
  ContactModel contact;
  std::vector<Wall> walls;
  geometry::Vec3 gravity = geometry::Vec3(0, 0, -9.81);  // m/s^2 at t = 0
  std::vector<GravityChange> gravity_changes;           // sorted by time
  TimestepSettings timestep;
  WatchdogSettings watchdog;
  OverlapRelaxation relaxation;
  ParallelBondModel bonds;  // used only by worlds built with bonds
  double skin = 0.0;  // m  Verlet skin; 0 = 0.2 x mean radius
  int max_grid_levels = 8;  // neighbour grid levels (one per doubling of the radius); 1 = plain grid
};

/// A sphere to add to a world.
struct SphereSpec {
  geometry::Vec3 position = geometry::Vec3::Zero();  // m
  geometry::Vec3 velocity = geometry::Vec3::Zero();  // m/s
  geometry::Vec3 omega = geometry::Vec3::Zero();     // rad/s
  double radius = 0.01;                              // m
  int material = 0;
};

/// A rigid clump to add to a world: member spheres in the body frame, whose axes
/// are the principal axes and whose origin is the centre of mass (build it with
/// geometry::clumpMassProperties). Member balls take `material` for contacts;
/// mass and inertia are the clump's (its density is not used).
struct ClumpSpec {
  geometry::Vec3 position = geometry::Vec3::Zero();        // m, centre of mass
  geometry::Quat orientation = geometry::Quat::Identity();  // body -> world
  geometry::Vec3 velocity = geometry::Vec3::Zero();        // m/s
  geometry::Vec3 omega = geometry::Vec3::Zero();           // rad/s, world frame
  double mass = 0.0;                                       // kg
  geometry::Vec3 principal_inertia = geometry::Vec3::Zero();  // kg m^2
  std::vector<geometry::Sphere> members;                   // body frame, m
  int material = 0;
};

}  // namespace rocklab::sim
