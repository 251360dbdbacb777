#include <atomic>
#include <cmath>
#include <mutex>
#include <new>
#include <vector>

#include <openvdb/io/File.h>
#include <openvdb/tools/ValueTransformer.h>
#include <openvdb/tree/LeafManager.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "weft/core/error.h"
#include "weft/core/number_name.h"
#include "weft/volume/grid_io.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace fs = std::filesystem;

void ensure_openvdb_initialized() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

namespace {

// OpenVDB rebuilds a linear transform from its 4×4 matrix whenever it copies one (every file
// write copies the grid first, and so does deepCopy): math::simplify takes the voxel size as
// (t + h) − t in doubles, t the translation (origin + h/2). The sum rounds to half an ulp of t,
// so once |t| nears 2⁵³·h (ulp(t) ≥ 2h) the recomputed size is 0 and OpenVDB throws
// ArithmeticError "Non-zero scale values required" (origin 1e20, h = 0.1: on save, long after
// the grid was made). Such a transform is refused where it is set, by OpenVDB's own copy.
// Below that the copy only rounds h (to 0.125 for 0.1 at t = 1e15): weft's own copies share
// the transform instead (deep_copy), and a file keeps the transform as set.
void require_copyable_transform(const openvdb::math::Transform& transform, const std::string& what) {
  try {
    (void)transform.copy();
  } catch (const openvdb::ArithmeticError&) {
    const double h = transform.voxelSize()[0];
    const openvdb::Vec3d t = transform.indexToWorld(openvdb::Vec3d(0.0));
    fail(
        "{}: origin ({:g}, {:g}, {:g}) is too far from 0 for voxels of {:g}: OpenVDB recomputes the voxel size as "
        "(origin + h) - origin in doubles whenever it copies or writes a grid, which gives ({:g}, {:g}, {:g}) here "
        "(|origin| must stay well below 2^53 h = {:.3g}): move the origin nearer 0 (subtract a common offset)",
        what, t[0] - 0.5 * h, t[1] - 0.5 * h, t[2] - 0.5 * h, h, (t[0] + h) - t[0], (t[1] + h) - t[1],
        (t[2] + h) - t[2], 0x1p53 * h);
  }
}

// Relative tolerance of a grid's transform against cubic, axis-aligned voxels: floating-point
// noise in a file's matrix (a rotation by 1e-12 rad) still loads.
constexpr double kTransformTolerance = 1e-9;

// What a transform does to the voxels beyond a positive uniform scale, given its 3×3 matrix
// divided by the voxel size: "" when it is the identity within kTransformTolerance.
std::string misalignment(const openvdb::math::Mat3d& unit, double determinant) {
  if (unit.eq(openvdb::math::Mat3d::identity(), kTransformTolerance)) return "";
  if (determinant < 0.0) return "mirrors the voxels (a negative scale)";
  const openvdb::math::Mat3d gram = unit * unit.transpose();
  if (gram.eq(openvdb::math::Mat3d::identity(), kTransformTolerance)) return "rotates the voxels";
  return "shears the voxels";
}

// Cubic voxels at origin + h·(i, j, k) (a positive uniform scale plus a translation) are what the
// DDA, the voxel-size-based physics and every export assume (docs/scene-format.md "Grid
// media"): any other transform is refused, not read as if axis-aligned.
void require_uniform_scale(const openvdb::FloatGrid& grid, const std::string& where) {
  const auto& map = *grid.transform().baseMap();
  if (!map.isLinear())
    fail("{}: grid '{}' has a non-linear transform; weft needs a uniform voxel scale", where, grid.getName());
  const openvdb::Vec3d size = grid.voxelSize();
  const double tol = kTransformTolerance * size.length();
  if (std::abs(size[0] - size[1]) > tol || std::abs(size[0] - size[2]) > tol) {
    fail("{}: grid '{}' has non-uniform voxel size ({}, {}, {}); weft needs cubic voxels", where, grid.getName(),
         size[0], size[1], size[2]);
  }
  if (!(size[0] > 0.0) || !std::isfinite(size[0]))
    fail("{}: grid '{}' has voxel size {}", where, grid.getName(), size[0]);
  const std::string problem =
      misalignment(map.getAffineMap()->getConstMat4().getMat3() * (1.0 / size[0]), map.determinant());
  if (!problem.empty()) {
    fail(
        "{}: grid '{}': its transform {}; weft needs axis-aligned voxels, a positive uniform scale plus a "
        "translation (docs/scene-format.md, \"Grid media\")",
        where, grid.getName(), problem);
  }
  require_copyable_transform(grid.transform(), fmt::format("{}: grid '{}'", where, grid.getName()));
}

// What weft reads (Grid::load): finite and >= 0.
bool valid_value(float v) { return std::isfinite(v) && v >= 0.0f; }

// Which values a check refuses: on reading, any but valid_value; on writing a grid flagged
// saveFloatAsHalf, a finite value its file would turn into ±∞ (OpenVDB rounds to a 16-bit half
// on writing, ±∞ beyond 65504), a value the reader refuses though the writer held a finite one.
enum class Check { read, write_half };
bool passes(float v, Check check) {
  return check == Check::read ? valid_value(v) : !(std::isfinite(v) && !std::isfinite(half_precision(v)));
}

// True when every active value passes `check`: the leaves on all threads, then the tiles.
bool all_values_valid(const openvdb::FloatGrid& grid, Check check) {
  const openvdb::tree::LeafManager<const openvdb::FloatTree> leaves(grid.tree());
  std::atomic<bool> valid{true};
  tbb::parallel_for(leaves.leafRange(), [&](const openvdb::tree::LeafManager<const openvdb::FloatTree>::LeafRange& r) {
    for (auto leaf = r.begin(); leaf; ++leaf) {
      for (auto it = leaf->cbeginValueOn(); it; ++it) {
        if (!passes(*it, check)) valid.store(false, std::memory_order_relaxed);
      }
    }
  });
  auto tile = grid.cbeginValueOn();
  tile.setMaxDepth(tile.getLeafDepth() - 1);  // tiles only
  for (; tile; ++tile) {
    if (!passes(*tile, check)) return false;
  }
  return valid.load();
}

// Only a grid that fails the parallel check is walked in tree order, so the voxel named is the
// same for any thread count.
void require_valid_values(const openvdb::FloatGrid& grid, const std::string& where, Check check) {
  if (all_values_valid(grid, check)) return;
  for (auto it = grid.cbeginValueOn(); it; ++it) {
    if (passes(*it, check)) continue;
    const float v = *it;
    const openvdb::Coord c = it.getCoord();
    if (check == Check::write_half) {
      fail(
          "{}: grid '{}' holds {} at voxel ({}, {}, {}), beyond the range of the 16-bit floats its file stores "
          "(+-{}): the file would hold {}, which weft refuses to read",
          where, grid.getName(), v, c.x(), c.y(), c.z(), kHalfMax, half_precision(v));
    }
    fail("{}: grid '{}' has invalid value {} at voxel ({}, {}, {}); values must be finite and >= 0", where,
         grid.getName(), v, c.x(), c.y(), c.z());
  }
}

void require_zero_background(const openvdb::FloatGrid& grid, const std::string& where) {
  const float bg = grid.background();
  if (!std::isfinite(bg) || bg != 0.0f)
    fail("{}: grid '{}' has background {}; weft needs background 0", where, grid.getName(), bg);
}

// OpenVDB's linear transform of cubic voxels of side h. Its scale map refuses a determinant
// h³ below 3·10⁻¹⁵ (math::Tolerance<double>, an ArithmeticError from deep inside OpenVDB), so
// voxels under about 14.4 µm in metres cannot be represented: say so in weft's words first.
openvdb::math::Transform::Ptr voxel_transform(double h) {
  require_positive("voxel size", h);
  if (h * h * h < 3.0 * openvdb::math::Tolerance<double>::value())
    fail(
        "voxel size {:.6g} is below the smallest OpenVDB represents (h^3 >= 3e-15, h >= {}): give lengths in a "
        "smaller unit (e.g. millimetres instead of metres)",
        h, bound_text(min_voxel_size(), BoundSide::at_least));
  return openvdb::math::Transform::createLinearTransform(h);
}

// A value a grid stored as half can hold: store_as_half and set_value refuse any other.
bool fits_half(float v) { return !(std::abs(v) > kHalfMax); }

}  // namespace

double min_voxel_size() { return std::cbrt(3.0 * openvdb::math::Tolerance<double>::value()); }

namespace {

// What Grid::load accepts: checked by the reader on what it read, and by every writer on what its
// file will hold, so that a writer never writes what its reader refuses of what it held: the
// transform, the background, the index range, and values a half file would turn into ±∞. (The
// values themselves are the writer's: local fields' α is +∞ where a block's variance is 0.)
void require_loadable(const openvdb::FloatGrid& grid, const std::string& where, bool writing) {
  require_uniform_scale(grid, where);
  if (!writing) require_valid_values(grid, where, Check::read);
  if (writing && grid.saveFloatAsHalf()) require_valid_values(grid, where, Check::write_half);
  require_zero_background(grid, where);
  if (!grid.tree().empty()) {
    const openvdb::CoordBBox b = active_voxel_bbox(grid);
    if (!b.empty())
      require_index_range({{b.min().x(), b.min().y(), b.min().z()}, {b.max().x(), b.max().y(), b.max().z()}},
                          fmt::format("{}: grid '{}': its active voxels span index box", where, grid.getName()));
  }
}

}  // namespace

void require_writable(const openvdb::FloatGrid& grid, const std::string& path) {
  require_loadable(grid, path + ": not written", true);
}

static_assert(openvdb::FloatTree::RootNodeType::ChildNodeType::DIM == 4096,
              "kMaxIndex keeps voxels out of the outermost root children, 4096 voxels a side");

namespace {
bool in_index_range(int i) { return i >= -kMaxIndex && i <= kMaxIndex; }
}  // namespace

std::string index_range_text() {
  return fmt::format("the index range of a grid, |index| <= {} (OpenVDB's 32-bit node origins overflow past it)",
                     kMaxIndex);
}

void require_index_range(const IndexBox& box, const std::string& what) {
  if (box.empty()) return;
  for (int a = 0; a < 3; ++a) {
    if (!in_index_range(box.min[a]) || !in_index_range(box.max[a]))
      fail("{} ({}, {}, {})..({}, {}, {}) reaches beyond {}", what, box.min[0], box.min[1], box.min[2], box.max[0],
           box.max[1], box.max[2], index_range_text());
  }
}

Grid make_grid(std::shared_ptr<Grid::Impl> impl) { return Grid(std::move(impl)); }

openvdb::FloatGrid::Ptr deep_copy(const Grid& grid) {
  const openvdb::FloatGrid& source = *grid.impl().grid;
  openvdb::FloatGrid::Ptr copy = source.deepCopy();
  // deepCopy's transform is rebuilt by math::simplify, which rounds h far from 0 (see
  // require_copyable_transform); the source's own is shared instead: weft never changes a
  // transform in place (set_origin makes a new one), so sharing it is a copy.
  copy->setTransform(openvdb::ConstPtrCast<openvdb::math::Transform>(source.transformPtr()));
  return copy;
}

Grid wrap_openvdb(openvdb::FloatGrid::Ptr grid) {
  require_uniform_scale(*grid, "grid");
  auto impl = std::make_shared<Grid::Impl>();
  impl->grid = std::move(grid);
  return make_grid(std::move(impl));
}

Grid::Grid(double voxel_size, const std::string& name) : impl_(std::make_shared<Impl>()) {
  ensure_openvdb_initialized();
  impl_->grid = openvdb::FloatGrid::create(0.0f);
  impl_->grid->setName(name);
  impl_->grid->setTransform(voxel_transform(voxel_size));
  impl_->grid->setGridClass(openvdb::GRID_FOG_VOLUME);
}

Grid Grid::load(const fs::path& path, const std::string& grid_name) {
  ensure_openvdb_initialized();
  const std::string where = path.string();
  std::error_code ec;
  if (!fs::exists(path, ec)) fail("{}: no such file", where);
  if (!fs::is_regular_file(path, ec)) fail("{}: not a regular file", where);
  check_vdb_file(path);  // bounds every length OpenVDB will read (grid_io.cpp)
  openvdb::GridBase::Ptr base;
  try {
    openvdb::io::File file(path.string());
    file.open(false);  // no delayed loading: the file may change under us, and we read it whole
    // A header cut short still opens, as a file without grids: say so rather than "no float grid".
    if (file.beginName() == file.endName())
      fail("{}: the file holds no grids (empty or truncated OpenVDB file)", where);
    // Only float grids are read: check_vdb_file checks the trees of float grids only.
    if (grid_name.empty()) {
      for (auto it = file.beginName(); it != file.endName(); ++it) {
        if (file.readGridMetadata(it.gridName())->isType<openvdb::FloatGrid>()) {
          base = file.readGrid(it.gridName());
          break;
        }
      }
      if (!base) fail("{}: the file holds no float grid", where);
    } else {
      if (!file.hasGrid(grid_name)) {
        std::string names;
        for (auto it = file.beginName(); it != file.endName(); ++it)
          names += (names.empty() ? "" : ", ") + it.gridName();
        fail("{}: no grid named '{}' (the file has: {})", where, grid_name, names.empty() ? "none" : names);
      }
      const auto meta = file.readGridMetadata(grid_name);
      if (!meta->isType<openvdb::FloatGrid>())
        fail("{}: grid '{}' is of type {}, weft needs a float grid", where, grid_name, meta->valueType());
      base = file.readGrid(grid_name);
    }
    file.close();
  } catch (const openvdb::Exception& e) {
    fail("{}: cannot read OpenVDB file: {}", where, e.what());
  } catch (const std::ios_base::failure& e) {
    fail("{}: cannot read OpenVDB file: {}", where, e.what());
  } catch (const std::bad_alloc&) {
    // OpenVDB allocates the buffer sizes a grid declares (fuzz_vdb, io::bloscFromStream).
    fail("{}: cannot read OpenVDB file: corrupt (a declared buffer size does not fit in memory)", where);
  }
  auto grid = openvdb::gridPtrCast<openvdb::FloatGrid>(base);
  if (!grid) fail("{}: grid '{}' is of type {}, weft needs a float grid", where, base->getName(), base->valueType());
  require_loadable(*grid, where, false);
  auto impl = std::make_shared<Impl>();
  impl->grid = grid;
  return Grid(std::move(impl));
}

void Grid::save(const fs::path& path) const { save_grids({*this}, path); }

Grid Grid::deep_copy() const {
  auto impl = std::make_shared<Impl>();
  impl->grid = volume::deep_copy(*this);
  return Grid(std::move(impl));
}

std::string Grid::name() const { return impl_->grid->getName(); }

double Grid::voxel_size() const { return impl_->grid->voxelSize()[0]; }

std::array<double, 3> Grid::origin() const {
  const openvdb::Vec3d o = impl_->grid->indexToWorld(openvdb::Vec3d(-0.5, -0.5, -0.5));
  return {o[0], o[1], o[2]};
}

void Grid::set_origin(const std::array<double, 3>& origin) {
  const double h = voxel_size();
  // OpenVDB puts voxel centres at integer index coordinates: index i covers [i-0.5, i+0.5).
  for (double c : origin) require_finite("grid origin", c);
  auto xform = voxel_transform(h);
  xform->postTranslate(openvdb::Vec3d(origin[0] + 0.5 * h, origin[1] + 0.5 * h, origin[2] + 0.5 * h));
  require_copyable_transform(*xform, fmt::format("grid '{}'", name()));
  impl_->grid->setTransform(xform);
}

std::uint64_t Grid::active_voxel_count() const { return impl_->grid->activeVoxelCount(); }

std::uint64_t Grid::memory_bytes() const { return impl_->grid->tree().memUsage(); }

float half_precision(float v) { return static_cast<float>(openvdb::math::half(v)); }

void Grid::store_as_half() {
  openvdb::FloatTree& tree = impl_->grid->tree();
  // Checked before anything changes, so a refused grid keeps its values.
  std::atomic<bool> too_large{false};
  openvdb::tools::foreach (tree.cbeginValueOn(), [&](const openvdb::FloatTree::ValueOnCIter& it) {
    if (!fits_half(*it)) too_large = true;
  });
  if (too_large) fail("grid '{}': a value is beyond the range of a 16-bit float (65504)", name());
  openvdb::tools::foreach (tree.beginValueOn(),
                           [](const openvdb::FloatTree::ValueOnIter& it) { it.setValue(half_precision(*it)); });
  impl_->grid->setSaveFloatAsHalf(true);
}

bool Grid::stored_as_half() const { return impl_->grid->saveFloatAsHalf(); }

openvdb::CoordBBox active_voxel_bbox(const openvdb::FloatGrid& grid) {
  using Leaves = openvdb::tree::LeafManager<const openvdb::FloatTree>;
  const Leaves leaves(grid.tree());
  openvdb::CoordBBox box = tbb::parallel_reduce(
      leaves.leafRange(), openvdb::CoordBBox(),
      [](const Leaves::LeafRange& r, openvdb::CoordBBox b) {
        for (auto leaf = r.begin(); leaf; ++leaf) leaf->evalActiveBoundingBox(b, true);
        return b;
      },
      [](openvdb::CoordBBox a, const openvdb::CoordBBox& b) {
        a.expand(b);
        return a;
      });
  auto tile = grid.cbeginValueOn();
  tile.setMaxDepth(tile.getLeafDepth() - 1);  // tiles only: leaf voxels are in the box already
  for (; tile; ++tile) box.expand(tile.getBoundingBox());
  return box;
}

IndexBox Grid::active_bbox() const {
  IndexBox box;
  if (impl_->grid->activeVoxelCount() == 0) return box;
  const openvdb::CoordBBox b = active_voxel_bbox(*impl_->grid);
  box.min = {b.min().x(), b.min().y(), b.min().z()};
  box.max = {b.max().x(), b.max().y(), b.max().z()};
  return box;
}

float Grid::value(int i, int j, int k) const {
  return impl_->grid->getConstAccessor().getValue(openvdb::Coord(i, j, k));
}

void Grid::set_value(int i, int j, int k, float v) {
  if (!in_index_range(i) || !in_index_range(j) || !in_index_range(k))
    fail("set_value: voxel ({}, {}, {}) is beyond {}", i, j, k, index_range_text());
  // A grid stored as half holds half values (store_as_half) and no value beyond them: refused
  // here, where the value enters, not when its file (±∞) is read back.
  if (stored_as_half()) {
    if (!fits_half(v)) {
      fail(
          "set_value: grid '{}' stores its values as 16-bit floats, whose range ends at {}: got {} at voxel ({}, {}, "
          "{})",
          name(), kHalfMax, v, i, j, k);
    }
    v = half_precision(v);
  }
  impl_->grid->getAccessor().setValue(openvdb::Coord(i, j, k), v);
}

struct VoxelReader::Impl {
  openvdb::FloatGrid::ConstPtr grid;  // keeps the tree alive for the reader
  LeafCachedReader reader;
  explicit Impl(openvdb::FloatGrid::ConstPtr g) : grid(std::move(g)), reader(*grid) {}
};

VoxelReader::VoxelReader(const Grid& grid) : impl_(std::make_unique<Impl>(grid.impl().grid)) {}
VoxelReader::~VoxelReader() = default;
VoxelReader::VoxelReader(VoxelReader&&) noexcept = default;
VoxelReader& VoxelReader::operator=(VoxelReader&&) noexcept = default;

float VoxelReader::value(const std::array<int, 3>& ijk) {
  return impl_->reader.value(openvdb::Coord(ijk[0], ijk[1], ijk[2]));
}

double Grid::sum() const {
  // Each leaf's values summed on any thread, then the leaves in tree order and the tiles: the
  // same double for any thread count, and a rounding error that grows with the number of leaves
  // rather than of voxels (a running sum over 20 M voxels was also 2 % of a large grid's
  // validate on one thread, serial: docs/benchmarks.notes.md "the serial pieces, third pass").
  using Leaves = openvdb::tree::LeafManager<const openvdb::FloatTree>;
  const Leaves leaves(impl_->grid->tree());
  std::vector<double> per_leaf(leaves.leafCount());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, per_leaf.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      double s = 0.0;
      for (auto v = leaves.leaf(i).cbeginValueOn(); v; ++v) s += static_cast<double>(*v);
      per_leaf[i] = s;
    }
  });
  double total = 0.0;
  for (const double s : per_leaf) total += s;
  auto tile = impl_->grid->cbeginValueOn();
  tile.setMaxDepth(tile.getLeafDepth() - 1);  // tiles only: the leaves' voxels are counted above
  for (; tile; ++tile) total += static_cast<double>(*tile) * static_cast<double>(tile.getVoxelCount());
  return total;
}

void Grid::set_metadata(const std::string& key, const std::string& value) {
  impl_->grid->insertMeta(key, openvdb::StringMetadata(value));
}

std::map<std::string, std::string> Grid::metadata() const {
  std::map<std::string, std::string> out;
  for (auto it = impl_->grid->beginMeta(); it != impl_->grid->endMeta(); ++it) out[it->first] = it->second->str();
  return out;
}

}  // namespace weft::volume
