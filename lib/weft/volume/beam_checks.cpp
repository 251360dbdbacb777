#include "weft/volume/beam_checks.h"

#include <algorithm>

#include <fmt/format.h>

#include "weft/core/error.h"
#include "weft/volume/beam.h"

namespace weft::volume {

void check_rays_per_column(const std::vector<std::array<double, 3>>& directions, int rays_per_column, bool jitter,
                           FrontEnd asker) {
  const Spelling rays{"--rays", "rays_per_column"};
  if (rays_per_column < 1) fail("{} must be >= 1, got {}", rays.in(asker), rays_per_column);
  const bool all_axis =
      std::all_of(directions.begin(), directions.end(), [](const auto& d) { return beam_axis(d) >= 0; });
  if (!all_axis || (rays_per_column == 1 && !jitter)) return;
  const Spelling what = rays_per_column > 1 ? Spelling{fmt::format("--rays {}", rays_per_column),
                                                       fmt::format("rays_per_column={}", rays_per_column)}
                                            : Spelling{"--jitter", "jitter=True"};
  const Spelling oblique{"weft measure --direction 1,1,1 --rays N",
                         "weft.measure_beam(grid, direction=(1, 1, 1), rays_per_column=N)"};
  fail(
      "{}: axis beams' rays in one voxel column cross the same voxels, so more rays per column and jitter cannot "
      "change T or its error; drop them, or trace an oblique beam ({})",
      what.in(asker), oblique.in(asker));
}

void check_full_chords(const std::vector<std::array<double, 3>>& directions, bool full_chords, FrontEnd asker) {
  if (!full_chords || directions.empty()) return;
  const bool all_axis =
      std::all_of(directions.begin(), directions.end(), [](const auto& d) { return beam_axis(d) >= 0; });
  if (!all_axis) return;
  const Spelling option{"--full-chords", "full_chords=True"};
  const Spelling every{"every --direction is an axis",
                       fmt::format("the beam runs along {}", direction_label(directions[0]))};
  fail("{} changes oblique beams only (an axis beam's rays all cross the whole box), and {}", option.in(asker),
       every.in(asker));
}

void check_full_chord_rays(const WorldBox& box, double cell, const BeamSpec& spec, FrontEnd asker) {
  const std::string why = full_chord_problem(box, cell, spec);
  if (why.empty()) return;
  const Spelling option{"--full-chords", "full_chords=True"};
  fail("{}: beam {}: {}", option.in(asker), direction_label(spec.direction), why);
}

void check_beam_method(BeamMethod method, const std::vector<std::array<double, 3>>& directions, FrontEnd asker) {
  if (method != BeamMethod::streaming) return;
  for (const auto& d : directions) {
    if (beam_axis(d) >= 0) continue;
    const Spelling streaming{"--method streaming", "method='streaming'"};
    const Spelling direction{"--direction", "direction"};
    const Spelling others{"--method auto or per-ray", "method='auto' or 'per-ray'"};
    fail("{} traces axis beams only, and {} {} is oblique; use {}", streaming.in(asker), direction.in(asker),
         direction_label(d), others.in(asker));
  }
}

}  // namespace weft::volume
