#pragma once
// `rocklab agglomerate`: a library of bonded agglomerates (agglomerate_library.h)
// made by one method (agglomerate_methods.h), N of them with seeds seed, seed+1, ...;
// writes LIB.h5, LIB.json (the structure of each) and LIB.png (the first one).
#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <string>

namespace rocklab::experiments {

struct AgglomerateOptions {
  std::string method = "dense";          // dense | hcp | mesh
  double diameter = 0.05;                // m  (dense, hcp)
  double r_max = 0.0025;                 // m  loose-pack (dense) or HCP sphere radius
  double r0 = 4.0;                       // -  r_max / r_min (Eq 5-11), dense and mesh
  double angle_deg = 0.0;                // hcp rotation about z, [0, 90]
  std::string mesh;                      // mesh method: STL/PLY/OBJ
  double size = 0.0;                     // m  mesh size (0 = as in the file)
  std::string size_kind = "equivalent";  // equivalent | sieve
  std::string unit = "m";                // unit of the mesh file: m | mm
  int fill_holes = 0;                    // mesh method: close holes of up to this many edges (0 = none)
  int count = 1;                         // agglomerates
  std::uint64_t seed = 1;
  double gap_tolerance = 1e-3;  // -  bond gap, of the smaller radius
  std::string pack = "servo";   // servo | geometric
  double pressure = 1e5;        // Pa  servo target
  bool preview = true;
  std::filesystem::path out;  // LIB.h5
};

/// Runs the command; returns an ExitCode (0; 1 when a pack failed; 2 for bad input,
/// with one message on `log` naming the option, the value and what is allowed).
int runAgglomerate(const AgglomerateOptions& options, std::ostream& log);

}  // namespace rocklab::experiments
