#pragma once
// `rocklab shape`: a scanned (or generated) particle mesh → a checked, measured mesh and
// a clump of overlapping spheres with its error against the mesh; optionally the
// error-against-cost table over sphere counts. See docs/shape.md.
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>
#include <vector>

namespace rocklab::experiments {

struct ShapeOptions {
  std::string mesh;                  // input mesh (STL/PLY/OBJ); with `generate`, the mesh file to write
  std::string method = "surface";    // "surface" (tangent spheres grown from the surface) | "medial" (medial axis)
  int spheres = 20;                  // largest sphere count
  double tolerance = 0.0;            // stop early when the uncovered volume fraction is <= this (0 = off)
  std::string unit = "m";            // unit of the file's coordinates: "m" | "mm"
  int fill_holes = 0;                // close holes of up to this many edges (0 = none: an open mesh is an error)
  double size = 0.0;                 // m, target size (0 = as in the file)
  std::string size_kind = "equivalent";  // "equivalent" (diameter of the equal-volume sphere) | "sieve"
  double density = 2730.0;           // kg/m^3 (the study's pebbles)
  double min_radius = 0.05;          // smallest member radius, fraction of the equivalent diameter
  double touch = 0.005;              // surface method: node tolerance, fraction of the equivalent diameter
  int grid = 48;                     // inside grid cells along the longest extent
  std::string generate;              // "" | "pebble" | "crushed" | "flake": make the mesh first (seeded)
  std::uint64_t seed = 1;
  std::vector<int> sweep;            // sphere counts for the error table (both methods); empty = none
  bool pile = false;                 // with sweep: time a settling pile of clumps per count
  int pile_clumps = 200;
  double pile_time = 0.4;            // s simulated
  bool preview = true;
  std::filesystem::path out_dir;     // required
};

/// Runs the command; returns an ExitCode: 0; 2 with one message on `log` for bad input;
/// 1 when the clump is written but misses the asked --tolerance, or stops below
/// --spheres without covering the inside (results.json status "target_not_met",
/// its stop_reason and uncovered_volume_fraction).
int runShape(const ShapeOptions& options, std::ostream& log);

}  // namespace rocklab::experiments
