#pragma once
// HDF5 helpers shared by the run file and the checkpoint writer/reader: how an
// array element type is stored, and writing datasets and attributes with the
// "unit" convention. Internal to rocklab_sim.
#include <H5Cpp.h>

#include <array>
#include <cstdint>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include "rocklab/sim/particles.h"  // sim::Vec3, sim::Quat

namespace rocklab::sim::output::detail {

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

/// Writes `values` as a dataset of shape [n] or [n,3] with a "unit" attribute.
template <class T>
void writeArray(const H5::Group& group, const char* name, std::span<const T> values,
                const char* unit) {
  const std::array<hsize_t, 2> dims{values.size(), Layout<T>::columns};
  const H5::DataSpace space(Layout<T>::columns == 0 ? 1 : 2, dims.data());
  const H5::DataSet dataset = group.createDataSet(name, Layout<T>::type(), space);
  if (!values.empty()) dataset.write(values.data(), Layout<T>::type());  // no buffer when n = 0
  writeTextAttribute(dataset, "unit", unit);
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
  return values;
}

/// Writes `text` as a scalar string dataset with an empty "unit" attribute.
inline void writeText(const H5::Group& group, const char* name, const std::string& text) {
  const H5::StrType type = textType();
  const H5::DataSet dataset = group.createDataSet(name, type, H5::DataSpace(H5S_SCALAR));
  dataset.write(text, type);
  writeTextAttribute(dataset, "unit", "");
}

}  // namespace rocklab::sim::output::detail
