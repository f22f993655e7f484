#pragma once
// HDF5 helpers shared by the run file and the checkpoint writer/reader: how an
// array element type is stored, and writing datasets and attributes with the
// "unit" convention and a checksum. Internal to rocklab_sim.
#include <H5Cpp.h>
#include <zlib.h>

#include <array>
#include <cstdio>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "rocklab/sim/particles.h"  // sim::Vec3, sim::Quat

namespace rocklab::sim::output::detail {

/// Instead of printing failures, HDF5 records the system's reason of each
/// (hdf5_errors.cpp); call before writing (a reader's dontPrint() turns it off).
void recordHdf5Errors();
/// What went wrong, with the system's reason first when a system call failed:
/// "no space left on device (H5File::close: H5Fclose failed)".
std::string hdf5Failure(const H5::Exception& e);
/// Files being written on disk, by their sec2 file descriptor (FileHandle): when
/// a system call of HDF5 fails (a full disk) each is diverted at once, inside the
/// failing call, to an anonymous in-memory file, so that everything HDF5 does
/// with them afterwards (the closes during unwinding, the final close) succeeds.
/// Needed because HDF5 1.10 frees an object whose close failed but keeps its id,
/// and a later close or its clean-up at exit then crashes. The diverted file's
/// contents are lost: its owner removes it.
void watchForFailure(int* fd);
void unwatch(int* fd);
/// Why a watched file was diverted ("" while it was not).
std::string diverted(int* fd);

/// An HDF5 file for writing, closed exactly once. HDF5 1.10 crashes when a file
/// whose close failed (a full disk) is closed again, as H5::H5File's destructor
/// does; this handle never retries. Closing is "strong": the objects still open
/// in the file are closed with it (their C++ wrappers then hold stale ids, which
/// they skip), so the flush, and its failure, happen in close(). Writes go
/// through root(), the file's root group (file attributes are its attributes).
class FileHandle {
 public:
  /// in_memory: HDF5's core driver builds the file in memory (image()), with no
  /// file on disk; otherwise the file at `path` is created (truncated).
  FileHandle(const std::string& path, bool in_memory) {
    const hid_t access = H5Pcreate(H5P_FILE_ACCESS);
    H5Pset_fclose_degree(access, H5F_CLOSE_STRONG);
    if (in_memory) H5Pset_fapl_core(access, 1 << 20, 0);  // 1 MiB steps, no backing file
    id_ = H5Fcreate(path.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, access);
    H5Pclose(access);
    if (id_ < 0) throw H5::FileIException("H5Fcreate", "cannot create '" + path + "'");
    root_ = H5::Group(H5Gopen2(id_, "/", H5P_DEFAULT));
    void* handle = nullptr;
    if (!in_memory && H5Fget_vfd_handle(id_, H5P_DEFAULT, &handle) >= 0 && handle != nullptr) {
      fd_ = static_cast<int*>(handle);  // the sec2 driver's handle is its file descriptor
      watchForFailure(fd_);
    }
  }
  ~FileHandle() {
    if (id_ < 0) return;
    H5Fclose(id_);  // once (after a failure the file is in memory: it succeeds)
    release();
  }
  FileHandle(const FileHandle&) = delete;
  FileHandle& operator=(const FileHandle&) = delete;

  const H5::Group& root() const { return root_; }
  void flush() const {
    if (H5Fflush(id_, H5F_SCOPE_GLOBAL) < 0) throw H5::FileIException("H5Fflush", "flush failed");
  }
  /// The bytes of an in-memory file (flushed first).
  std::string image() const {
    flush();
    const ssize_t size = H5Fget_file_image(id_, nullptr, 0);
    if (size < 0) throw H5::FileIException("H5Fget_file_image", "no file image");
    std::string bytes(static_cast<std::size_t>(size), '\0');
    if (H5Fget_file_image(id_, bytes.data(), bytes.size()) != size)
      throw H5::FileIException("H5Fget_file_image", "short file image");
    return bytes;
  }
  /// Closes the file (and whatever is open in it). The flush comes first: when
  /// it fails (a full disk) this throws and the file stays open, for abandon();
  /// a failure of the close itself throws too, and it is never tried again.
  void close() {
    if (id_ < 0) return;
    flush();
    const herr_t result = H5Fclose(id_);
    release();
    if (result < 0) throw H5::FileIException("H5Fclose", "closing the file failed");
  }
  /// Closes a file a write failed in (diverted to memory by then, see
  /// watchForFailure), for good; the caller removes it.
  void abandon() noexcept {
    if (id_ < 0) return;
    H5Fclose(id_);
    release();
  }
  /// "" or why a failure diverted this file to memory (its writes are lost).
  std::string failure() const { return fd_ != nullptr ? diverted(fd_) : std::string(); }
  bool isOpen() const { return id_ >= 0; }

 private:
  void release() {
    if (fd_ != nullptr) unwatch(fd_);
    fd_ = nullptr;
    id_ = H5I_INVALID_HID;
  }
  hid_t id_ = H5I_INVALID_HID;
  int* fd_ = nullptr;  // the driver's descriptor (files on disk), watched while open
  H5::Group root_;
};

// A Vec3 array is handed to HDF5 as [n,3] contiguous doubles.
static_assert(sizeof(Vec3) == 3 * sizeof(double));

// How a C++ array element is stored: its HDF5 type and the number of columns of
// the dataset (0 = a 1-D dataset). Memory and file use the same native types, so
// HDF5 copies the bytes unchanged and a read gives back the same bits.
template <class T>
struct Layout;
template <>
struct Layout<double> {
  static const H5::PredType& type() { return H5::PredType::NATIVE_DOUBLE; }
  static constexpr hsize_t columns = 0;
};
template <>
struct Layout<std::uint64_t> {
  static const H5::PredType& type() { return H5::PredType::NATIVE_UINT64; }
  static constexpr hsize_t columns = 0;
};
template <>
struct Layout<std::uint32_t> {
  static const H5::PredType& type() { return H5::PredType::NATIVE_UINT32; }
  static constexpr hsize_t columns = 0;
};
template <>
struct Layout<std::uint8_t> {
  static const H5::PredType& type() { return H5::PredType::NATIVE_UINT8; }
  static constexpr hsize_t columns = 0;
};
template <>
struct Layout<std::int32_t> {
  static const H5::PredType& type() { return H5::PredType::NATIVE_INT32; }
  static constexpr hsize_t columns = 0;
};
template <>
struct Layout<Vec3> {
  static const H5::PredType& type() { return H5::PredType::NATIVE_DOUBLE; }
  static constexpr hsize_t columns = 3;
};

// A quaternion is stored as [n,4] doubles in Eigen's order x, y, z, w.
static_assert(sizeof(Quat) == 4 * sizeof(double));
template <>
struct Layout<Quat> {
  static const H5::PredType& type() { return H5::PredType::NATIVE_DOUBLE; }
  static constexpr hsize_t columns = 4;
};

inline H5::StrType textType() {
  // Variable-length UTF-8: scene text of any length, with any characters.
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  return type;
}

inline void writeTextAttribute(const H5::H5Object& object, const char* name,
                               const std::string& value) {
  const H5::StrType type = textType();
  object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, value);
}

template <class T>
void writeScalarAttribute(const H5::H5Object& object, const char* name, const H5::PredType& type,
                          T value) {
  object.createAttribute(name, type, H5::DataSpace(H5S_SCALAR)).write(type, &value);
}

// Every dataset written here carries the CRC-32 of its bytes (native types: the
// bytes as stored), so a reader tells random damage from values (files written
// before it have none and are read unchecked).
constexpr const char* kChecksumAttribute = "crc32";

inline std::uint32_t checksum(const void* data, std::size_t bytes) {
  const auto start = crc32_z(0L, Z_NULL, 0);
  return static_cast<std::uint32_t>(crc32_z(start, static_cast<const Bytef*>(data), bytes));
}

inline void writeChecksum(const H5::H5Object& object, const void* data, std::size_t bytes) {
  writeScalarAttribute(object, kChecksumAttribute, H5::PredType::NATIVE_UINT32, checksum(data, bytes));
}

/// What the stored checksum of a dataset says about the values read from it.
struct ChecksumCheck {
  bool present = false;  // false: a file from before checksums (unchecked)
  bool matches = true;
  std::uint32_t stored = 0, computed = 0;
  std::string mismatch() const {
    char text[96];
    std::snprintf(text, sizeof text, "checksum mismatch (stored crc32 %08x, the data gives %08x)", stored, computed);
    return std::string(text) + ": the file is damaged";
  }
};

inline ChecksumCheck verifyChecksum(const H5::H5Object& object, const void* data, std::size_t bytes) {
  ChecksumCheck c;
  if (!object.attrExists(kChecksumAttribute)) return c;
  c.present = true;
  c.computed = checksum(data, bytes);
  const H5::Attribute stored = object.openAttribute(kChecksumAttribute);
  // Read only a scalar integer: anything else would overrun `stored` (or is damage).
  if (stored.getTypeClass() != H5T_INTEGER || stored.getSpace().getSimpleExtentNpoints() != 1) {
    c.matches = false;
    return c;
  }
  stored.read(H5::PredType::NATIVE_UINT32, &c.stored);
  c.matches = c.stored == c.computed;
  return c;
}

/// Reads a scalar attribute as `type`; throws std::runtime_error when it is not
/// one value (reading an array attribute into one T would overrun it).
template <class T>
T readScalarAttribute(const H5::H5Object& object, const char* name, const H5::PredType& type) {
  if (!object.attrExists(name)) throw std::runtime_error(std::string("missing attribute '") + name + "'");
  const H5::Attribute stored = object.openAttribute(name);
  if (stored.getSpace().getSimpleExtentNpoints() != 1)
    throw std::runtime_error(std::string("attribute '") + name + "' is not a scalar");
  T value{};
  stored.read(type, &value);
  return value;
}

/// Writes `values` as a dataset of shape [n] or [n,3] with "unit" and checksum attributes.
template <class T>
void writeArray(const H5::Group& group, const char* name, std::span<const T> values,
                const char* unit) {
  const std::array<hsize_t, 2> dims{values.size(), Layout<T>::columns};
  const H5::DataSpace space(Layout<T>::columns == 0 ? 1 : 2, dims.data());
  const H5::DataSet dataset = group.createDataSet(name, Layout<T>::type(), space);
  if (!values.empty()) dataset.write(values.data(), Layout<T>::type());  // no buffer when n = 0
  writeTextAttribute(dataset, "unit", unit);
  writeChecksum(dataset, values.data(), values.size_bytes());
}

/// The same for a vector (a span parameter cannot deduce T from one).
template <class T>
void writeArray(const H5::Group& group, const char* name, const std::vector<T>& values,
                const char* unit) {
  writeArray(group, name, std::span<const T>(values), unit);
}

/// Reads a dataset written by writeArray ([n] or [n,columns]); empty when absent.
/// Throws std::runtime_error when its shape does not fit T.
template <class T>
std::vector<T> readArray(const H5::Group& group, const char* name) {
  if (!group.nameExists(name)) return {};
  const H5::DataSet dataset = group.openDataSet(name);
  const H5::DataSpace space = dataset.getSpace();
  std::array<hsize_t, 2> dims{0, 0};
  const int rank = space.getSimpleExtentNdims();
  if (rank < 1 || rank > 2) throw std::runtime_error(std::string("dataset ") + name + " has rank " + std::to_string(rank));
  space.getSimpleExtentDims(dims.data());
  if ((rank == 1) != (Layout<T>::columns == 0) || (rank == 2 && dims[1] != Layout<T>::columns))
    throw std::runtime_error(std::string("dataset ") + name + " has the wrong shape");
  std::vector<T> values(dims[0]);
  if (!values.empty()) dataset.read(values.data(), Layout<T>::type());
  if (const ChecksumCheck c = verifyChecksum(dataset, values.data(), values.size() * sizeof(T)); !c.matches)
    throw std::runtime_error(std::string("dataset ") + name + ": " + c.mismatch());
  return values;
}

/// Writes `text` as a scalar string dataset with an empty "unit" attribute and a checksum.
inline void writeText(const H5::Group& group, const char* name, const std::string& text) {
  const H5::StrType type = textType();
  const H5::DataSet dataset = group.createDataSet(name, type, H5::DataSpace(H5S_SCALAR));
  dataset.write(text, type);
  writeTextAttribute(dataset, "unit", "");
  writeChecksum(dataset, text.data(), text.size());
}

}  // namespace rocklab::sim::output::detail
