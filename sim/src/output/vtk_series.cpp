#include "rocklab/sim/output/vtk_series.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkIntArray.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkTypeUInt64Array.h>
#include <vtkErrorCode.h>
#include <vtkXMLPolyDataWriter.h>

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <functional>
#include <span>
#include <sstream>
#include <stdexcept>
#include <string_view>
#include <system_error>
#include <utility>

#include "rocklab/sim/output/file_write.h"
#include "rocklab/sim/particles.h"  // sim::Vec3
#include "rocklab/sim/wall_motion.h"
#include "snapshot_check.h"

namespace rocklab::sim::output {
namespace {

using detail::particleCount;

vtkSmartPointer<vtkDoubleArray> vectorArray(const char* name, std::span<const Vec3> values) {
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(name);
  array->SetNumberOfComponents(3);
  array->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
  for (std::size_t k = 0; k < values.size(); ++k) {
    array->SetTypedTuple(static_cast<vtkIdType>(k), values[k].data());
  }
  return array;
}

vtkSmartPointer<vtkDoubleArray> scalarArray(const char* name, std::span<const double> values) {
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName(name);
  array->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
  for (std::size_t k = 0; k < values.size(); ++k) {
    array->SetValue(static_cast<vtkIdType>(k), values[k]);
  }
  return array;
}

vtkSmartPointer<vtkTypeUInt64Array> idArray(std::span<const std::uint64_t> values) {
  auto array = vtkSmartPointer<vtkTypeUInt64Array>::New();
  array->SetName("id");
  array->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
  for (std::size_t k = 0; k < values.size(); ++k) {
    array->SetValue(static_cast<vtkIdType>(k), values[k]);
  }
  return array;
}

/// The balls as points (one vertex cell each, so ParaView renders them) with
/// their fields as point data; radius is the active scalar for glyph scaling.
vtkSmartPointer<vtkPolyData> makePolyData(const Snapshot& snapshot) {
  const auto n = static_cast<vtkIdType>(particleCount(snapshot));
  vtkNew<vtkPoints> points;
  points->SetData(vectorArray("position", snapshot.position));  // m, kept in double

  vtkNew<vtkCellArray> vertices;
  vertices->AllocateExact(n, n);
  for (vtkIdType k = 0; k < n; ++k) vertices->InsertNextCell(1, &k);

  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetVerts(vertices);
  vtkPointData* data = poly->GetPointData();
  data->SetScalars(scalarArray("radius", snapshot.radius));    // m
  data->AddArray(vectorArray("velocity", snapshot.velocity));  // m/s
  data->AddArray(vectorArray("omega", snapshot.omega));        // rad/s
  data->AddArray(vectorArray("force", snapshot.force));        // N
  data->AddArray(idArray(snapshot.id));
  return poly;
}

/// The walls with an extent (meshes, polygons as a fan) active at `time`, each
/// vertex where the wall's motion puts it then.
vtkSmartPointer<vtkPolyData> makeWallPolyData(const Model& model, double time) {
  std::vector<Vec3> positions, velocities;
  vtkNew<vtkCellArray> triangles;
  auto wall_index = vtkSmartPointer<vtkIntArray>::New();
  wall_index->SetName("wall");
  for (std::size_t k = 0; k < model.walls.size(); ++k) {
    const Wall& w = model.walls[k];
    if (w.shape == WallShape::Plane || !w.activeAt(time)) continue;
    const WallPose pose = wallPoseAt(w.motion, time);
    const auto first = static_cast<vtkIdType>(positions.size());
    const std::vector<Vec3>& rest = w.shape == WallShape::Mesh ? w.mesh.vertices : w.vertices;
    for (const Vec3& v : rest) {
      positions.push_back(pose.place(v));
      velocities.push_back(w.motion.isStatic() ? Vec3::Zero() : pose.velocityAt(positions.back()));
    }
    auto add = [&](vtkIdType a, vtkIdType b, vtkIdType c) {
      const vtkIdType ids[3] = {first + a, first + b, first + c};
      triangles->InsertNextCell(3, ids);
      wall_index->InsertNextValue(static_cast<int>(k));
    };
    if (w.shape == WallShape::Mesh) {
      for (const auto& t : w.mesh.triangles) add(t[0], t[1], t[2]);
    } else {
      for (std::size_t j = 1; j + 1 < rest.size(); ++j)
        add(0, static_cast<vtkIdType>(j), static_cast<vtkIdType>(j + 1));  // convex: a fan
    }
  }
  vtkNew<vtkPoints> points;
  points->SetData(vectorArray("position", positions));
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(points);
  poly->SetPolys(triangles);
  poly->GetCellData()->SetScalars(wall_index);
  poly->GetPointData()->AddArray(vectorArray("velocity", velocities));  // m/s
  return poly;
}

void writePolyData(vtkPolyData* poly, const std::filesystem::path& file) {
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetFileName(file.c_str());
  writer->SetInputData(poly);
  // Raw appended binary with zlib: compact and quick to load; base64 would
  // only matter for files that must stay valid text.
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();
  writer->SetCompressorTypeToZLib();
  if (writer->Write() != 1) {
    const unsigned long code = writer->GetErrorCode();
    const std::string reason = code == vtkErrorCode::OutOfDiskSpaceError
                                   ? systemReason(ENOSPC)
                                   : "the VTK writer failed (vtkErrorCode " + std::to_string(code) + ")";
    throw OutputError("cannot write VTK file '" + file.string() + "': " + reason);
  }
}

/// Writes `target` through `write(temporary)` and a rename, so readers (such as
/// ParaView reloading the series) never see a half-written file.
void writeAtomically(const std::filesystem::path& target,
                     const std::function<void(const std::filesystem::path&)>& write) {
  std::filesystem::path temporary = target;
  temporary += ".tmp";
  try {
    write(temporary);
    std::filesystem::rename(temporary, target);
  } catch (...) {
    std::error_code ignored;
    std::filesystem::remove(temporary, ignored);
    throw;
  }
}

/// Shortest text that reads back as the same double (times like 0.1 stay "0.1").
std::string formatTime(double seconds) {
  char buffer[32];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, seconds);
  return std::string(buffer, result.ptr);
}

std::string xmlEscaped(std::string_view text) {
  std::string escaped;
  for (const char c : text) {
    switch (c) {
      case '&':
        escaped += "&amp;";
        break;
      case '<':
        escaped += "&lt;";
        break;
      case '>':
        escaped += "&gt;";
        break;
      case '"':
        escaped += "&quot;";
        break;
      default:
        escaped += c;
    }
  }
  return escaped;
}

std::string frameFileName(const std::string& basename, std::size_t frame) {
  char number[32];
  std::snprintf(number, sizeof number, "_%06zu.vtp", frame);
  return basename + number;
}

}  // namespace

VtkSeries::VtkSeries(std::filesystem::path directory, std::string basename)
    : directory_(std::move(directory)), basename_(std::move(basename)) {
  std::filesystem::create_directories(directory_);
}

void VtkSeries::addFrame(double time, const std::function<void(const std::filesystem::path&)>& write) {
  const std::string name = frameFileName(basename_, entries_.size());
  writeAtomically(directory_ / name, write);
  entries_.emplace_back(time, name);
  writeCollection();  // the .pvd always lists every finished frame
}

void VtkSeries::writeFrame(const Snapshot& snapshot) {
  const vtkSmartPointer<vtkPolyData> poly = makePolyData(snapshot);
  addFrame(snapshot.time, [&](const std::filesystem::path& file) { writePolyData(poly, file); });
}

void VtkSeries::writeWalls(const Model& model, double time) {
  const vtkSmartPointer<vtkPolyData> poly = makeWallPolyData(model, time);
  addFrame(time, [&](const std::filesystem::path& file) { writePolyData(poly, file); });
}

void VtkSeries::writeCollection() const {
  std::ostringstream xml;
  xml << "<?xml version=\"1.0\"?>\n"
      << "<VTKFile type=\"Collection\" version=\"0.1\">\n"
      << "  <Collection>\n";
  for (const auto& [time, name] : entries_) {
    // File names are relative: the .pvd sits in the same directory as the frames.
    xml << "    <DataSet timestep=\"" << formatTime(time) << "\" group=\"\" part=\"0\" file=\""
        << xmlEscaped(name) << "\"/>\n";
  }
  xml << "  </Collection>\n"
      << "</VTKFile>\n";
  writeFileAtomically(directory_ / (basename_ + ".pvd"), xml.str());
}

}  // namespace rocklab::sim::output
