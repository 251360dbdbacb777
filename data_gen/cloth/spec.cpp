#include "data_gen/cloth/spec.h"

#include "data_gen/cloth/cloth.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string_view>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "weft/core/error.h"
#include "weft/core/file_kind.h"
#include "weft/core/json_input.h"
#include "weft/core/number_name.h"
#include "weft/volume/grid.h"

namespace weft::cloth {
namespace {

using json = nlohmann::json;

YarnField real(const char* name, const char* unit, const char* doc, double YarnParams::*member) {
  return YarnField{name, unit, doc, false, member, nullptr};
}
YarnField whole(const char* name, const char* unit, const char* doc, int YarnParams::*member) {
  return YarnField{name, unit, doc, true, nullptr, member};
}

}  // namespace

const std::vector<YarnField>& yarn_fields() {
  static const std::vector<YarnField> fields = {
      whole("ply_count", "1", "plies per yarn, twisted around the yarn axis", &YarnParams::ply_count),
      real("ply_radius", "mm", "radius of a ply cross-section before ellipse scaling", &YarnParams::ply_radius),
      real("ply_offset", "mm", "distance of each ply centre from the yarn axis", &YarnParams::ply_offset),
      real("ply_pitch", "mm", "length of one turn of the plies about the yarn axis", &YarnParams::ply_pitch),
      whole("ply_twist", "+1/-1", "handedness of the ply twist: +1 Z (right-handed), -1 S", &YarnParams::ply_twist),
      real("ellipse_n", "x ply radius", "ply cross-section semi-axis pointing at the yarn axis",
           &YarnParams::ellipse_n),
      real("ellipse_b", "x ply radius", "ply cross-section semi-axis across it", &YarnParams::ellipse_b),
      whole("fiber_count", "1", "regular fibres per ply", &YarnParams::fiber_count),
      real("fiber_radius", "mm", "fibre radius", &YarnParams::fiber_radius),
      real("fiber_pitch", "mm", "length of one turn of the fibres about their ply centre, in the ply frame",
           &YarnParams::fiber_pitch),
      whole("fiber_twist", "+1/-1", "fibre twist against (-1) or with (+1) the ply twist", &YarnParams::fiber_twist),
      real("density_epsilon", "1", "epsilon of p(R) ~ (1-2e)((e-exp R)/(e-1))^beta + e, in [0, 0.5)",
           &YarnParams::density_epsilon),
      real("density_beta", "1", "beta of p(R), >= 0 (larger: denser core)", &YarnParams::density_beta),
      real("rho_min", "x R", "migration: smallest radius of a fibre's path", &YarnParams::rho_min),
      real("rho_max", "x R", "migration: largest radius of a fibre's path", &YarnParams::rho_max),
      real("migration_period", "mm", "period s of the radial migration", &YarnParams::migration_period),
      real("fiber_min_spacing", "x fibre diameter", "minimum distance of fibre centres in a ply cross-section (0: off)",
           &YarnParams::fiber_min_spacing),
      real("loop_density", "1/mm", "loop-type flyaways per mm of ply (each pulls out a regular fibre, adds none)",
           &YarnParams::loop_density),
      real("loop_radius_mean", "x ply radius", "mean radius a loop flyaway reaches", &YarnParams::loop_radius_mean),
      real("loop_radius_sd", "x ply radius", "standard deviation of the loop radius", &YarnParams::loop_radius_sd),
      real("hair_density", "1/mm", "hair-type flyaways per mm of ply", &YarnParams::hair_density),
      real("hair_span_mean", "x ply radius", "mean radial rise of a hair flyaway", &YarnParams::hair_span_mean),
      real("hair_span_sd", "x ply radius", "standard deviation of the hair radial rise", &YarnParams::hair_span_sd),
      real("hair_angle_span_mean", "rad", "mean turn of a hair about its ply centre",
           &YarnParams::hair_angle_span_mean),
      real("hair_angle_span_sd", "rad", "standard deviation of the hair turn", &YarnParams::hair_angle_span_sd),
      real("hair_length_mean", "mm", "mean axial length of a hair", &YarnParams::hair_length_mean),
      real("hair_length_sd", "mm", "standard deviation of the hair length", &YarnParams::hair_length_sd),
      real("sample_step", "mm", "spacing of polyline points along the fibres", &YarnParams::sample_step),
  };
  return fields;
}

std::vector<std::string> yarn_preset_names() { return {"cotton", "polyester", "silk", "wool", "linen"}; }

// Plausible values in the range of the fits of Zhao et al. 2016 (Table 2) rescaled to mm;
// staple fibres (cotton, wool, linen) are hairy, filament yarns (polyester, silk) nearly not.
YarnParams yarn_preset(const std::string& name) {
  YarnParams y;  // the defaults are cotton
  y.preset = name;
  if (name == "cotton") return y;
  if (name == "polyester") {
    y.ply_count = 3;
    y.ply_radius = 0.06;
    y.ply_offset = 0.065;
    y.ply_pitch = 1.2;
    y.ellipse_n = 1.0;
    y.ellipse_b = 0.9;
    y.fiber_count = 36;
    y.fiber_radius = 0.0065;
    y.fiber_pitch = 3.0;
    y.density_epsilon = 0.1;
    y.density_beta = 0.3;
    y.rho_min = 0.9;
    y.migration_period = 2.0;
    y.loop_density = 0.4;
    y.hair_density = 0.2;
    return y;
  }
  if (name == "silk") {
    y.ply_count = 2;
    y.ply_radius = 0.05;
    y.ply_offset = 0.04;
    y.ply_pitch = 1.5;
    y.ellipse_n = 1.0;
    y.ellipse_b = 0.7;
    y.fiber_count = 50;
    y.fiber_radius = 0.004;
    y.fiber_pitch = 4.0;
    y.density_epsilon = 0.15;
    y.density_beta = 0.2;
    y.rho_min = 0.95;
    y.migration_period = 3.0;
    y.loop_density = 0.2;
    y.hair_density = 0.1;
    return y;
  }
  if (name == "wool") {
    y.ply_count = 2;
    y.ply_radius = 0.11;
    y.ply_offset = 0.09;
    y.ply_pitch = 1.4;
    y.ellipse_n = 1.0;
    y.ellipse_b = 0.85;
    y.fiber_count = 45;
    y.fiber_radius = 0.0095;
    y.fiber_pitch = 2.2;
    y.density_epsilon = 0.05;
    y.density_beta = 0.8;
    y.rho_min = 0.7;
    y.migration_period = 1.0;
    y.loop_density = 4.0;
    y.loop_radius_mean = 1.7;
    y.hair_density = 6.0;
    y.hair_span_mean = 0.9;
    y.hair_length_mean = 0.35;
    return y;
  }
  if (name == "linen") {
    y.ply_count = 1;
    y.ply_radius = 0.12;
    y.ply_offset = 0.0;
    y.ply_pitch = 2.0;
    y.ellipse_n = 1.0;
    y.ellipse_b = 0.75;
    y.fiber_count = 70;
    y.fiber_radius = 0.0075;
    y.fiber_pitch = 2.5;
    y.density_epsilon = 0.08;
    y.density_beta = 0.5;
    y.rho_min = 0.85;
    y.migration_period = 1.5;
    y.loop_density = 1.0;
    y.hair_density = 2.0;
    return y;
  }
  std::string names;
  for (const auto& n : yarn_preset_names()) names += (names.empty() ? "" : ", ") + n;
  fail("unknown yarn preset '{}' (known: {})", name, names);
}

namespace {

bool same_value(const YarnField& f, const YarnParams& a, const YarnParams& b) {
  return f.integer ? a.*(f.whole) == b.*(f.whole) : a.*(f.real) == b.*(f.real);
}

std::string field_value(const YarnField& f, const YarnParams& y) {
  return f.integer ? fmt::format("{}", y.*(f.whole)) : fmt::format("{}", y.*(f.real));
}

constexpr std::string_view kModified = " (modified: ";

}  // namespace

std::string yarn_label(const YarnParams& y) {
  const YarnParams preset = yarn_preset(y.preset);
  std::string changed;
  for (const auto& f : yarn_fields()) {
    if (!same_value(f, y, preset)) changed += (changed.empty() ? "" : ", ") + std::string(f.name);
  }
  return changed.empty() ? y.preset : fmt::format("{}{}{})", y.preset, kModified, changed);
}

std::string label_preset(const std::string& label) {
  const auto at = label.find(kModified);
  return at != std::string::npos && label.ends_with(')') ? label.substr(0, at) : label;
}

void validate(const YarnParams& y, const std::string& where) {
  try {
    static_cast<void>(yarn_preset(y.preset));
  } catch (const Error& e) {
    fail("{}.preset: {}", where, e.what());
  }
  const auto is = [&](const char* field) { return fmt::format("{}.{}", where, field); };
  const auto positive = [&](const char* field, double v) {
    if (!std::isfinite(v) || !(v > 0.0)) fail("{} must be finite and > 0, got {}", is(field), v);
  };
  const auto non_negative = [&](const char* field, double v) {
    if (!std::isfinite(v) || !(v >= 0.0)) fail("{} must be finite and >= 0, got {}", is(field), v);
  };
  if (y.ply_count < 1 || y.ply_count > 64) fail("{} must be in [1, 64], got {}", is("ply_count"), y.ply_count);
  if (y.fiber_count < 1 || y.fiber_count > 100000) {
    fail("{} must be in [1, 100000], got {}", is("fiber_count"), y.fiber_count);
  }
  positive("ply_radius", y.ply_radius);
  non_negative("ply_offset", y.ply_offset);
  positive("ply_pitch", y.ply_pitch);
  if (y.ply_twist != 1 && y.ply_twist != -1) fail("{} must be +1 or -1, got {}", is("ply_twist"), y.ply_twist);
  if (y.fiber_twist != 1 && y.fiber_twist != -1) fail("{} must be +1 or -1, got {}", is("fiber_twist"), y.fiber_twist);
  positive("ellipse_n", y.ellipse_n);
  positive("ellipse_b", y.ellipse_b);
  positive("fiber_radius", y.fiber_radius);
  positive("fiber_pitch", y.fiber_pitch);
  non_negative("density_epsilon", y.density_epsilon);
  if (y.density_epsilon >= 0.5) fail("{} must be < 0.5, got {}", is("density_epsilon"), y.density_epsilon);
  non_negative("density_beta", y.density_beta);
  positive("rho_min", y.rho_min);
  positive("rho_max", y.rho_max);
  if (y.rho_min > y.rho_max)
    fail("{} ({}) must not exceed {} ({})", is("rho_min"), y.rho_min, is("rho_max"), y.rho_max);
  positive("migration_period", y.migration_period);
  non_negative("fiber_min_spacing", y.fiber_min_spacing);
  non_negative("loop_density", y.loop_density);
  non_negative("loop_radius_mean", y.loop_radius_mean);
  non_negative("loop_radius_sd", y.loop_radius_sd);
  non_negative("hair_density", y.hair_density);
  non_negative("hair_span_mean", y.hair_span_mean);
  non_negative("hair_span_sd", y.hair_span_sd);
  require_finite(is("hair_angle_span_mean").c_str(), y.hair_angle_span_mean);
  non_negative("hair_angle_span_sd", y.hair_angle_span_sd);
  positive("hair_length_mean", y.hair_length_mean);
  non_negative("hair_length_sd", y.hair_length_sd);
  positive("sample_step", y.sample_step);
}

double yarn_envelope_radius(const YarnParams& y) {
  return y.ply_offset + y.ply_radius * std::max(y.ellipse_n, y.ellipse_b) * y.rho_max;
}

std::vector<std::string> pattern_names() {
  return {"plain", "twill21", "twill22", "twill31", "satin5", "basket", "stockinette", "import"};
}

// Short names: the commonest member of each family.
std::string canonical_pattern(const std::string& name) {
  if (name == "twill") return "twill22";
  if (name == "satin") return "satin5";
  if (name == "knit") return "stockinette";
  return name;
}

ClothSpec resolve(ClothSpec spec) {
  spec.pattern = canonical_pattern(spec.pattern);
  const double rw = yarn_envelope_radius(spec.warp_yarn);
  const double rf = yarn_envelope_radius(spec.weft_yarn);
  if (spec.pattern == "stockinette") {
    // Knit (pattern.cpp): course spacing 8 r, wale spacing 6.5 r and loop depth 1.8 r keep the
    // centrelines of interlocked loops ≥ 2.19 r apart (checked numerically over the loop shape).
    if (spec.warp_spacing == 0.0) spec.warp_spacing = 8.0 * rw;
    if (spec.weft_spacing == 0.0) spec.weft_spacing = 6.5 * rw;
    if (spec.crimp == 0.0) spec.crimp = 1.8 * rw;
    return spec;
  }
  // Woven: with the cosine-eased crimp profile (pattern.cpp), spacing 1.8·(r_warp + r_weft) and
  // crimp 0.6·(r_warp + r_weft) keep a warp and a weft centreline ≥ 1.03·(r_warp + r_weft) apart
  // everywhere around a crossing, not only at it (checked numerically; the tighter the spacing,
  // the more the eased centrelines cut the corner around the crossing yarn).
  if (spec.warp_spacing == 0.0) spec.warp_spacing = 1.8 * (rw + rf);
  if (spec.weft_spacing == 0.0) spec.weft_spacing = 1.8 * (rw + rf);
  if (spec.crimp == 0.0) spec.crimp = 0.6 * (rw + rf);
  return spec;
}

void validate(const ClothSpec& spec) {
  validate(spec.warp_yarn, "warp_yarn");
  validate(spec.weft_yarn, "weft_yarn");
  const auto names = pattern_names();
  if (std::find(names.begin(), names.end(), canonical_pattern(spec.pattern)) == names.end()) {
    std::string list;
    for (const auto& n : names) list += (list.empty() ? "" : ", ") + n;
    fail("pattern: unknown pattern '{}' (known: {})", spec.pattern, list);
  }
  if (spec.warp_count < 1 || spec.warp_count > kMaxYarnCount)
    fail("warp_count must be in [1, {}], got {}", kMaxYarnCount, spec.warp_count);
  if (spec.weft_count < 1 || spec.weft_count > kMaxYarnCount)
    fail("weft_count must be in [1, {}], got {}", kMaxYarnCount, spec.weft_count);
  require_non_negative("warp_spacing", spec.warp_spacing);
  require_non_negative("weft_spacing", spec.weft_spacing);
  require_non_negative("crimp", spec.crimp);
  if (canonical_pattern(spec.pattern) == "import" && spec.input.empty()) {
    fail("input: pattern 'import' needs an input file (.bcc or .obj)");
  }
  require_positive("input_scale", spec.input_scale);
  require_positive("voxel_size", spec.voxel_size);
  // The grid's voxel: OpenVDB represents none smaller (volume::min_voxel_size), and a voxel that
  // holds the whole cloth is no picture of it (the longest side, below and in pattern.cpp).
  if (spec.voxel_size < volume::min_voxel_size()) {
    fail("voxel_size {} mm is below the smallest voxel OpenVDB represents: voxel_size must be >= {} mm",
         spec.voxel_size, bound_text(volume::min_voxel_size(), BoundSide::at_least));
  }
  if (spec.samples_per_voxel < 1 || spec.samples_per_voxel > 64) {
    fail("samples_per_voxel must be in [1, 64], got {}", spec.samples_per_voxel);
  }
  require_non_negative("max_memory_mb", spec.max_memory_mb);
  if (canonical_pattern(spec.pattern) == "import") return;  // the curves are checked as read (pattern.cpp)
  check_cloth_extent(spec);
}

void check_cloth_extent(const ClothSpec& given) {
  // A woven or knit cloth spans count x spacing along x and y (a knit course 1.5 spacings more)
  // and +-crimp along z (pattern.cpp), each plus a yarn radius: each must stay inside the
  // voxelizer's index range, said here with the input that sets it, before the estimate turns a
  // far cloth into an overflow of counts. A spacing or crimp left at 0 is a multiple of the yarn
  // radius (resolve), so then the yarn's fields are what to change, not the spacing or crimp.
  const ClothSpec spec = resolve(given);
  const bool knit = spec.pattern == "stockinette";
  const double rw = yarn_envelope_radius(spec.warp_yarn);
  const double rf = yarn_envelope_radius(spec.weft_yarn);
  const bool warp_widest = knit || rw >= rf;  // a knit has only the warp's yarn
  const double radius = warp_widest ? rw : rf;
  const double h = spec.voxel_size;
  const double reach = static_cast<double>(kMaxVoxelIndex) * h;
  struct Axis {
    std::string what;  // the input that places the yarns along it
    double placement;  // mm from the origin to the farthest centreline
    bool automatic;    // a multiple of the yarn radius (resolve)
    std::string knob;  // the field a user sets for it
    double per;        // placement = per x knob
    [[nodiscard]] double fixed() const { return automatic ? 0.0 : placement; }  // what no yarn change moves
  };
  const auto rule = [&](bool automatic, double knit_factor, const char* woven) {
    if (!automatic) return std::string();
    return knit ? fmt::format(" ({} x the yarn radius)", knit_factor) : fmt::format(" ({})", woven);
  };
  const bool auto_crimp = given.crimp == 0.0;
  const bool auto_weft = given.weft_spacing == 0.0;
  const bool auto_warp = given.warp_spacing == 0.0;
  const std::vector<Axis> axes = {
      {fmt::format("crimp {:g} mm", spec.crimp) + rule(auto_crimp, 1.8, "0.6 x the warp and weft yarn radii"),
       spec.crimp, auto_crimp, "crimp", 1.0},
      {fmt::format("weft_count x weft_spacing ({} x {:g} mm)", spec.weft_count, spec.weft_spacing) +
           rule(auto_weft, 6.5, "1.8 x the warp and weft yarn radii"),
       spec.weft_count * spec.weft_spacing, auto_weft, "weft_spacing", static_cast<double>(spec.weft_count)},
      {fmt::format("warp_count x warp_spacing ({} x {:g} mm)", spec.warp_count, spec.warp_spacing) +
           rule(auto_warp, 8.0, "1.8 x the warp and weft yarn radii"),
       (spec.warp_count + 1.5) * spec.warp_spacing, auto_warp, "warp_spacing", spec.warp_count + 1.5},
  };
  // The farthest axis is named; the bounds given hold for every axis.
  const Axis* worst = &axes[0];
  const Axis* worst_given = nullptr;  // the farthest one past the range whose input was given
  double h_needed = 0.0;
  double radius_fits = std::numeric_limits<double>::infinity();
  for (const Axis& a : axes) {
    const double far = a.placement + radius;
    if (far > worst->placement + radius) worst = &a;
    h_needed = std::max(h_needed, far / static_cast<double>(kMaxVoxelIndex));
    if (far >= reach) radius_fits = std::min(radius_fits, radius * (reach - a.fixed()) / (far - a.fixed()));
    if (!a.automatic && far >= reach && (worst_given == nullptr || a.placement > worst_given->placement))
      worst_given = &a;
  }
  const double far = worst->placement + radius;
  if (far >= reach) {
    const std::string range =
        fmt::format("past the voxel index range +-{} at voxel_size {} mm (+-{:.3g} mm)", kMaxVoxelIndex, h, reach);
    const std::string coarser = bound_text(h_needed, BoundSide::at_least);
    // A given crimp or spacing is named with its own bound (what keeps its side, with the yarn's
    // radius on top, inside the range), unless the radius alone is past it.
    if (worst_given != nullptr && reach - radius > 0.0) {
      fail(
          "{} puts the yarns {:.6g} mm from the origin (with the yarn radius {:.3g} mm), {}: {} must be below {} mm "
          "here, or voxel_size above {} mm",
          worst_given->what, worst_given->placement + radius, radius, range, worst_given->knob,
          bound_text((reach - radius) / worst_given->per, BoundSide::at_most), coarser);
    }
    const YarnParams& y = warp_widest ? spec.warp_yarn : spec.weft_yarn;
    // The radius is a sum of the yarn's fields: its bound also said for the ply radius, the field a
    // user sets, at the ply offset given.
    const double per_ply = std::max(y.ellipse_n, y.ellipse_b) * y.rho_max;
    const double ply_fits = (radius_fits - y.ply_offset) / per_ply;
    const std::string ply_bound =
        ply_fits > 0.0 ? fmt::format("ply_radius below {} at this ply_offset", bound_text(ply_fits, BoundSide::at_most))
                       : std::string("ply_offset alone is past it");
    fail(
        "the {} radius {:.6g} mm (ply_offset {:g} + ply_radius {:g} x max(ellipse_n {:g}, ellipse_b {:g}) x rho_max "
        "{:g}) puts the yarns {:.3g} mm from the origin through {}{}, {}: the yarn radius must be below {} mm "
        "here ({}), or voxel_size above {} mm",
        warp_widest ? "warp_yarn" : "weft_yarn", radius, y.ply_offset, y.ply_radius, y.ellipse_n, y.ellipse_b,
        y.rho_max, far, worst->automatic ? "the automatic " : "", worst->what, range,
        bound_text(radius_fits, BoundSide::at_most), ply_bound, coarser);
  }
  // The longest side of the cloth's box, yarn surfaces included: the largest voxel worth a grid.
  const double longest =
      std::max({spec.weft_count * spec.weft_spacing, (spec.warp_count + 1.5) * spec.warp_spacing, 2.0 * spec.crimp}) +
      2.0 * radius;
  require_voxel_within("the cloth", longest, h);
}

void require_voxel_within(const std::string& what, double longest, double voxel_size) {
  if (voxel_size < longest) return;
  fail(
      "voxel_size {} mm holds all of {} ({:.3g} mm along its longest side) in one voxel: voxel_size must be < {:.3g} "
      "mm",
      voxel_size, what, longest, longest);
}

namespace {

json yarn_to_json(const YarnParams& y) {
  json j;
  j["preset"] = yarn_label(y);
  for (const auto& f : yarn_fields()) {
    if (f.integer) {
      j[f.name] = y.*(f.whole);
    } else {
      j[f.name] = y.*(f.real);
    }
  }
  return j;
}

double number(const json& j, const std::string& where) {
  if (!j.is_number()) fail("{}: expected a number, got {}", where, j.dump());
  return j.get<double>();
}

int integer(const json& j, const std::string& where) {
  if (!j.is_number_integer()) fail("{}: expected an integer, got {}", where, j.dump());
  const auto v = j.get<std::int64_t>();
  if (v < -1000000000 || v > 1000000000) fail("{}: integer {} out of range", where, v);
  return static_cast<int>(v);
}

// A yarn that gives every field leaves its preset nothing to fill, so there the preset is only
// a name; when the fields are all another preset's, the name was changed and not the yarn, and
// "wool (modified: <every field>)" would hide that the yarn is cotton: refused, naming both
// (docs/cloth.md "Presets and explicit fields"). Any other edit is recorded by yarn_label.
void check_renamed_preset(const YarnParams& y, const std::string& label, const std::string& where) {
  if (label != y.preset) return;
  for (const auto& other : yarn_preset_names()) {
    YarnParams as_other = y;
    as_other.preset = other;
    if (other == y.preset || yarn_label(as_other) != other) continue;
    const YarnParams named = yarn_preset(y.preset);
    std::string diffs;
    int count = 0;
    for (const auto& f : yarn_fields()) {
      if (same_value(f, y, named)) continue;
      if (++count <= 3) {
        diffs += fmt::format("{}{} {}, {}'s {}", diffs.empty() ? "" : "; ", f.name, field_value(f, y), y.preset,
                             field_value(f, named));
      }
    }
    if (count > 3) diffs += fmt::format("; and {} more", count - 3);
    fail(
        "{}.preset: '{}', but every field is {}'s ({}): a preset fills only the fields a yarn does not give; "
        "for {} give the preset alone (with just the fields to change), for {} name it '{}'",
        where, label, other, diffs, y.preset, other, other);
  }
}

YarnParams yarn_from_json(const json& j, const std::string& where) {
  if (!j.is_object()) fail("{}: expected an object", where);
  YarnParams y;
  std::string label;
  if (j.contains("preset")) {
    if (!j["preset"].is_string()) fail("{}.preset: expected a string", where);
    label = j["preset"].get<std::string>();
    try {
      y = yarn_preset(label_preset(label));
    } catch (const Error& e) {
      fail("{}.preset: {}", where, e.what());
    }
  }
  std::size_t given = 0;
  for (auto it = j.begin(); it != j.end(); ++it) {
    if (it.key() == "preset") continue;
    const auto& fields = yarn_fields();
    const auto f = std::find_if(fields.begin(), fields.end(), [&](const YarnField& x) { return it.key() == x.name; });
    if (f == fields.end()) fail("{}.{}: unknown yarn parameter", where, it.key());
    const std::string at = where + "." + it.key();
    if (f->integer) {
      y.*(f->whole) = integer(it.value(), at);
    } else {
      y.*(f->real) = number(it.value(), at);
    }
    ++given;
  }
  if (!label.empty() && given == yarn_fields().size()) check_renamed_preset(y, label, where);
  return y;
}

}  // namespace

std::string cloth_spec_json(const ClothSpec& spec) {
  json j;
  j["generator"] = "weft gen (Zhao-Luan-Bala 2016 procedural yarns)";
  j["units"] = "mm";
  j["pattern"] = spec.pattern;
  j["warp_count"] = spec.warp_count;
  j["weft_count"] = spec.weft_count;
  j["warp_spacing"] = spec.warp_spacing;
  j["weft_spacing"] = spec.weft_spacing;
  j["crimp"] = spec.crimp;
  j["warp_yarn"] = yarn_to_json(spec.warp_yarn);
  j["weft_yarn"] = yarn_to_json(spec.weft_yarn);
  j["input"] = spec.input;
  j["input_scale"] = spec.input_scale;
  j["voxel_size"] = spec.voxel_size;
  j["samples_per_voxel"] = spec.samples_per_voxel;
  j["max_memory_mb"] = spec.max_memory_mb;
  j["seed"] = spec.seed;
  return j.dump(2) + "\n";
}

ClothSpec cloth_spec_from_json(const std::string& text, const std::string& where) {
  json j = parse_json_input(text, where);
  if (!j.is_object()) fail("{}: expected a JSON object", where);
  ClothSpec spec;
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string& k = it.key();
    const std::string at = fmt::format("{}: {}", where, k);
    const json& v = it.value();
    if (k == "generator" || k == "units") {
      if (k == "units" && v != "mm") fail("{}: only \"mm\" is supported, got {}", at, v.dump());
    } else if (k == "pattern") {
      if (!v.is_string()) fail("{}: expected a string", at);
      spec.pattern = v.get<std::string>();
    } else if (k == "warp_count") {
      spec.warp_count = integer(v, at);
    } else if (k == "weft_count") {
      spec.weft_count = integer(v, at);
    } else if (k == "warp_spacing") {
      spec.warp_spacing = number(v, at);
    } else if (k == "weft_spacing") {
      spec.weft_spacing = number(v, at);
    } else if (k == "crimp") {
      spec.crimp = number(v, at);
    } else if (k == "warp_yarn") {
      spec.warp_yarn = yarn_from_json(v, at);
    } else if (k == "weft_yarn") {
      spec.weft_yarn = yarn_from_json(v, at);
    } else if (k == "input") {
      if (!v.is_string()) fail("{}: expected a string", at);
      spec.input = v.get<std::string>();
    } else if (k == "input_scale") {
      spec.input_scale = number(v, at);
    } else if (k == "voxel_size") {
      spec.voxel_size = number(v, at);
    } else if (k == "samples_per_voxel") {
      spec.samples_per_voxel = integer(v, at);
    } else if (k == "max_memory_mb") {
      spec.max_memory_mb = number(v, at);
    } else if (k == "seed") {
      // A whole number past 64 bits reaches here as a double: said as out of range, not as no integer.
      if (v.is_number_float() && v.get<double>() >= 0x1p64 && v.get<double>() == std::floor(v.get<double>()))
        fail("{}: must be <= {}, got {}", at, std::numeric_limits<std::uint64_t>::max(), v.dump());
      if (!v.is_number_unsigned()) fail("{}: expected a non-negative integer", at);
      spec.seed = v.get<std::uint64_t>();
    } else {
      fail("{}: unknown parameter", at);
    }
  }
  try {
    validate(spec);
  } catch (const Error& e) {
    fail("{}: {}", where, e.what());
  }
  return spec;
}

}  // namespace weft::cloth
