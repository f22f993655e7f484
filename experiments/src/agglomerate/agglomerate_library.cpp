#include "agglomerate/agglomerate_library.h"

#include <H5Cpp.h>

#include <cmath>
#include <sstream>
#include <system_error>
#include <type_traits>

namespace rocklab::experiments {

namespace {

using Record = AgglomerateRecord;

// Every attribute of a group, by type: one table drives the writer and the reader.
struct DoubleField {
  const char* name;
  double Record::*member;
};
constexpr DoubleField kDoubleFields[] = {
    {"r_max", &Record::r_max},
    {"r0", &Record::r0},
    {"diameter", &Record::diameter},
    {"angle_deg", &Record::angle_deg},
    {"gap_tolerance", &Record::gap_tolerance},
    {"mesh_size", &Record::mesh_size},
    {"porosity", &Record::porosity},
    {"coordination_number", &Record::coordination_number},
    {"max_overlap", &Record::max_overlap},
    {"locked_in_stress_Pa", &Record::locked_in_stress_Pa},
};
struct CountField {
  const char* name;
  std::uint64_t Record::*member;
};
constexpr CountField kCountFields[] = {
    {"seed", &Record::seed},
    {"sphere_count", &Record::sphere_count},
    {"bond_count", &Record::bond_count},
};
struct TextField {
  const char* name;
  std::string Record::*member;
};
constexpr TextField kTextFields[] = {{"method", &Record::method}, {"mesh", &Record::mesh}};

constexpr const char* kUnits =
    "SI: centres and radii m (centres about the centre of mass), stresses Pa; bonds are sphere "
    "indices";

std::string inQuotes(const std::string& s) {
  return "'" + s + "'";
}

/// "" or what makes a record unusable (checked before writing and after reading).
std::string recordProblem(const Record& r) {
  const std::size_t n = r.spheres.size();
  if (r.sphere_count != n)
    return "attribute 'sphere_count' is " + std::to_string(r.sphere_count) + " but there are " +
           std::to_string(n) + " spheres";
  if (r.bond_count != r.bonds.size())
    return "attribute 'bond_count' is " + std::to_string(r.bond_count) + " but there are " +
           std::to_string(r.bonds.size()) + " bonds";
  for (std::size_t i = 0; i < n; ++i) {
    const geometry::Sphere& s = r.spheres[i];
    if (!(s.radius > 0) || !std::isfinite(s.radius)) {
      std::ostringstream m;
      m << "dataset 'radii': sphere " << i << " has radius " << s.radius << " (must be > 0 m)";
      return m.str();
    }
    if (!s.centre.allFinite())
      return "dataset 'centres': sphere " + std::to_string(i) + " is not finite";
  }
  for (std::size_t k = 0; k < r.bonds.size(); ++k) {
    const auto [a, b] = r.bonds[k];
    if (a >= n || b >= n)
      return "dataset 'bonds': row " + std::to_string(k) + " (" + std::to_string(a) + ", " +
             std::to_string(b) + ") refers to a sphere beyond the " + std::to_string(n) +
             " spheres";
    if (a >= b)
      return "dataset 'bonds': row " + std::to_string(k) + " (" + std::to_string(a) + ", " +
             std::to_string(b) + ") must have first < second";
  }
  return "";
}

// ---------------------------------------------------------------- writing

H5::StrType textType() {
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  return type;
}

void writeText(const H5::H5Object& object, const char* name, const std::string& value) {
  const H5::StrType type = textType();
  object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, value);
}

template <class T>
void writeScalar(const H5::H5Object& object, const char* name, const H5::PredType& type, T value) {
  object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, &value);
}

/// A [rows, columns] dataset (rank 1 when columns == 0) from contiguous values.
void writeTable(const H5::Group& group, const char* name, const H5::PredType& type,
                const void* data, hsize_t rows, hsize_t columns) {
  const hsize_t dims[2] = {rows, columns};
  const H5::DataSpace space(columns == 0 ? 1 : 2, dims);
  const H5::DataSet dataset = group.createDataSet(name, type, space);
  if (rows > 0) dataset.write(data, type);  // no buffer for an empty table
}

void writeGroup(H5::H5File& file, const Record& r, const std::string& name) {
  const H5::Group g = file.createGroup(name);
  const std::size_t n = r.spheres.size();
  std::vector<double> centres(3 * n), radii(n);
  for (std::size_t i = 0; i < n; ++i) {
    for (int a = 0; a < 3; ++a) centres[3 * i + a] = r.spheres[i].centre[a];
    radii[i] = r.spheres[i].radius;
  }
  writeTable(g, "centres", H5::PredType::NATIVE_DOUBLE, centres.data(), n, 3);
  writeTable(g, "radii", H5::PredType::NATIVE_DOUBLE, radii.data(), n, 0);
  static_assert(sizeof(std::array<std::uint32_t, 2>) == 2 * sizeof(std::uint32_t));
  writeTable(g, "bonds", H5::PredType::NATIVE_UINT32, r.bonds.data(), r.bonds.size(), 2);
  for (const TextField& f : kTextFields) writeText(g, f.name, r.*f.member);
  for (const DoubleField& f : kDoubleFields)
    writeScalar(g, f.name, H5::PredType::NATIVE_DOUBLE, r.*f.member);
  for (const CountField& f : kCountFields)
    writeScalar(g, f.name, H5::PredType::NATIVE_UINT64, r.*f.member);
}

// ---------------------------------------------------------------- reading

/// Reads one library file; every complaint names the file (and the group).
class Reader {
 public:
  explicit Reader(const std::filesystem::path& path)
      : path_(path.string()), file_(path_, H5F_ACC_RDONLY) {}

  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw AgglomerateLibraryError("agglomerate library " + inQuotes(path_) + ": " +
                                  (where.empty() ? "" : where + ": ") + what);
  }

  std::uint64_t checkFormat() const {
    if (!file_.attrExists("format"))
      fail("", std::string("not an agglomerate library (no 'format' attribute; expected '") +
                   kAgglomerateLibraryFormat + "')");
    const std::string format = text(file_, "", "format");
    if (format != kAgglomerateLibraryFormat)
      fail("", "not an agglomerate library (format is '" + format + "', expected '" +
                   kAgglomerateLibraryFormat + "')");
    const auto version = scalar<std::int64_t>(file_, "", "version", H5::PredType::NATIVE_INT64);
    if (version != kAgglomerateLibraryVersion)
      fail("", "unsupported version " + std::to_string(version) + " (this build reads " +
                   std::to_string(kAgglomerateLibraryVersion) + ")");
    return scalar<std::uint64_t>(file_, "", "count", H5::PredType::NATIVE_UINT64);
  }

  Record group(std::size_t index) const {
    Record r;
    r.name = agglomerateGroupName(index);
    const std::string where = "group " + inQuotes(r.name);
    if (!file_.nameExists(r.name))
      fail("", "group " + inQuotes(r.name) + " is missing (the file says it holds " +
                   std::to_string(count_) + " agglomerates)");
    const H5::Group g = file_.openGroup(r.name);
    for (const TextField& f : kTextFields) r.*f.member = text(g, where, f.name);
    for (const DoubleField& f : kDoubleFields)
      r.*f.member = scalar<double>(g, where, f.name, H5::PredType::NATIVE_DOUBLE);
    for (const CountField& f : kCountFields)
      r.*f.member = scalar<std::uint64_t>(g, where, f.name, H5::PredType::NATIVE_UINT64);

    const std::vector<double> centres = table<double>(g, where, "centres", 3, H5T_FLOAT);
    const std::vector<double> radii = table<double>(g, where, "radii", 0, H5T_FLOAT);
    const std::vector<std::uint32_t> bonds =
        table<std::uint32_t>(g, where, "bonds", 2, H5T_INTEGER);
    if (centres.size() != 3 * radii.size())
      fail(where, "dataset 'centres' has " + std::to_string(centres.size() / 3) +
                      " rows but 'radii' has " + std::to_string(radii.size()));
    for (std::size_t i = 0; i < radii.size(); ++i)
      r.spheres.push_back(
          {geometry::Vec3(centres[3 * i], centres[3 * i + 1], centres[3 * i + 2]), radii[i]});
    for (std::size_t k = 0; k < bonds.size() / 2; ++k)
      r.bonds.push_back({bonds[2 * k], bonds[2 * k + 1]});
    if (const std::string problem = recordProblem(r); !problem.empty()) fail(where, problem);
    return r;
  }

  void setCount(std::uint64_t count) { count_ = count; }

 private:
  static hssize_t points(const H5::DataSpace& space) { return space.getSimpleExtentNpoints(); }

  const H5::Attribute attribute(const H5::H5Object& object, const std::string& where,
                                const char* name) const {
    if (!object.attrExists(name)) fail(where, std::string("missing attribute '") + name + "'");
    const H5::Attribute a = object.openAttribute(name);
    if (points(a.getSpace()) != 1)  // a scalar is read into one value
      fail(where, std::string("attribute '") + name + "' is not a single value");
    return a;
  }

  std::string text(const H5::H5Object& object, const std::string& where, const char* name) const {
    const H5::Attribute a = attribute(object, where, name);
    if (a.getTypeClass() != H5T_STRING)
      fail(where, std::string("attribute '") + name + "' is not a string");
    std::string value;
    a.read(a.getStrType(), value);
    return value;
  }

  template <class T>
  T scalar(const H5::H5Object& object, const std::string& where, const char* name,
           const H5::PredType& type) const {
    const H5::Attribute a = attribute(object, where, name);
    const H5T_class_t cls = a.getTypeClass();
    const bool wanted_float = type == H5::PredType::NATIVE_DOUBLE;
    if (cls != (wanted_float ? H5T_FLOAT : H5T_INTEGER))
      fail(where, std::string("attribute '") + name + "' is not " +
                      (wanted_float ? "a number" : "an integer"));
    T value{};
    a.read(type, &value);
    return value;
  }

  /// A [n, columns] table (rank 1 when columns == 0) of `cls` numbers, flattened.
  template <class T>
  std::vector<T> table(const H5::Group& g, const std::string& where, const char* name,
                       hsize_t columns, H5T_class_t cls) const {
    const std::string what = std::string("dataset '") + name + "'";
    if (!g.nameExists(name)) fail(where, what + " is missing");
    const H5::DataSet d = g.openDataSet(name);
    if (d.getTypeClass() != cls)
      fail(where,
           what + " holds " + (cls == H5T_FLOAT ? "no floating-point numbers" : "no integers"));
    const H5::DataSpace space = d.getSpace();
    const int rank = space.getSimpleExtentNdims();
    hsize_t dims[2] = {0, 0};
    if (rank >= 1 && rank <= 2) space.getSimpleExtentDims(dims);
    const bool shape_ok = columns == 0 ? rank == 1 : (rank == 2 && dims[1] == columns);
    if (!shape_ok) {
      std::ostringstream m;
      m << what << " has the wrong shape (rank " << rank;
      if (rank == 2) m << ", " << dims[0] << " x " << dims[1];
      m << "; expected "
        << (columns == 0 ? std::string("[n]") : "[n," + std::to_string(columns) + "]") << ")";
      fail(where, m.str());
    }
    std::vector<T> values(dims[0] * (columns == 0 ? 1 : columns));
    const H5::PredType& type =
        std::is_same_v<T, double> ? H5::PredType::NATIVE_DOUBLE : H5::PredType::NATIVE_UINT32;
    if (!values.empty()) d.read(values.data(), type);
    return values;
  }

  std::string path_;
  H5::H5File file_;
  std::uint64_t count_ = 0;
};

}  // namespace

std::string agglomerateGroupName(std::size_t index) {
  const std::string digits = std::to_string(index);
  return "agglomerate_" + std::string(digits.size() < 4 ? 4 - digits.size() : 0, '0') + digits;
}

void writeAgglomerateLibrary(const std::filesystem::path& path,
                             const std::vector<AgglomerateRecord>& agglomerates) {
  H5::Exception::dontPrint();  // errors reach the caller as exceptions instead
  for (std::size_t k = 0; k < agglomerates.size(); ++k)
    if (const std::string problem = recordProblem(agglomerates[k]); !problem.empty())
      throw AgglomerateLibraryError("agglomerate library " + inQuotes(path.string()) + ": group " +
                                    inQuotes(agglomerateGroupName(k)) + ": " + problem);
  // Beside the target, renamed over it: a library is replaced in one step.
  std::filesystem::path temporary = path;
  temporary += ".tmp";
  std::error_code error;
  if (path.has_parent_path()) std::filesystem::create_directories(path.parent_path(), error);
  try {
    H5::H5File file(temporary.string(), H5F_ACC_TRUNC);
    writeText(file, "format", kAgglomerateLibraryFormat);
    writeScalar(file, "version", H5::PredType::NATIVE_INT32, kAgglomerateLibraryVersion);
    writeScalar(file, "count", H5::PredType::NATIVE_UINT64,
                static_cast<std::uint64_t>(agglomerates.size()));
    writeText(file, "units", kUnits);
    for (std::size_t k = 0; k < agglomerates.size(); ++k)
      writeGroup(file, agglomerates[k], agglomerateGroupName(k));
  } catch (const H5::Exception& e) {
    std::filesystem::remove(temporary, error);
    throw std::runtime_error("cannot write agglomerate library " + inQuotes(path.string()) +
                             ": HDF5 error in " + e.getFuncName() + ": " + e.getDetailMsg());
  }
  std::filesystem::rename(temporary, path, error);
  if (error) {
    std::filesystem::remove(temporary, error);
    throw std::runtime_error("cannot write agglomerate library " + inQuotes(path.string()) +
                             ": rename failed: " + error.message());
  }
}

std::vector<AgglomerateRecord> readAgglomerateLibrary(const std::filesystem::path& path) {
  H5::Exception::dontPrint();
  const auto fail = [&](const std::string& what) {
    return AgglomerateLibraryError("agglomerate library " + inQuotes(path.string()) + ": " + what);
  };
  std::error_code error;
  if (!std::filesystem::exists(path, error)) throw fail("file does not exist");
  if (!std::filesystem::is_regular_file(path, error)) throw fail("not a regular file");
  try {
    if (!H5::H5File::isHdf5(path.string()))
      throw fail("not an agglomerate library (not an HDF5 file)");
    Reader reader(path);
    const std::uint64_t count = reader.checkFormat();
    reader.setCount(count);
    std::vector<AgglomerateRecord> out;
    for (std::uint64_t k = 0; k < count; ++k) out.push_back(reader.group(k));
    return out;
  } catch (const H5::Exception& e) {
    throw fail("HDF5 error in " + e.getFuncName() + ": " + e.getDetailMsg());
  }
}

}  // namespace rocklab::experiments
