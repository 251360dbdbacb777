#include "weft/viz/vtk_files.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <set>
#include <utility>
#include <vector>

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkImageAlgorithm.h>
#include <vtkImageData.h>
#include <vtkInformation.h>
#include <vtkInformationVector.h>
#include <vtkIntArray.h>
#include <vtkLZ4DataCompressor.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkStreamingDemandDrivenPipeline.h>
#include <vtkTypeInt32Array.h>
#include <vtkTypeInt64Array.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLPolyDataWriter.h>

#include <tbb/parallel_for.h>

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

// Writes a configured writer's file to `tmp`; errors name `target`.
template <typename Writer>
void run_writer(Writer& writer, const fs::path& tmp, const fs::path& target) {
  writer.SetFileName(tmp.c_str());
  (void)detail::take_vtk_message();
  errno = 0;
  if (writer.Write() != 1 || writer.GetErrorCode() != 0) {
    // A short write (a full disk, a file size limit) in the words every other writer uses, not
    // VTK's pipeline dump.
    const int error = errno;
    if (error == ENOSPC || error == EFBIG || error == EDQUOT || error == EIO)
      fail("cannot write '{}': {}", target.string(), std::strerror(error));
    const std::string detail = detail::take_vtk_message();
    fail("{}: cannot write VTK file{}{}", target.string(), detail.empty() ? "" : ": ", detail);
  }
}

template <typename Writer>
void write_with(Writer& writer, const fs::path& tmp, const fs::path& target) {
  configure(writer);
  run_writer(writer, tmp, target);
}

// VTK's XML writer compresses an array in blocks of BlockSize bytes, one after the other; for a
// dense .vti that is most of the write, on one thread. This compressor is handed a piece's bytes as
// soon as the piece is made and compresses all its blocks at once, spread over the threads; the
// writer then finds each block it asks for done. The blocks are compressed by the base class's own
// call at the same level, so the bytes are those of a plain write for any thread count; a block
// that is not the next one expected (another cut, a converted copy) is compressed on the spot as
// VTK would; the writer usually hands the array's own memory, which then needs no comparison.
// LZ4, not zlib, for the dense box (docs/viz.md "ParaView files"): the box holds several times the grid's
// active voxels, mostly zeros and fibre values, and zlib spent 60 % of a large grid's `validate`
// compressing it (docs/benchmarks.md "Validate: the .vti's compressor"); LZ4 makes a file about
// 15 % larger in a third of the time, and VTK and ParaView read either.
// No vtkTypeMacro: GetClassName() stays "vtkLZ4DataCompressor", the name the writer puts in the
// file's `compressor` attribute and by which readers choose the decompressor.
class BlockParallelLZ4 : public vtkLZ4DataCompressor {
 public:
  static BlockParallelLZ4* New();

  // Compresses the blocks of `bytes` (valid until the next call) as the writer will cut them.
  void prepare(const unsigned char* bytes, std::size_t size, std::size_t block) {
    base_ = bytes;
    size_ = size;
    block_ = std::max<std::size_t>(block, 1);
    next_ = 0;
    const std::size_t count = (size + block_ - 1) / block_;
    blocks_.assign(count, {});
    tbb::parallel_for(std::size_t{0}, count, [&](std::size_t b) {
      const std::size_t n = block_length(b);
      std::vector<unsigned char>& out = blocks_[b];
      out.resize(GetMaximumCompressionSpace(n));
      out.resize(vtkLZ4DataCompressor::CompressBuffer(base_ + b * block_, n, out.data(), out.size()));
    });
  }

 protected:
  BlockParallelLZ4() = default;

  size_t CompressBuffer(unsigned char const* data, size_t size, unsigned char* out, size_t space) override {
    if (next_ < blocks_.size()) {
      const std::vector<unsigned char>& done = blocks_[next_];
      if (size == block_length(next_) && !done.empty() && done.size() <= space &&
          (data == base_ + next_ * block_ || std::memcmp(data, base_ + next_ * block_, size) == 0)) {
        std::memcpy(out, done.data(), done.size());
        ++next_;
        return done.size();
      }
    }
    return vtkLZ4DataCompressor::CompressBuffer(data, size, out, space);
  }

 private:
  std::size_t block_length(std::size_t b) const { return std::min(block_, size_ - b * block_); }

  const unsigned char* base_ = nullptr;
  std::size_t size_ = 0;
  std::size_t block_ = 1;
  std::size_t next_ = 0;
  std::vector<std::vector<unsigned char>> blocks_;
};
vtkStandardNewMacro(BlockParallelLZ4);

// The grid's active box as vtkImageData, made one requested extent at a time: with
// vtkXMLImageDataWriter::SetNumberOfPieces(n) the writer streams the image through the pipeline,
// asking for n sub-extents in turn and writing each before the next, so the dense copy of the
// box (4 bytes for every voxel of it, active or not: 9× the grid itself for a long yarn
// meandering through its box) never exists whole. Voxel (i,j,k) is cell (i,j,k) − box.min of a
// point lattice one larger; the box's lower corner is the image origin.
class GridImageSource : public vtkImageAlgorithm {
 public:
  static GridImageSource* New();
  vtkTypeMacro(GridImageSource, vtkImageAlgorithm)

      public : const openvdb::FloatGrid* grid = nullptr;
  volume::IndexBox box;
  double h = 1.0;
  std::array<double, 3> origin{};
  std::string name;
  // When set, each piece's bytes are handed to it as soon as they are made (in blocks of
  // block_size bytes, the writer's).
  BlockParallelLZ4* compressor = nullptr;
  std::size_t block_size = 0;

  // Leaves and active tiles with their boxes, once: each piece then visits only the nodes that
  // overlap it.
  void index_nodes() {
    for (auto leaf = grid->tree().cbeginLeaf(); leaf; ++leaf) leaves_.push_back(&*leaf);
    auto tile = grid->cbeginValueOn();
    tile.setMaxDepth(tile.getLeafDepth() - 1);  // tiles only: leaf voxels come from leaves_
    for (; tile; ++tile) tiles_.emplace_back(tile.getBoundingBox(), *tile);
  }

 protected:
  GridImageSource() { SetNumberOfInputPorts(0); }

  int RequestInformation(vtkInformation* /*request*/, vtkInformationVector** /*in*/,
                         vtkInformationVector* out) override {
    vtkInformation* info = out->GetInformationObject(0);
    const auto ext = box.extent();
    const int whole[6] = {0, static_cast<int>(ext[0]), 0, static_cast<int>(ext[1]), 0, static_cast<int>(ext[2])};
    info->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
    info->Set(vtkDataObject::SPACING(), h, h, h);
    info->Set(vtkDataObject::ORIGIN(), origin[0] + h * box.min[0], origin[1] + h * box.min[1],
              origin[2] + h * box.min[2]);
    info->Set(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT(), 1);
    return 1;
  }

  int RequestData(vtkInformation* /*request*/, vtkInformationVector** /*in*/, vtkInformationVector* out) override {
    vtkInformation* info = out->GetInformationObject(0);
    vtkImageData* image = vtkImageData::SafeDownCast(info->Get(vtkDataObject::DATA_OBJECT()));
    int e[6];
    info->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), e);
    image->SetExtent(e);
    image->SetSpacing(h, h, h);
    image->SetOrigin(origin[0] + h * box.min[0], origin[1] + h * box.min[1], origin[2] + h * box.min[2]);
    // Cells of the point extent e, in grid index coordinates.
    const openvdb::CoordBBox cells(openvdb::Coord(box.min[0] + e[0], box.min[1] + e[2], box.min[2] + e[4]),
                                   openvdb::Coord(box.min[0] + e[1] - 1, box.min[1] + e[3] - 1, box.min[2] + e[5] - 1));
    const vtkIdType nx = std::max(0, e[1] - e[0]);
    const vtkIdType ny = std::max(0, e[3] - e[2]);
    const vtkIdType nz = std::max(0, e[5] - e[4]);
    vtkNew<vtkFloatArray> values;
    values->SetName(name.c_str());
    values->SetNumberOfValues(nx * ny * nz);
    float* const dense = values->GetPointer(0);
    const vtkIdType count = nx * ny * nz;
    // Filled on all threads: nodes never overlap, so each voxel is written by one of them.
    tbb::parallel_for(
        tbb::blocked_range<vtkIdType>(0, count, vtkIdType{1} << 16),
        [&](const tbb::blocked_range<vtkIdType>& r) { std::fill(dense + r.begin(), dense + r.end(), 0.0f); });
    const auto set = [&](const openvdb::Coord& c, float v) {
      dense[vtkIdType{c.x() - cells.min().x()} +
            nx * (vtkIdType{c.y() - cells.min().y()} + ny * vtkIdType{c.z() - cells.min().z()})] = v;
    };
    if (!cells.empty()) {
      tbb::parallel_for(std::size_t{0}, leaves_.size(), [&](std::size_t l) {
        const auto* leaf = leaves_[l];
        if (!cells.hasOverlap(leaf->getNodeBoundingBox())) return;
        for (auto it = leaf->cbeginValueOn(); it; ++it) {
          const openvdb::Coord c = it.getCoord();
          if (cells.isInside(c)) set(c, *it);
        }
      });
      // Active tiles stand for a whole block of voxels with one value: expand their overlap.
      tbb::parallel_for(std::size_t{0}, tiles_.size(), [&](std::size_t t) {
        const auto& [tile, v] = tiles_[t];
        if (!cells.hasOverlap(tile)) return;
        const openvdb::Coord lo = openvdb::Coord::maxComponent(tile.min(), cells.min());
        const openvdb::Coord hi = openvdb::Coord::minComponent(tile.max(), cells.max());
        for (int k = lo.z(); k <= hi.z(); ++k) {
          for (int j = lo.y(); j <= hi.y(); ++j) {
            for (int i = lo.x(); i <= hi.x(); ++i) set(openvdb::Coord(i, j, k), v);
          }
        }
      });
    }
    image->GetCellData()->SetScalars(values);
    if (compressor != nullptr) {
      compressor->prepare(reinterpret_cast<const unsigned char*>(dense),
                          static_cast<std::size_t>(count) * sizeof(float), block_size);
    }
    return 1;
  }

 private:
  std::vector<const openvdb::FloatTree::LeafNodeType*> leaves_;
  std::vector<std::pair<openvdb::CoordBBox, float>> tiles_;
};
vtkStandardNewMacro(GridImageSource);

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

namespace {

// The particles as VTK poly data: one vertex cell per point, so ParaView draws them without a
// glyph filter. `path` names the file in errors.
vtkSmartPointer<vtkPolyData> point_poly(const PointSet& points, const fs::path& path) {
  detail::quiet_vtk_messages();
  std::set<std::string> names;
  check_arrays(points.point_scalars, points.points.size(), "point", names, path);
  auto poly = vtkSmartPointer<vtkPolyData>::New();
  poly->SetPoints(make_points(points.points));
  vtkNew<vtkCellArray> verts;
  verts->AllocateExact(static_cast<vtkIdType>(points.points.size()), static_cast<vtkIdType>(points.points.size()));
  for (std::size_t i = 0; i < points.points.size(); ++i) {
    const vtkIdType id = static_cast<vtkIdType>(i);
    verts->InsertNextCell(1, &id);
  }
  poly->SetVerts(verts);
  add_doubles(*poly->GetPointData(), points.point_scalars);
  return poly;
}

}  // namespace

void write_vtp(const PointSet& points, const fs::path& path) {
  const vtkSmartPointer<vtkPolyData> poly = point_poly(points, path);
  write_atomically(path, [&](const fs::path& tmp) {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(poly);
    write_with(*writer, tmp, path);
  });
}

std::string vtp_bytes(const PointSet& points, const fs::path& path) {
  const vtkSmartPointer<vtkPolyData> poly = point_poly(points, path);
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(poly);
  configure(*writer);
  writer->WriteToOutputStringOn();
  (void)detail::take_vtk_message();
  if (writer->Write() != 1 || writer->GetErrorCode() != 0) {
    const std::string detail = detail::take_vtk_message();
    fail("{}: cannot write VTK file{}{}", path.string(), detail.empty() ? "" : ": ", detail);
  }
  return writer->GetOutputString();
}

std::string vti_refusal(const volume::Grid& grid, std::uint64_t max_voxels) {
  const volume::IndexBox box = grid.active_bbox();
  if (box.empty()) return fmt::format("grid '{}' has no active voxels; nothing to write", grid.name());
  const auto ext = box.extent();
  const std::uint64_t total =
      static_cast<std::uint64_t>(ext[0]) * static_cast<std::uint64_t>(ext[1]) * static_cast<std::uint64_t>(ext[2]);
  if (total > max_voxels)
    return fmt::format("grid '{}' spans {}x{}x{} = {} voxels, above the limit of {} for a dense .vti", grid.name(),
                       ext[0], ext[1], ext[2], total, max_voxels);
  return {};
}

void write_vti(const volume::Grid& grid, const fs::path& path, std::uint64_t max_voxels, std::uint64_t piece_voxels) {
  detail::quiet_vtk_messages();
  if (const std::string why = vti_refusal(grid, max_voxels); !why.empty()) fail("{}: {}", path.string(), why);
  const volume::IndexBox box = grid.active_bbox();
  const auto ext = box.extent();
  const std::uint64_t total =
      static_cast<std::uint64_t>(ext[0]) * static_cast<std::uint64_t>(ext[1]) * static_cast<std::uint64_t>(ext[2]);
  vtkNew<GridImageSource> source;
  source->grid = grid.impl().grid.get();
  source->box = box;
  source->h = grid.voxel_size();
  source->origin = grid.origin();
  source->name = grid.name().empty() ? "density" : grid.name();
  source->index_nodes();
  // Pieces of at most piece_voxels voxels (at least one voxel layer each): the writer asks the
  // source for one piece at a time and writes it out before asking for the next.
  const std::uint64_t pieces = std::clamp<std::uint64_t>(
      (total + piece_voxels - 1) / std::max<std::uint64_t>(piece_voxels, 1), 1, static_cast<std::uint64_t>(ext[2]));
  write_atomically(path, [&](const fs::path& tmp) {
    vtkNew<vtkXMLImageDataWriter> writer;
    writer->SetInputConnection(source->GetOutputPort());
    writer->SetNumberOfPieces(static_cast<int>(pieces));
    configure(*writer);
    vtkNew<BlockParallelLZ4> compressor;
    compressor->SetAccelerationLevel(1);  // LZ4's own default mode: its best ratio short of LZ4-HC
    writer->SetCompressor(compressor);
    source->compressor = compressor;
    source->block_size = writer->GetBlockSize();
    run_writer(*writer, tmp, path);
    source->compressor = nullptr;
  });
}

}  // namespace weft::viz
