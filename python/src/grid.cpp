// Sparse voxel grids (weft/volume/grid.h): .vdb files, metadata, dense numpy sub-boxes.
#include <filesystem>
#include <string>

#include "common.h"
#include "weft/core/memory.h"
#include "weft/volume/dense.h"
#include "weft/volume/grid.h"
#include "weft/volume/provenance.h"

namespace weft::python {
namespace {

namespace vol = weft::volume;

using Box = std::pair<std::array<int, 3>, std::array<int, 3>>;

vol::IndexBox to_box(const std::optional<Box>& box, const vol::Grid& grid) {
  if (!box) {
    const vol::IndexBox b = grid.active_bbox();
    if (b.empty()) fail("to_numpy: the grid has no active voxels; pass box=((i0, j0, k0), (i1, j1, k1))");
    return b;
  }
  vol::IndexBox b{box->first, box->second};
  if (b.empty())
    fail("to_numpy: box min must be <= max per axis, got ({}, {}, {})..({}, {}, {})", b.min[0], b.min[1], b.min[2],
         b.max[0], b.max[1], b.max[2]);
  vol::require_index_range(b, "to_numpy: box");
  return b;
}

py::array_t<float> to_numpy(const vol::Grid& grid, const std::optional<Box>& box, std::optional<double> max_memory_mb) {
  const vol::IndexBox b = to_box(box, grid);
  // A given limit is finite and > 0, as `weft export --max-memory-mb` and `weft gen --max-memory`.
  const std::uint64_t limit = memory_budget_bytes(
      "to_numpy: max_memory_mb", max_memory_mb ? require_positive("to_numpy: max_memory_mb", *max_memory_mb) : 0.0);
  // Ctrl-C raises KeyboardInterrupt at the copy's next report (docs/python.md "Interrupting a call").
  std::vector<float> values =
      run_released(py::none(), [&](ProgressSink& progress) { return vol::to_dense(grid, b, limit, progress); });
  const auto e = b.extent();
  auto* owned = new std::vector<float>(std::move(values));
  py::capsule free_when_done(owned, [](void* p) { delete static_cast<std::vector<float>*>(p); });
  return py::array_t<float>({e[0], e[1], e[2]}, owned->data(), free_when_done);
}

vol::Grid from_numpy(const py::array_t<float, py::array::c_style | py::array::forcecast>& values, double voxel_size,
                     const std::array<int, 3>& index_origin, const std::string& name,
                     const std::optional<std::array<double, 3>>& origin) {
  if (values.ndim() != 3) fail("from_numpy: expected a 3-D array, got {} dimensions", values.ndim());
  require_positive("from_numpy: voxel_size", voxel_size);
  vol::Grid grid(voxel_size, name);
  if (origin) {
    for (double c : *origin) require_finite("from_numpy: origin", c);
    grid.set_origin(*origin);
  }
  const std::array<std::int64_t, 3> extent{values.shape(0), values.shape(1), values.shape(2)};
  const float* data = values.data();
  py::gil_scoped_release release;
  vol::from_dense(grid, index_origin, extent, data, "from_numpy");
  return grid;
}

std::optional<std::string> optional_text(const std::string& text) {
  if (text.empty()) return std::nullopt;
  return text;
}

py::dict metadata(const vol::Grid& g) {
  py::dict d;
  for (const auto& [k, v] : g.metadata()) d[py::str(k)] = v;
  return d;
}

}  // namespace

volume::SigmaChoice grid_sigma(const volume::Grid& grid, const std::optional<double>& sigma, const char* call) {
  const volume::Provenance p = volume::read_provenance(grid);
  const std::optional<double> given =
      sigma ? std::optional<double>(require_positive(fmt::format("{}: sigma", call).c_str(), *sigma)) : std::nullopt;
  return volume::resolve_sigma(p, given, p.value_kind == "extinction", call, FrontEnd::python);
}

void init_grid(py::module_& m) {
  py::class_<vol::Grid>(m, "Grid",
                        "A sparse scalar voxel grid (an OpenVDB FloatGrid): fibre volume fraction C or extinction mu.\n"
                        "Index (i, j, k) covers [origin + voxel_size*i, origin + voxel_size*(i+1)) per axis.")
      .def(py::init<double, const std::string&>(), py::arg("voxel_size") = 1.0, py::arg("name") = "density",
           "An empty grid with cubic voxels of voxel_size (length units), origin -voxel_size/2 per axis\n"
           "(OpenVDB's voxel centres at voxel_size*(i, j, k)); weft gen's grids have origin 0.")
      .def_static(
          "load",
          [](const py::object& path, const std::string& name) {
            const std::filesystem::path p = path_arg(path, "Grid.load: path");
            py::gil_scoped_release release;
            return vol::Grid::load(p, name);
          },
          py::arg("path"), py::arg("name") = "",
          "Reads the float grid `name` (or the first) of a .vdb file; weft.Error for a missing, corrupt or invalid "
          "file.")
      .def(
          "save",
          [](const vol::Grid& g, const py::object& path) {
            const std::filesystem::path p = output_path_arg(path, "Grid.save: path", false);
            py::gil_scoped_release release;
            g.save(p);
          },
          py::arg("path"), "Writes the grid with its metadata to a .vdb file (atomically).")
      .def_property_readonly("name", &vol::Grid::name)
      .def_property_readonly("voxel_size", &vol::Grid::voxel_size, "Voxel edge in length units (mm for weft gen).")
      .def_property("origin", &vol::Grid::origin, &vol::Grid::set_origin,
                    "World position of the low corner of voxel (0, 0, 0).")
      .def_property_readonly("active_voxel_count", &vol::Grid::active_voxel_count)
      .def_property_readonly(
          "bbox",
          [](const vol::Grid& g) -> py::object {
            const auto b = g.active_bbox();
            if (b.empty()) return py::none();
            return py::make_tuple(py::make_tuple(b.min[0], b.min[1], b.min[2]),
                                  py::make_tuple(b.max[0], b.max[1], b.max[2]));
          },
          "Inclusive index box ((i0, j0, k0), (i1, j1, k1)) of the active voxels; None when empty.")
      .def_property_readonly("metadata", &metadata,
                             "Provenance stored in the .vdb (generator parameters as JSON, seed, units...).")
      .def("set_metadata", &vol::Grid::set_metadata, py::arg("key"), py::arg("value"))
      // Typed provenance (docs/architecture.md §5, volume/provenance.h): the keys weft gen writes,
      // read by the one reader validate, measure and render use; None where the grid has none.
      .def_property_readonly(
          "sigma", [](const vol::Grid& g) { return vol::read_provenance(g).sigma; },
          "Extinction per unit concentration (1/length) from the provenance (weft:sigma_per_concentration), "
          "or None.")
      .def_property_readonly(
          "sigma_rule", [](const vol::Grid& g) { return optional_text(vol::read_provenance(g).sigma_rule); },
          "How sigma was derived (weft:sigma_rule), or None.")
      .def_property_readonly(
          "yarn_diameter", [](const vol::Grid& g) { return vol::read_provenance(g).yarn_diameter; },
          "Mean yarn diameter (length units) from the provenance (weft:yarn_diameter): the window of "
          "validate's default scale; or None.")
      .def_property_readonly(
          "fiber_radius", [](const vol::Grid& g) { return vol::read_provenance(g).fiber_radius; },
          "Fibre radius (length units) from the provenance (weft:fiber_radius), or None.")
      .def_property_readonly(
          "units", [](const vol::Grid& g) { return optional_text(vol::read_provenance(g).units); },
          "Length unit of the grid (weft:units, \"mm\" for weft gen), or None.")
      .def_property_readonly(
          "value_kind", [](const vol::Grid& g) { return optional_text(vol::read_provenance(g).value_kind); },
          "\"concentration\" or \"extinction\" (weft:value_kind), or None.")
      .def("value", &vol::Grid::value, py::arg("i"), py::arg("j"), py::arg("k"), "Value at a voxel (0 where inactive).")
      .def(
          "set_value",
          [](vol::Grid& g, int i, int j, int k, float v) {
            if (!std::isfinite(v) || v < 0.0f) fail("set_value: values must be finite and >= 0, got {}", v);
            g.set_value(i, j, k, v);
          },
          py::arg("i"), py::arg("j"), py::arg("k"), py::arg("value"))
      .def("sum", &vol::Grid::sum, "Sum of the active values.")
      .def("to_numpy", &to_numpy, py::arg("box") = py::none(), py::arg("max_memory_mb") = py::none(),
           "Dense float32 copy of an index box (default: the active bbox) as an array [i, j, k] of shape\n"
           "(nx, ny, nz); inactive voxels are 0. Refuses (weft.Error) arrays above max_memory_mb\n"
           "(default half the RAM).")
      .def_static("from_numpy", &from_numpy, py::arg("values"), py::arg("voxel_size") = 1.0,
                  py::arg("index_origin") = std::array<int, 3>{0, 0, 0}, py::arg("name") = "density",
                  py::arg("origin") = py::none(),
                  "A grid from a dense array [i, j, k]: element (0, 0, 0) goes to voxel index_origin; zeros stay\n"
                  "inactive. weft.Error for NaN, infinite or negative values. origin=None is -voxel_size/2 per axis\n"
                  "(as weft.Grid(voxel_size)), not weft gen's 0: to keep a grid g's world placement exactly, pass\n"
                  "voxel_size=g.voxel_size, index_origin=g.bbox[0], origin=g.origin.")
      // A Grid is a handle on its tree: copy.copy and copy.deepcopy both give an independent grid,
      // so that set_value on the copy never changes the original.
      .def(
          "__copy__", [](const vol::Grid& g) { return g.deep_copy(); },
          "An independent copy (as copy.deepcopy): values, metadata, voxel size and origin.")
      .def(
          "__deepcopy__", [](const vol::Grid& g, const py::dict& /*memo*/) { return g.deep_copy(); }, py::arg("memo"),
          "An independent copy of the grid: values, metadata, voxel size and origin.")
      .def("__repr__", [](const vol::Grid& g) {
        const vol::Provenance p = vol::read_provenance(g);
        std::string more;
        if (!p.units.empty()) more += " units=" + p.units;
        if (p.sigma) more += fmt::format(" sigma={:.4g}", *p.sigma);
        return fmt::format("<weft.Grid '{}' voxel_size={} active_voxels={}{}>", g.name(), g.voxel_size(),
                           g.active_voxel_count(), more);
      });
}

}  // namespace weft::python
