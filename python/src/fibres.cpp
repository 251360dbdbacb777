// The fibre ground truth (weft/fibres/fibre_beam.h): fibres as capsules, T_fibre(t) of a beam on
// the voxel beam's ray lattice, and the fibres a weft gen grid was made from.
#include <memory>
#include <optional>
#include <string>

#include "common.h"
#include "data_gen/cloth/grid_fibres.h"
#include "weft/fibres/fibre_beam.h"
#include "weft/volume/beam_checks.h"
#include "weft/volume/voxel_rule.h"

namespace weft::python {
namespace {

namespace vol = weft::volume;
namespace fib = weft::fibres;

/// Fibres held by Python: the polylines, their index (built once) and, for the fibres of a weft
/// gen grid (Fibres.of_grid), the lattice they were voxelized on: a grid given to
/// measure_fibre_beam with them must be on it, as `weft measure --fibres` checks its own grid
/// (docs/validate.md §Fibre ground truth).
struct PyFibres {
  fib::FibreSet set;
  std::shared_ptr<const fib::CapsuleIndex> index;
  std::optional<cloth::VoxelizedLattice> lattice;
  explicit PyFibres(fib::FibreSet s, std::optional<cloth::VoxelizedLattice> l = std::nullopt)
      : set(std::move(s)), index(std::make_shared<fib::CapsuleIndex>(set)), lattice(l) {}
};

std::array<double, 3> direction_arg(const py::object& direction) {
  if (py::isinstance<py::str>(direction)) return vol::parse_direction(direction.cast<std::string>());
  std::array<double, 3> d{};
  try {
    d = direction.cast<std::array<double, 3>>();
  } catch (const py::cast_error&) {
    throw py::type_error("measure_fibre_beam: direction must be 'x', '-z', 'dx,dy,dz' or 3 numbers");
  }
  return vol::unit_direction(d, "measure_fibre_beam");
}

}  // namespace

void init_fibres(py::module_& m) {
  py::class_<PyFibres, std::shared_ptr<PyFibres>>(
      m, "Fibres", "Fibres as capsules (polylines swept by a sphere of their radius), for exact ray intersection.")
      .def(py::init([](const std::vector<std::vector<std::array<double, 3>>>& polylines, const py::object& radius) {
             fib::FibreSet s;
             std::vector<double> r;
             if (py::isinstance<py::float_>(radius) || py::isinstance<py::int_>(radius)) {
               r.assign(polylines.size(), radius.cast<double>());
             } else {
               r = arg_cast<std::vector<double>>(radius, "Fibres: radius", "a number or one number per polyline");
             }
             if (r.size() != polylines.size()) fail("Fibres: {} radii for {} polylines", r.size(), polylines.size());
             for (std::size_t i = 0; i < polylines.size(); ++i) {
               if (polylines[i].empty()) fail("Fibres: polyline {} has no points", i);
               s.add(polylines[i], r[i]);
             }
             return std::make_shared<PyFibres>(std::move(s));
           }),
           py::arg("polylines"), py::arg("radius"),
           "Fibres(polylines, radius): polylines a list of (n, 3) point lists, radius one number or one per "
           "polyline (length units of the points).")
      .def_static(
          "of_grid",
          [](const vol::Grid& grid, const py::object& progress) {
            const std::string what = "grid '" + grid.name() + "'";
            auto set = run_released(
                progress, [&](ProgressSink& p) { return cloth::fibre_geometry(cloth::fibers_of_grid(grid, what, p)); });
            return std::make_shared<PyFibres>(std::move(set), cloth::read_voxelized_lattice(grid, what));
          },
          py::arg("grid"), py::kw_only(), py::arg("progress") = py::none(),
          "The fibres a grid written by weft gen was voxelized from, regenerated from its provenance;\n"
          "weft.Error when the grid does not name its fibres, or is not on the lattice weft gen voxelized them\n"
          "on (moved, resampled or cut since; docs/validate.md, Fibre ground truth). The fibres keep that\n"
          "lattice: measure_fibre_beam refuses a grid not on it.")
      .def("__len__", [](const PyFibres& f) { return f.set.size(); })
      .def_property_readonly("segments", [](const PyFibres& f) { return f.index->capsule_count(); })
      .def_property_readonly(
          "volume", [](const PyFibres& f) { return f.set.volume(); }, "Sum of length * pi r^2 (caps not counted).")
      .def("__repr__", [](const PyFibres& f) {
        return fmt::format("<weft.Fibres {} fibres, {} segments, volume {:.4g}>", f.set.size(),
                           f.index->capsule_count(), f.set.volume());
      });

  m.def(
      "measure_fibre_beam",
      [](const PyFibres& fibres, const py::object& grid, const py::object& direction, const py::object& box,
         double cell, int rays_per_cell, std::uint64_t seed, double depth_step, const py::object& extinction,
         bool full_chords, const py::object& progress) {
        vol::BeamSpec spec;
        spec.direction = direction_arg(direction);
        spec.full_chords = full_chords;
        vol::check_full_chords({spec.direction}, full_chords, FrontEnd::python);
        if (rays_per_cell < 1) fail("measure_fibre_beam: rays_per_cell must be >= 1, got {}", rays_per_cell);
        spec.rays_per_column = rays_per_cell;
        spec.jitter = rays_per_cell > 1;
        spec.seed = seed;
        spec.depth_step = require_non_negative("measure_fibre_beam: depth_step", depth_step);
        const double kappa = extinction.is_none()
                                 ? fib::kOpaque
                                 : arg_cast<double>(extinction, "measure_fibre_beam: extinction", "a number or None");
        if (!grid.is_none()) {
          if (!box.is_none()) fail("measure_fibre_beam: give grid or box, not both");
          const auto& g = arg_cast<const vol::Grid&>(grid, "measure_fibre_beam: grid", "a weft.Grid or None");
          if (fibres.lattice)
            cloth::check_on_lattice(g, *fibres.lattice, fmt::format("measure_fibre_beam: grid '{}'", g.name()));
          vol::check_full_chord_rays(vol::active_world_box(g), g.voxel_size(), spec, FrontEnd::python);
          return run_released(
              progress, [&](ProgressSink& p) { return fib::measure_fibre_beam(*fibres.index, g, spec, kappa, p); });
        }
        vol::WorldBox b = fib::fibre_box(*fibres.index);
        if (!box.is_none()) {
          const auto corners = arg_cast<std::array<std::array<double, 3>, 2>>(
              box, "measure_fibre_beam: box", "two corners ((x0, y0, z0), (x1, y1, z1)) or None");
          b = {corners[0], corners[1]};
        }
        require_positive("measure_fibre_beam: cell (needed without a grid)", cell);
        return run_released(
            progress, [&](ProgressSink& p) { return fib::measure_fibre_beam(*fibres.index, b, cell, spec, kappa, p); });
      },
      py::arg("fibres"), py::arg("grid") = py::none(), py::kw_only(), py::arg("direction") = "z",
      py::arg("box") = py::none(), py::arg("cell") = 0.0, py::arg("rays_per_cell") = 1, py::arg("seed") = 1,
      py::arg("depth_step") = 0.0, py::arg("extinction") = py::none(), py::arg("full_chords") = false,
      py::arg("progress") = py::none(),
      "measure_fibre_beam(fibres, grid=None, direction='z', box=None, cell=0, rays_per_cell=1, seed=1,\n"
      "                   depth_step=0, extinction=None, full_chords=False) -> TransmittanceCurve\n\n"
      "T_fibre(t): the beam's rays intersected exactly with the fibres (docs/validate.md). With a grid:\n"
      "the rays of measure_beam on that grid (its active box, one cell per voxel). Without: box\n"
      "((lo), (hi)) or the fibres' bounds, cells of width `cell`. Fibres of a grid (Fibres.of_grid) take\n"
      "only a grid on the lattice they were voxelized on (weft.Error otherwise). extinction: inside the fibres\n"
      "[1/length]; None = opaque fibres. Same numbers as `weft measure --fibres`.");

  m.def(
      "extinction_grid",
      [](const vol::Grid& grid, double sigma, const std::string& rule) {
        return vol::extinction_grid(grid, sigma, vol::parse_voxel_rule(rule));
      },
      py::arg("grid"), py::arg("sigma"), py::arg("rule") = "opaque",
      "extinction_grid(grid, sigma, rule='opaque') -> Grid of mu: 'linear' sigma*C or 'opaque'\n"
      "-max(sigma, 1/h) ln(1 - C) (docs/validate.md, voxelization error).");
}

}  // namespace weft::python
