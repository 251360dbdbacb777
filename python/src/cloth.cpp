// The cloth generator (data_gen/cloth): a spec (JSON text of a dict) -> fibres and voxel grid.
#include <string>

#include "common.h"
#include "data_gen/cloth/cloth.h"

namespace weft::python {
namespace {

namespace cl = weft::cloth;

py::dict fibers_dict(const cl::FiberSet& f) {
  py::dict d;
  py::array_t<double> points({static_cast<py::ssize_t>(f.points.size()), py::ssize_t{3}});
  double* p = points.mutable_data();
  for (std::size_t i = 0; i < f.points.size(); ++i) {
    for (std::size_t c = 0; c < 3; ++c) p[3 * i + c] = f.points[i][c];
  }
  d["points"] = points;
  // int64, not uint64: numpy index arithmetic (offsets - 1) stays integral.
  d["offsets"] = to_array(std::vector<std::int64_t>(f.offsets.begin(), f.offsets.end()));
  d["radius"] = to_array(f.radius);
  d["yarn"] = to_array(f.yarn);
  d["ply"] = to_array(f.ply);
  d["fiber"] = to_array(f.fiber);
  std::vector<std::int32_t> kind;
  kind.reserve(f.kind.size());
  for (auto k : f.kind) kind.push_back(static_cast<std::int32_t>(k));
  d["kind"] = to_array(kind);
  return d;
}

py::dict report_dict(const cl::VoxelizeReport& r) {
  py::dict d;
  d["fiber_volume"] = r.fiber_volume;
  d["grid_volume"] = r.grid_volume;
  d["relative_error"] = r.relative_error;
  d["overlap_fraction"] = r.overlap_fraction;
  d["active_voxels"] = r.active_voxels;
  d["fiber_count"] = r.fiber_count;
  d["generate_seconds"] = r.generate_seconds;
  d["voxelize_seconds"] = r.voxelize_seconds;
  return d;
}

}  // namespace

void init_cloth(py::module_& m) {
  m.def(
      "_gen_json",
      [](const std::optional<std::string>& spec_json, const py::object& progress) {
        // No spec: the default cloth of `weft gen`; otherwise what `weft gen --config` reads.
        cl::ClothSpec spec = spec_json ? cl::cloth_spec_from_json(*spec_json, "gen spec") : cl::default_cloth_spec();
        spec = cl::resolve(spec);
        cl::validate(spec);
        auto build =
            run_released(progress, [&](ProgressSink& p) { return cl::build_cloth(spec, p, false, FrontEnd::python); });
        warn_all(cl::cloth_warnings(build, FrontEnd::python), "weft.gen");
        py::dict out;
        out["grid"] = py::cast(std::move(build.grid));
        out["fibers"] = fibers_dict(build.fibers);
        out["report"] = report_dict(build.report);
        out["spec_json"] = cl::cloth_spec_json(build.spec);
        return out;
      },
      py::arg("spec_json"), py::arg("progress") = py::none());
  m.def("pattern_names", &cl::pattern_names, "Weave and knit patterns of the generator.");
  m.def("yarn_preset_names", &cl::yarn_preset_names, "Yarn presets (cotton, polyester, ...).");
  m.def(
      "default_cloth_spec", [] { return cl::cloth_spec_json(cl::default_cloth_spec()); },
      "The default cloth of `weft gen` as JSON text (json.loads gives the dict weft.gen takes).");
}

}  // namespace weft::python
