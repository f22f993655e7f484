#pragma once
// Agglomerate library files (LIB.h5), written once by `rocklab agglomerate` and read
// by scenes (and the crushing test): bonded sphere assemblies with their structure.
//
// Layout (HDF5): root attributes format = "rocklab-agglomerates" (string), version
// (int), count (uint64), units (string); groups agglomerate_0000, agglomerate_0001, ...
// (count of them), each with
//   datasets  centres [n,3] double, m, about the agglomerate's centre of mass
//             radii   [n]   double, m
//             bonds   [m,2] uint32, sphere indices (first < second)
//   attributes method, mesh (strings); r_max (m), r0 (-), diameter (m), angle_deg,
//             gap_tolerance (- of the smaller radius), mesh_size (m), porosity (-),
//             coordination_number (-), max_overlap (m), locked_in_stress_Pa (Pa,
//             mean normal, compression > 0) as doubles; seed, sphere_count,
//             bond_count as uint64.
// Doubles are stored as IEEE doubles: a read gives back the bits written. Written to
// "<path>.tmp" and renamed over the path, so a crash never leaves half a library.
#include <array>
#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "rocklab/geometry/packing.h"

namespace rocklab::experiments {

inline constexpr const char* kAgglomerateLibraryFormat = "rocklab-agglomerates";
inline constexpr int kAgglomerateLibraryVersion = 1;

/// One agglomerate of a library.
struct AgglomerateRecord {
  std::string name;                // group name (agglomerateGroupName); set by the reader
  std::string method;              // "dense" | "hcp" | "mesh"
  std::string mesh;                // mesh file of the mesh method, else ""
  double r_max = 0;                // m
  double r0 = 0;                   // -  r_max / r_min (Eq 5-11); 1 for hcp
  double diameter = 0;             // m  of the spherical agglomerate (mesh: the one carved)
  double angle_deg = 0;            // hcp rotation about z
  double gap_tolerance = 0;        // -  bond gap, of the smaller radius
  double mesh_size = 0;            // m  the mesh's size (mesh method)
  double porosity = 0;             // -
  double coordination_number = 0;  // -  2 bonds / spheres
  double max_overlap = 0;          // m  largest initial overlap
  double locked_in_stress_Pa = 0;  // Pa
  std::uint64_t seed = 0;
  std::uint64_t sphere_count = 0;                   // = spheres.size()
  std::uint64_t bond_count = 0;                     // = bonds.size()
  std::vector<geometry::Sphere> spheres;            // centre about the centre of mass, m
  std::vector<std::array<std::uint32_t, 2>> bonds;  // sphere indices, first < second
};

/// A library file that cannot be read: the message names the file, the group and
/// the dataset or attribute, and what is wrong. Bad input (exit code 2 in the CLI).
struct AgglomerateLibraryError : std::invalid_argument {
  using std::invalid_argument::invalid_argument;
};

/// Group name of the agglomerate at `index`: agglomerate_0000, agglomerate_0001, ...
std::string agglomerateGroupName(std::size_t index);

/// Writes `agglomerates` in order, as agglomerateGroupName(index) (their `name` is not used).
/// Throws std::runtime_error naming the file when it cannot be written, and AgglomerateLibraryError
/// for a record that would not read back (counts that disagree with the arrays, a bond out of
/// range, a radius <= 0).
void writeAgglomerateLibrary(const std::filesystem::path& path,
                             const std::vector<AgglomerateRecord>& agglomerates);

/// Reads and checks every agglomerate of a library. Throws AgglomerateLibraryError.
std::vector<AgglomerateRecord> readAgglomerateLibrary(const std::filesystem::path& path);

}  // namespace rocklab::experiments
