#pragma once
// Shared by the libFuzzer targets (tests/fuzz/README.md): a scratch folder per
// process, the input split into parts, and for the HDF5 readers a template file
// whose values (dataset elements and numeric attributes) the input patches, so
// the fuzzer tests rocklab's checks of the values rather than libhdf5's parser.
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace rocklab::fuzz {

/// A folder of this process under the temporary directory, made once.
const std::filesystem::path& scratchDir();
/// Writes `bytes` to `path` (replacing it).
void writeFile(const std::filesystem::path& path, std::string_view bytes);
std::string readFile(const std::filesystem::path& path);
/// The input split at NUL bytes (at most `max_parts`; the last part keeps the rest).
std::vector<std::string> splitInput(const std::uint8_t* data, std::size_t size, std::size_t max_parts);

/// A folder holding checkpoint.h5 and run.h5 of a tiny run (two spheres, a
/// four-ball clump, a plane and a polygon wall, a few frames) made once per
/// process with `rocklab run`: the templates the HDF5 targets patch.
const std::filesystem::path& templateRun();

/// Where the values of an HDF5 file sit: each dataset's contiguous data and
/// each numeric attribute's bytes, with the element size and kind.
struct ValueRegion {
  std::string name;        // "/particles/radius", "/@dt"
  std::size_t offset = 0;  // bytes into the file
  std::size_t size = 0;    // bytes
  std::size_t element = 1; // bytes per element
  bool floating = false;
};
std::vector<ValueRegion> valueRegions(const std::filesystem::path& file);

/// Applies the input to `file` (a copy of the template's bytes) as patches of
/// 6 bytes each: region, operation, a 32-bit position. Even operations set one
/// byte to operation/2; odd ones write an edge value (0, -1, -5, 2^31, 2e9,
/// NaN, inf, 1e300, 1e-300, a huge count) as the region's element type.
void patchValues(std::string& file, const std::vector<ValueRegion>& regions, const std::uint8_t* data,
                 std::size_t size);

/// The template file `name` of templateRun() with the input's patches applied,
/// written to the scratch folder under the same name; returns its path.
std::filesystem::path patchedTemplate(const std::string& name, const std::uint8_t* data, std::size_t size);

}  // namespace rocklab::fuzz
