#include "weft/viz/vtk_files.h"

#include <set>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkTypeInt32Array.h>
#include <vtkTypeInt64Array.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLPolyDataWriter.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/viz/vtk_support.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::viz {
namespace fs = std::filesystem;

namespace {

vtkNew<vtkPoints> make_points(const std::vector<std::array<double, 3>>& points, bool as_float = false) {
  vtkNew<vtkPoints> out;
  if (as_float) {
    out->SetDataTypeToFloat();
  } else {
    out->SetDataTypeToDouble();
  }
  out->SetNumberOfPoints(static_cast<vtkIdType>(points.size()));
  for (std::size_t i = 0; i < points.size(); ++i) out->SetPoint(static_cast<vtkIdType>(i), points[i].data());
  return out;
}

template <typename Array>
vtkNew<Array> index_array(const std::vector<std::uint64_t>& values) {
  vtkNew<Array> a;
  a->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
  for (std::size_t i = 0; i < values.size(); ++i)
    a->SetValue(static_cast<vtkIdType>(i), static_cast<typename Array::ValueType>(values[i]));
  return a;
}

template <typename Array>
vtkNew<Array> iota_array(std::size_t n) {
  vtkNew<Array> a;
  a->SetNumberOfValues(static_cast<vtkIdType>(n));
  for (std::size_t i = 0; i < n; ++i) a->SetValue(static_cast<vtkIdType>(i), static_cast<typename Array::ValueType>(i));
  return a;
}

// Every array must match its entity count and carry a unique, non-empty name: VTK finds
// arrays by name, so a clash would silently hide one of them in ParaView.
template <typename T>
void check_arrays(const std::map<std::string, std::vector<T>>& arrays, std::size_t count, const char* entity,
                  std::set<std::string>& names, const fs::path& path) {
  for (const auto& [name, values] : arrays) {
    if (name.empty()) fail("{}: a {} data array has an empty name", path.string(), entity);
    if (!names.insert(name).second) fail("{}: two {} data arrays are named '{}'", path.string(), entity, name);
    if (values.size() != count) {
      fail("{}: {} data array '{}' has {} values for {} {}s", path.string(), entity, name, values.size(), count,
           entity);
    }
  }
}

void add_doubles(vtkFieldData& data, const std::map<std::string, std::vector<double>>& arrays) {
  for (const auto& [name, values] : arrays) {
    vtkNew<vtkDoubleArray> a;
    a->SetName(name.c_str());
    a->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), values[i]);
    data.AddArray(a);
  }
}

void add_ints(vtkFieldData& data, const std::map<std::string, std::vector<std::int32_t>>& arrays) {
  for (const auto& [name, values] : arrays) {
    vtkNew<vtkIntArray> a;
    a->SetName(name.c_str());
    a->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i) a->SetValue(static_cast<vtkIdType>(i), values[i]);
    data.AddArray(a);
  }
}

// Binary, zlib-compressed appended data: compact and what ParaView reads fastest.
template <typename Writer>
void configure(Writer& writer) {
  writer.SetDataModeToAppended();
  writer.EncodeAppendedDataOff();
  writer.SetCompressorTypeToZLib();
}

template <typename Writer>
void write_with(Writer& writer, const fs::path& tmp, const fs::path& target) {
  configure(writer);
  writer.SetFileName(tmp.c_str());
  (void)detail::take_vtk_message();
  if (writer.Write() != 1 || writer.GetErrorCode() != 0) {
    const std::string detail = detail::take_vtk_message();
    fail("{}: cannot write VTK file{}{}", target.string(), detail.empty() ? "" : ": ", detail);
  }
}

}  // namespace

void write_vtp(const PolylineSet& lines, const fs::path& path) {
  detail::quiet_vtk_messages();
  const auto& off = lines.offsets;
  if (off.empty() || off.front() != 0) fail("{}: polyline offsets must start with 0", path.string());
  for (std::size_t i = 1; i < off.size(); ++i) {
    if (off[i] < off[i - 1]) fail("{}: polyline offsets decrease at polyline {}", path.string(), i - 1);
  }
  if (off.back() != lines.points.size()) {
    fail("{}: polyline offsets end at {} but there are {} points", path.string(), off.back(), lines.points.size());
  }
  const std::size_t n_lines = off.size() - 1;
  std::set<std::string> cell_names;
  std::set<std::string> point_names;
  check_arrays(lines.cell_ints, n_lines, "polyline", cell_names, path);
  check_arrays(lines.cell_scalars, n_lines, "polyline", cell_names, path);
  check_arrays(lines.point_scalars, lines.points.size(), "point", point_names, path);

  vtkNew<vtkPolyData> poly;
  poly->SetPoints(make_points(lines.points, lines.float_points));
  // 32-bit cell indices when they fit: half the bytes of the connectivity array, which is as
  // long as the points (VTK reads either width).
  vtkNew<vtkCellArray> cells;
  if (lines.points.size() < (1ULL << 31U)) {
    cells->SetData(index_array<vtkTypeInt32Array>(off), iota_array<vtkTypeInt32Array>(lines.points.size()));
  } else {
    cells->SetData(index_array<vtkTypeInt64Array>(off), iota_array<vtkTypeInt64Array>(lines.points.size()));
  }
  poly->SetLines(cells);
  add_ints(*poly->GetCellData(), lines.cell_ints);
  add_doubles(*poly->GetCellData(), lines.cell_scalars);
  add_doubles(*poly->GetPointData(), lines.point_scalars);

  write_atomically(path, [&](const fs::path& tmp) {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(poly);
    write_with(*writer, tmp, path);
  });
}

void write_vtp(const PointSet& points, const fs::path& path) {
  detail::quiet_vtk_messages();
  std::set<std::string> names;
  check_arrays(points.point_scalars, points.points.size(), "point", names, path);

  vtkNew<vtkPolyData> poly;
  poly->SetPoints(make_points(points.points));
  // One vertex cell per point, so ParaView draws them without a glyph filter.
  vtkNew<vtkCellArray> verts;
  verts->AllocateExact(static_cast<vtkIdType>(points.points.size()), static_cast<vtkIdType>(points.points.size()));
  for (std::size_t i = 0; i < points.points.size(); ++i) {
    const vtkIdType id = static_cast<vtkIdType>(i);
    verts->InsertNextCell(1, &id);
  }
  poly->SetVerts(verts);
  add_doubles(*poly->GetPointData(), points.point_scalars);

  write_atomically(path, [&](const fs::path& tmp) {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(poly);
    write_with(*writer, tmp, path);
  });
}

void write_vti(const volume::Grid& grid, const fs::path& path, std::uint64_t max_voxels) {
  detail::quiet_vtk_messages();
  const volume::IndexBox box = grid.active_bbox();
  if (box.empty()) fail("{}: grid '{}' has no active voxels; nothing to write", path.string(), grid.name());
  const auto ext = box.extent();
  const std::uint64_t total =
      static_cast<std::uint64_t>(ext[0]) * static_cast<std::uint64_t>(ext[1]) * static_cast<std::uint64_t>(ext[2]);
  if (total > max_voxels) {
    fail("{}: grid '{}' spans {}x{}x{} = {} voxels, above the limit of {} for a dense .vti", path.string(), grid.name(),
         ext[0], ext[1], ext[2], total, max_voxels);
  }

  // Voxel (i,j,k) covers [origin + h·i, origin + h·(i+1)): the box's lower corner is the image
  // origin and voxels are cells of a (n+1)³ point lattice.
  const double h = grid.voxel_size();
  const auto o = grid.origin();
  vtkNew<vtkImageData> image;
  image->SetDimensions(static_cast<int>(ext[0] + 1), static_cast<int>(ext[1] + 1), static_cast<int>(ext[2] + 1));
  image->SetSpacing(h, h, h);
  image->SetOrigin(o[0] + h * box.min[0], o[1] + h * box.min[1], o[2] + h * box.min[2]);

  vtkNew<vtkFloatArray> values;
  values->SetName(grid.name().empty() ? "density" : grid.name().c_str());
  values->SetNumberOfValues(static_cast<vtkIdType>(total));
  values->FillValue(0.0f);
  const auto cell = [&](int i, int j, int k) {
    return static_cast<vtkIdType>((i - box.min[0]) +
                                  ext[0] * ((j - box.min[1]) + ext[1] * std::int64_t{k - box.min[2]}));
  };
  const openvdb::FloatGrid& vdb = *grid.impl().grid;
  // Active tiles stand for a whole block of voxels with one value: expand them.
  for (auto it = vdb.cbeginValueOn(); it; ++it) {
    const float v = *it;
    if (it.isVoxelValue()) {
      const auto c = it.getCoord();
      values->SetValue(cell(c.x(), c.y(), c.z()), v);
      continue;
    }
    const openvdb::CoordBBox tile = it.getBoundingBox();
    for (int k = tile.min().z(); k <= tile.max().z(); ++k) {
      for (int j = tile.min().y(); j <= tile.max().y(); ++j) {
        for (int i = tile.min().x(); i <= tile.max().x(); ++i) values->SetValue(cell(i, j, k), v);
      }
    }
  }
  image->GetCellData()->SetScalars(values);

  write_atomically(path, [&](const fs::path& tmp) {
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetInputData(image);
    write_with(*writer, tmp, path);
  });
}

}  // namespace weft::viz
