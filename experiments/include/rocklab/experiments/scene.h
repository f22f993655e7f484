#pragma once
// Scenes are TOML files (assets/scenes/*.toml). Loading one validates every
// key: an unknown key, a wrong type or a value out of range is a SceneError
// whose message names the file, line, key, value and what is allowed.
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "rocklab/geometry/camera.h"
#include "rocklab/geometry/cone_crusher.h"
#include "rocklab/geometry/mantle_motion.h"
#include "rocklab/render/frame.h"
#include "rocklab/sim/model.h"

namespace rocklab::experiments {

struct SceneError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// How a run is driven and what it writes.
struct RunSettings {
  std::string name;
  std::string description;
  std::uint64_t seed = 1;
  double end_time = 0.0;       // s; or...
  std::uint64_t steps = 0;     // ...a step count (exactly one of the two is set)
  double frame_interval = 0.0;       // s between trajectory frames; 0 = first and last only
  double energy_interval = 0.0;      // s between energy-log rows; 0 = at frames only
  double checkpoint_interval = 0.0;  // s between checkpoints; 0 = at the end only
  bool hdf5 = true;            // run.h5
  bool vtk = false;            // .vtp/.pvd series
  bool checkpoint = true;      // checkpoint.h5
};

/// The settings of the scene's experiment: read and checked by its driver
/// (experiments/src/drivers/), never seen by code outside the library.
struct ExperimentSettings;

/// Mass properties of one clump shape of the scene, for the log and results.json.
struct ClumpShapeReport {
  std::string source;          // particles.N
  std::string shape;           // "four_ball" or the clump file
  std::size_t members = 0;
  double mass = 0;             // kg
  double volume = 0;           // m^3, the volume the mass stands for
  double union_volume = 0;     // m^3, true union volume (and its quadrature error)
  double union_volume_error = 0;
  double equivalent_diameter = 0;  // m, sphere of `volume`
  std::string distribution;    // sum | equal_mass | union
  geometry::Vec3 principal_inertia = geometry::Vec3::Zero();  // kg m^2
};

/// One bonded agglomerate of the scene ([[particles]] type = "agglomerate"):
/// its balls are scene.spheres[first_ball, first_ball + balls), its bonds
/// scene.bonds[first_bond, first_bond + bonds) (with bonds.type =
/// "parallel+contact" the parallel ones; their contact bonds follow all of those).
struct AgglomerateReport {
  std::string source;           // particles.N
  std::string method;           // "hcp", "dense" or "library:<its method>"
  std::size_t first_ball = 0, balls = 0, first_bond = 0, bonds = 0;
  double diameter = 0;          // m, of the bounding sphere
  double porosity = 0;          // -, against the bounding sphere
  double coordination_number = 0;  // bonds per ball (x 2)
  double solid_volume = 0;      // m^3
  double bond_strength = 0;     // Pa (N if contact bonds only), its own (constant or drawn) tensile strength; 0 = per bond
};

/// A virtual camera of the scene ([[cameras]]): frames are rendered only at its
/// frame times, never every step. A scene without cameras never creates a GL context.
/// What a ball's colour shows: its material (marker pebbles red), or its
/// fragment (the balls joined by intact bonds; camera/fragment_colours.h).
enum class ColourBy { Material, Fragment };

struct CameraSettings {
  std::string name;
  ColourBy colour_by = ColourBy::Material;
  geometry::Camera camera;       // intrinsics, pose, frame rate, exposure
  double start_time = 0.0;       // s, first frame
  double end_time = std::numeric_limits<double>::infinity();  // s
  bool movie = true;             // <name>.mp4 (or .avi)
  double movie_fps = 25.0;       // playback rate of the movie, frames/s
  double still_interval = 0.0;   // s between PNG stills (0 = none)
  bool all_frames = false;       // every frame as PNG (for tracking)
  bool timestamp = true;         // overlays on movie and stills (never on the all_frames PNGs)
  bool scale_bar = true;
  double scale_depth = 0.0;      // m along the view where the scale bar is true (0 = distance to target)
  // Lab realism, off by default (render::RenderOptions).
  bool motion_blur = false;
  double noise_sigma = 0.0;      // grey levels
  double light_gain = 1.0;
  // Lighting as fractions of a material's colour: ambient (light from all sides,
  // a sizing station's dome) and the lamp at the camera (diffuse, and the white
  // specular highlight); render::RenderOptions' defaults.
  double ambient = 0.35, diffuse = 0.65, specular = 0.20;
  // A cut-away ([cameras.cut]): what lies beyond the plane (beyond both planes, with
  // a wedge_normal) is not drawn (walls clipped per pixel, balls whose centre is
  // in the removed part dropped); none by default.
  std::optional<render::CutPlane> cut;
};

/// How a wall is drawn.
struct WallLook {
  render::Rgb colour{0.45f, 0.45f, 0.47f};
  float opacity = 1.0f;          // < 1: transparent (the Perspex wall the lab filmed through)
  bool visible = true;
  // An infinite plane is drawn as a square (side plane_size) or a disc
  // (diameter plane_size) around its point; with plane_thickness > 0 as a solid
  // slab of that thickness behind the plane (a platen seen edge-on from the side).
  double plane_size = 2.0;       // m
  bool plane_disc = false;       // plane_shape = "disc" (default "square")
  double plane_thickness = 0.0;  // m, 0 = a flat polygon
};

/// The cone crusher of a scene ([crusher], experiments.md §g): its chamber
/// (geometry/cone_crusher.h) and mantle motion (geometry/mantle_motion.h). Its
/// walls are added to the model as mesh walls named crusher.mantle,
/// crusher.mantle_cap (both gyrating about the crusher axis and spinning by Eq
/// 6-9: the spin is a WallMotion spin, velocity only), crusher.lower_concave,
/// crusher.upper_concave (static).
struct CrusherSettings {
  geometry::ConeCrusherSpec spec;
  double eccentric_rpm = 300.0;  // rpm, gyration speed (omega_ecc)
  geometry::SpinSense spin_sense = geometry::SpinSense::Opposite;
  int material = 0;              // index of the walls' material
};

struct Scene {
  std::filesystem::path source;  // file it came from ("" for text)
  std::string text;              // effective TOML (overrides applied), stored with outputs
  sim::Model model;
  std::vector<sim::SphereSpec> spheres;
  std::vector<sim::ClumpSpec> clumps;
  std::vector<ClumpShapeReport> clump_shapes;
  std::vector<sim::BondSpec> bonds;  // bonds between scene.spheres: parallel (model.bonds), contact
  std::vector<AgglomerateReport> agglomerates;
  RunSettings run;
  std::string experiment_type;  // "" (plain run) or a registered driver's type
  std::shared_ptr<const ExperimentSettings> experiment;  // its settings (null for a plain run)
  std::vector<CameraSettings> cameras;
  std::vector<WallLook> wall_looks;             // one per model wall
  std::vector<render::Rgb> material_colours;    // one per material (balls)
  std::optional<CrusherSettings> crusher;       // [crusher], when the scene has one
};

/// Parses and validates a scene. `overrides` are "key.path=value" strings
/// (from --set), applied before validation; value is TOML (1e-6, "text", [0,0,1]).
Scene loadScene(const std::filesystem::path& path, const std::vector<std::string>& overrides = {});
/// [scene] description of a scene file (its `extends` followed), without building the
/// scene: a listing need not make a bonded feed's agglomerates. Throws SceneError.
std::string sceneDescription(const std::filesystem::path& path);
Scene loadSceneText(const std::string& text, const std::string& source_name,
                    const std::vector<std::string>& overrides = {},
                    const std::filesystem::path& base_dir = {});

/// Reads the [[cameras]] tables of a camera file (the same keys as in a scene).
std::vector<CameraSettings> loadCameras(const std::filesystem::path& path);
/// The --set assignment that gives a scene the [[cameras]] of a camera file in place of
/// its own ("cameras=[{...}]"): how `--camera FILE` films a run of any scene or
/// checkpoint. The file is checked as loadCameras checks it (SceneError naming it).
std::string cameraFileOverride(const std::filesystem::path& path);

/// Directory of the built-in scenes, and the resolution of a bare name ("pour")
/// to a file in it.
std::filesystem::path builtinSceneDir();
std::filesystem::path resolveScene(const std::string& name_or_path);

}  // namespace rocklab::experiments
