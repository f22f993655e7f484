#include "fuzz_support.h"

#include <hdf5.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <algorithm>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "rocklab/experiments/cli.h"

namespace rocklab::fuzz {

namespace {
constexpr const char* kTemplateScene = R"(
[scene]
name = "fuzz-template"
seed = 1
end_time = 0.002

[materials.rock]
density = 2650
kn = 1e5
friction = 0.5

[[walls]]
type = "plane"
name = "floor"
material = "rock"
point = [0.0, 0.0, 0.0]
normal = [0.0, 0.0, 1.0]

[[walls]]
type = "polygon"
name = "ramp"
material = "rock"
vertices = [[0.1, 0.0, 0.0], [0.2, 0.0, 0.0], [0.2, 0.1, 0.05]]

[[particles]]
type = "list"
material = "rock"
positions = [[0.0, 0.0, 0.0105], [0.03, 0.0, 0.012]]
radius = 0.01

[[particles]]
type = "list"
shape = "four_ball"
member_radius = 0.005
material = "rock"
positions = [[0.0, 0.05, 0.02]]

[output]
frame_interval = 0.0005
)";
}  // namespace

const std::filesystem::path& templateRun() {
  static const std::filesystem::path dir = [] {
    const auto d = scratchDir() / "template";
    std::filesystem::create_directories(d);
    writeFile(d / "scene.toml", kTemplateScene);
    const std::string scene = (d / "scene.toml").string(), out = (d / "run").string();
    const char* argv[] = {"rocklab", "run", scene.c_str(), "--out", out.c_str(), "--threads", "1", "--quiet"};
    if (experiments::runCli(8, argv) != 0) throw std::runtime_error("fuzz: the template run failed");
    return d / "run";
  }();
  return dir;
}

const std::filesystem::path& scratchDir() {
  static const std::filesystem::path dir = [] {
    const auto d = std::filesystem::temp_directory_path() / ("rocklab-fuzz-" + std::to_string(getpid()));
    std::filesystem::create_directories(d);
    return d;
  }();
  return dir;
}

void writeFile(const std::filesystem::path& path, std::string_view bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::vector<std::string> splitInput(const std::uint8_t* data, std::size_t size, std::size_t max_parts) {
  std::vector<std::string> parts(1);
  for (std::size_t k = 0; k < size; ++k) {
    if (data[k] == 0 && parts.size() < max_parts) parts.emplace_back();
    else parts.back() += static_cast<char>(data[k]);
  }
  return parts;
}

namespace {

struct Visit {
  std::vector<ValueRegion>* regions;
  const std::string* bytes;
};

/// The bytes of `value` found once in the file: where an attribute is stored.
void addIfUnique(const std::string& file, const std::string& name, const std::vector<char>& value, std::size_t element,
                 bool floating, std::vector<ValueRegion>& out) {
  if (value.empty()) return;
  const std::string needle(value.begin(), value.end());
  const std::size_t first = file.find(needle);
  if (first == std::string::npos || file.find(needle, first + 1) != std::string::npos) return;
  out.push_back({name, first, value.size(), element, floating});
}

herr_t visitAttribute(hid_t object, const char* attr_name, const H5A_info_t*, void* op) {
  auto& v = *static_cast<Visit*>(op);
  const hid_t attr = H5Aopen(object, attr_name, H5P_DEFAULT);
  const hid_t type = H5Aget_type(attr);
  const H5T_class_t kind = H5Tget_class(type);
  if (kind == H5T_INTEGER || kind == H5T_FLOAT) {
    const hid_t space = H5Aget_space(attr);
    const auto count = static_cast<std::size_t>(H5Sget_simple_extent_npoints(space));
    const std::size_t element = H5Tget_size(type);
    std::vector<char> value(count * element);
    if (!value.empty() && H5Aread(attr, type, value.data()) >= 0)
      addIfUnique(*v.bytes, std::string("@") + attr_name, value, element, kind == H5T_FLOAT, *v.regions);
    H5Sclose(space);
  }
  H5Tclose(type);
  H5Aclose(attr);
  return 0;
}

herr_t visitObject(hid_t root, const char* name, const H5O_info_t* info, void* op) {
  auto& v = *static_cast<Visit*>(op);
  const hid_t object = H5Oopen(root, name, H5P_DEFAULT);
  if (object < 0) return 0;
  H5Aiterate2(object, H5_INDEX_NAME, H5_ITER_NATIVE, nullptr, visitAttribute, op);
  if (info->type == H5O_TYPE_DATASET) {
    const hid_t type = H5Dget_type(object);
    const H5T_class_t kind = H5Tget_class(type);
    const haddr_t offset = H5Dget_offset(object);  // undefined for chunked or empty data
    if ((kind == H5T_INTEGER || kind == H5T_FLOAT) && offset != HADDR_UNDEF)
      v.regions->push_back({std::string("/") + name, static_cast<std::size_t>(offset),
                            static_cast<std::size_t>(H5Dget_storage_size(object)), H5Tget_size(type),
                            kind == H5T_FLOAT});
    H5Tclose(type);
  }
  H5Oclose(object);
  return 0;
}

}  // namespace

std::vector<ValueRegion> valueRegions(const std::filesystem::path& file) {
  const std::string bytes = readFile(file);
  std::vector<ValueRegion> regions;
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (f < 0) return regions;
  Visit v{&regions, &bytes};
  H5Ovisit(f, H5_INDEX_NAME, H5_ITER_NATIVE, visitObject, &v);
  H5Fclose(f);
  std::erase_if(regions, [&bytes](const ValueRegion& r) { return r.size == 0 || r.offset + r.size > bytes.size(); });
  return regions;
}

void patchValues(std::string& file, const std::vector<ValueRegion>& regions, const std::uint8_t* data,
                 std::size_t size) {
  if (regions.empty()) return;
  static const double kFloats[] = {0.0, -1.0, -5.0, 2147483648.0, 2e9, std::nan(""),
                                   std::numeric_limits<double>::infinity(), 1e300, 1e-300, -0.0};
  static const std::int64_t kIntegers[] = {0, -1, -5, 2147483648LL, 2000000000, 99, 1, 4294967295LL,
                                           std::numeric_limits<std::int64_t>::max(), 65536};
  // ROCKLAB_FUZZ_VERBOSE=1: each patch on stderr, to say what a finding changed.
  static const bool verbose = std::getenv("ROCKLAB_FUZZ_VERBOSE") != nullptr;
  for (std::size_t k = 0; k + 6 <= size; k += 6) {
    const ValueRegion& r = regions[data[k] % regions.size()];
    const std::uint8_t op = data[k + 1];
    std::uint32_t at = 0;
    std::memcpy(&at, data + k + 2, 4);
    if (verbose)
      std::fprintf(stderr, "patch %s (%zu bytes of %zu-byte %s): %s at %zu\n", r.name.c_str(), r.size, r.element,
                   r.floating ? "floats" : "integers",
                   op % 2 ? ("edge value " + std::to_string((op / 2) % 10)).c_str()
                          : ("byte " + std::to_string(op / 2)).c_str(),
                   static_cast<std::size_t>(op % 2 ? at % std::max<std::size_t>(1, r.size / r.element) : at % r.size));
    if (op % 2 == 0) {
      file[r.offset + at % r.size] = static_cast<char>(op / 2);
      continue;
    }
    const std::size_t elements = r.size / r.element;
    if (elements == 0) continue;
    char* where = file.data() + r.offset + (at % elements) * r.element;
    const std::size_t pick = (op / 2) % 10;
    if (r.floating && r.element == 8) {
      std::memcpy(where, &kFloats[pick], 8);
    } else if (r.floating && r.element == 4) {
      const auto f = static_cast<float>(kFloats[pick]);
      std::memcpy(where, &f, 4);
    } else if (!r.floating && r.element <= 8) {
      std::memcpy(where, &kIntegers[pick], r.element);  // little-endian: the low bytes
    }
  }
}

std::filesystem::path patchedTemplate(const std::string& name, const std::uint8_t* data, std::size_t size) {
  struct Template {
    std::string bytes;
    std::vector<ValueRegion> regions;
  };
  static std::map<std::string, Template> templates;
  auto [it, made] = templates.try_emplace(name);
  if (made) it->second = {readFile(templateRun() / name), valueRegions(templateRun() / name)};
  std::string bytes = it->second.bytes;
  patchValues(bytes, it->second.regions, data, size);
  const auto file = scratchDir() / name;
  writeFile(file, bytes);
  return file;
}

}  // namespace rocklab::fuzz
