#pragma once
// The scene reader's table groups, one file each, private to the library:
// scene.cpp (the top-level reader, `extends`, --set), scene_output.cpp
// ([scene], [output]), scene_materials.cpp ([materials.NAME], [contact]),
// scene_engine.cpp
// ([gravity], [timestep], [neighbours], [watchdog], [relaxation]),
// scene_walls.cpp ([[walls]]), scene_crusher.cpp ([crusher]), scene_particles.cpp ([[particles]]),
// scene_cameras.cpp ([[cameras]]), scene_experiment.cpp ([experiment]).
// Each reads its keys with the TableReader (file:line messages) in the order
// readScene calls them, which is the order of the messages.
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "rocklab/experiments/scene.h"
#include "rocklab/geometry/packing.h"
#include "scene/toml_reader.h"

namespace rocklab::experiments::detail {

using geometry::Vec3;

void readRunTable(TableReader& root, RunSettings& run);
/// Why `name` cannot name a folder or file of the outputs (scene.name is out/NAME
/// without --out, a camera's NAME.mp4 and frames/NAME/): "" when it can. One plain
/// name: not a path ("/x", "../x", "a/b"), not empty, no control characters.
std::string folderNameProblem(const std::string& name);
void readOutput(TableReader& root, RunSettings& run);

/// Material name -> index into model.materials.
std::map<std::string, int> readMaterials(TableReader& root, Scene& scene);
void readContact(TableReader& root, sim::Model& model);
/// An RGB colour [r, g, b] with channels in [0, 1].
render::Rgb readColour(TableReader& t, const std::string& key, render::Rgb fallback);
/// The index of the table's `material` key among `materials`.
int materialIndex(TableReader& t, const std::map<std::string, int>& materials);

void readGravity(TableReader& root, sim::Model& model);
void readEngine(TableReader& root, sim::Model& model);

void readWalls(TableReader& root, const std::map<std::string, int>& materials,
               const std::filesystem::path& base_dir, sim::Model& model,
               std::vector<WallLook>& looks);
/// [crusher]: the cone crusher's chamber and motion into scene.crusher, its
/// walls appended to the model (scene_crusher.cpp).
void readCrusher(TableReader& root, const std::map<std::string, int>& materials, Scene& scene);
/// The mantle's (and its cap's) wall motion: the gyration as the rotation about
/// the crusher axis, the spin of Eq 6-9 as WallMotion's spin (velocity only).
sim::WallMotion mantleWallMotion(const geometry::MantleMotion& m);
void readParticles(TableReader& root, const std::map<std::string, int>& materials,
                   const std::vector<sim::Material>& material_list, std::uint64_t seed,
                   const std::filesystem::path& base_dir, Scene& scene);
/// One [[particles]] source of type "agglomerate" (scene_agglomerates.cpp):
/// its balls into scene.spheres, its bonded pairs into scene.bonds (strengths
/// set by readBonds), its report into scene.agglomerates.
void readAgglomerate(TableReader& t, int material, const std::filesystem::path& base_dir, geometry::Rng& rng,
                     Scene& scene);
/// [[particles]] type = "agglomerates": `count` agglomerates of diameters uniform in
/// [diameter_min, diameter_max] at random in a box, each turned at random (§g.7's
/// bonded feed); `placed` grows by their bounding spheres.
void readAgglomerateFeed(TableReader& t, int material, geometry::Rng& rng, std::vector<geometry::Sphere>& placed,
                         Scene& scene);
/// [bonds]: the parallel-bond model and the strengths of the agglomerates' bonds
/// (constant, or Weibull per bond or per agglomerate, seeded).
void readBonds(TableReader& root, std::uint64_t seed, Scene& scene);
void readCameras(TableReader& root, std::vector<CameraSettings>& cameras);
void readExperiment(TableReader& root, Scene& scene);

}  // namespace rocklab::experiments::detail
