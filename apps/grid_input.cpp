#include "grid_input.h"

#include <cmath>
#include <filesystem>
#include <map>
#include <optional>

#include <fmt/core.h>

#include "usage.h"
#include "weft/core/error.h"
#include "weft/core/parse_number.h"

namespace weft::app {

void add_grid_input(CLI::App& sub, GridInputOptions& o, bool required) {
  o.grid_option = sub.add_option("--grid", o.grid,
                                 required ? "Input .vdb grid" : "Use this .vdb grid instead of generating a cloth")
                      ->check(file_name);
  if (required) o.grid_option->required();
  sub.add_option("--grid-name", o.grid_name, "Grid to read from --grid (default: the first float grid)")
      ->needs(o.grid_option);
  sub.add_option("--values", o.values, "Meaning of the grid's values: concentration (mu = sigma*C) or extinction (mu)")
      ->check(CLI::IsMember({"concentration", "extinction"}))
      ->capture_default_str();
  o.sigma_option = sub.add_option(
      "--sigma", o.sigma,
      "Extinction cross-section per unit concentration [1/length]. Default: the grid's provenance (weft gen "
      "records 2/(pi r_fibre), opaque fibres across the beam); a concentration grid without provenance needs it");
}

void check_grid_input(const GridInputOptions& o) {
  if (o.sigma_given()) usage_positive("--sigma", o.sigma);
  if (o.extinction() && o.sigma_given()) usage_fail("--sigma applies to concentration values, not --values extinction");
}

volume::SigmaChoice resolve_sigma(const GridInputOptions& o, const volume::Provenance& p, const std::string& what) {
  return volume::resolve_sigma(p, o.sigma_given() ? std::optional<double>(o.sigma) : std::nullopt, o.extinction(),
                               what);
}

LoadedGrid load_grid_input(const GridInputOptions& o) {
  check_grid_input(o);
  LoadedGrid out;
  out.grid = volume::Grid::load(o.grid, o.grid_name);
  if (out.grid.active_voxel_count() == 0) fail("{}: grid '{}' is empty (no active voxels)", o.grid, out.grid.name());
  try {
    out.provenance = volume::read_provenance(out.grid);
  } catch (const Error& e) {
    fail("{}: {}", o.grid, e.what());
  }
  volume::require_value_kind(out.provenance, o.extinction(), o.grid);
  out.sigma = resolve_sigma(o, out.provenance, o.grid);
  return out;
}

std::string grid_title(const GridInputOptions& o, const volume::Grid& grid) {
  const std::string file = std::filesystem::path(o.grid).filename().string();
  return grid.name() == "density" ? file : fmt::format("{} (grid '{}')", file, grid.name());
}

std::string beams_record_line(const BeamsRecord& r) {
  return fmt::format(
      "# weft measure: sigma={:.17g}; values={}; voxel_size={:.17g}; active_voxels={}; value_sum={:.17g}\n", r.sigma,
      r.values, r.voxel_size, r.active_voxels, r.value_sum);
}

BeamsRecord parse_beams_record(const std::string& line, const std::string& path) {
  const std::string prefix = "# weft measure: ";
  if (line.rfind(prefix, 0) != 0) {
    // Another of weft measure's tables (scatterer.csv, fibres.csv, fields.csv) has a header row
    // where beams.csv has its record line (an older beams.csv starts with its own header, below).
    if (line.rfind("t,", 0) == 0 || (line.rfind("beam,", 0) == 0 && line.rfind("beam,dx,dy,dz,t,T,", 0) != 0))
      fail("{}: not a beams.csv (its first line is a table header, '{}'): give the beams.csv of weft measure's --out",
           path, line.substr(0, 40));
    fail(
        "{}: no '# weft measure: sigma=...' first line (written by an older weft measure or by hand): re-run "
        "weft measure, so the sigma of the curves is known",
        path);
  }
  BeamsRecord r;
  std::map<std::string, std::string> kv;
  std::size_t pos = prefix.size();
  while (pos < line.size()) {
    const std::size_t end = std::min(line.find(';', pos), line.size());
    std::string item = line.substr(pos, end - pos);
    while (!item.empty() && item.front() == ' ') item.erase(item.begin());
    const std::size_t eq = item.find('=');
    if (eq != std::string::npos) kv[item.substr(0, eq)] = item.substr(eq + 1);
    pos = end + 1;
  }
  auto number = [&](const std::string& key) {
    const auto it = kv.find(key);
    if (it == kv.end()) fail("{}: first line has no {}=", path, key);
    const std::optional<double> v = parse_number(it->second);
    if (!v || !std::isfinite(*v)) fail("{}: first line: {}='{}' is not a number", path, key, it->second);
    return *v;
  };
  r.sigma = number("sigma");
  r.voxel_size = number("voxel_size");
  r.active_voxels = static_cast<std::uint64_t>(number("active_voxels"));
  r.value_sum = number("value_sum");
  const auto it = kv.find("values");
  if (it == kv.end()) fail("{}: first line has no values=", path);
  r.values = it->second;
  return r;
}

void check_beams_record(const BeamsRecord& m, const BeamsRecord& now, const std::string& path) {
  auto close = [](double a, double b) { return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b)); };
  if (m.values != now.values) fail("{}: measured on {} values, this run has {}", path, m.values, now.values);
  if (!close(m.sigma, now.sigma)) {
    fail(
        "{}: measured with sigma = {:.6g}, this run uses sigma = {:.6g}; re-measure with the same sigma (log T of a "
        "beam is not linear in sigma)",
        path, m.sigma, now.sigma);
  }
  if (!close(m.voxel_size, now.voxel_size) || m.active_voxels != now.active_voxels ||
      !close(m.value_sum, now.value_sum)) {
    fail("{}: measured on another grid ({} active voxels of {:.6g}, value sum {:.9g}; this grid: {} of {:.6g}, {:.9g})",
         path, m.active_voxels, m.voxel_size, m.value_sum, now.active_voxels, now.voxel_size, now.value_sum);
  }
}

}  // namespace weft::app
