#include "validate_fibres.h"

#include <chrono>

#include <fmt/core.h>

#include "data_gen/cloth/grid_fibres.h"
#include "weft/fibres/fibre_beam.h"

namespace weft::app {

FibreCheck check_against_fibres(const volume::Grid& grid, const fit::Validation& v, std::uint64_t seed,
                                const std::string& what, ProgressSink& progress) {
  const auto t0 = std::chrono::steady_clock::now();
  const fibres::CapsuleIndex index(cloth::fibre_geometry(cloth::fibers_of_grid(grid, what, progress)));
  FibreCheck out;
  out.report = {{"fibres", "opaque"},
                {"source", "regenerated from the grid's weft gen provenance"},
                {"segments", index.capsule_count()},
                {"axes", nlohmann::json::object()}};
  for (const auto& a : v.axes) {
    volume::BeamSpec spec;
    spec.direction = a.direction;
    spec.seed = seed;
    out.curves.push_back(fibres::measure_fibre_beam(index, grid, spec, fibres::kOpaque, progress));
    const auto d = fibres::curve_difference(a.ground_truth, out.curves.back());
    out.report["axes"][a.label] = {{"T_fibre_at_depth_max", d.end_b},
                                   {"T_gt_at_depth_max", d.end_a},
                                   {"rms_T_gt_minus_T_fibre", d.rms},
                                   {"max_abs_T_gt_minus_T_fibre", d.max_abs},
                                   {"rms_stderr_fibre", d.rms_stderr_b}};
    out.summary.push_back(
        fmt::format("fibres {}: T_fibre(end) = {:.4f}, T_gt(end) = {:.4f}; voxelization error RMS "
                    "{:.4f}, max {:.4f}",
                    a.label, d.end_b, d.end_a, d.rms, d.max_abs));
  }
  out.report["seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace weft::app
