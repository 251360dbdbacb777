#pragma once
/// @file
/// @brief Every parameter of the cloth generator: the procedural yarn model of Zhao, Luan and
/// Bala 2016 ("Fitting procedural yarn models for realistic cloth rendering", TOG 35(4)), the
/// weave/knit pattern, the import source and the voxelizer. Lengths are millimetres.

#include <cstdint>
#include <string>
#include <vector>

namespace weft::cloth {

/// @brief Parameters of one procedural yarn (Zhao et al. 2016, §4). Lengths in mm; radial
/// quantities marked "× ply radius" are relative to the ply cross-section.
struct YarnParams {
  std::string preset = "cotton";  ///< the preset these values started from (a name; see yarn_label)
  int ply_count = 2;              ///< plies per yarn, twisted around the yarn axis
  double ply_radius = 0.08;       ///< mm, radius of a ply's (circular) cross-section before ellipse scaling
  double ply_offset = 0.07;       ///< mm, distance of each ply centre from the yarn axis (0 for one ply)
  double ply_pitch = 0.9;         ///< mm per turn of the plies about the yarn axis
  int ply_twist = 1;              ///< +1: plies turn right-handed (Z twist) about the yarn axis, −1: left-handed (S)
  double ellipse_n = 1.0;         ///< ply cross-section semi-axis towards the yarn axis, × ply radius
  double ellipse_b = 0.8;         ///< ply cross-section semi-axis across it, × ply radius
  int fiber_count = 40;           ///< fibres per ply (regular fibres; flyaways come on top)
  double fiber_radius = 0.006;    ///< mm, radius of every fibre
  double fiber_pitch = 1.6;       ///< mm per turn of the fibres about their ply centre (in the turning ply frame)
  int fiber_twist = -1;           ///< −1: fibres turn against the ply twist (balanced yarn), +1: with it
  double density_epsilon = 0.05;  ///< ε of the radial density p(R) ∝ (1−2ε)((e−e^R)/(e−1))^β + ε, in [0, 0.5)
  double density_beta = 0.6;      ///< β of p(R) (≥ 0); larger packs fibres towards the ply centre
  double rho_min = 0.8;           ///< migration: smallest radius of a fibre's path, × its sampled R
  double rho_max = 1.0;           ///< migration: largest radius of a fibre's path, × its sampled R
  double migration_period = 1.2;  ///< mm, period s of the radial migration along the yarn
  double fiber_min_spacing =
      1.0;  ///< minimum centre distance between fibres in a ply cross-section, × fibre diameter (0 = off)
  double loop_density = 2.0;          ///< loop-type flyaways per mm of ply: a fibre's migration cycle pulled out
  double loop_radius_mean = 1.5;      ///< radius a loop reaches, × ply radius (mean of a normal law)
  double loop_radius_sd = 0.2;        ///< standard deviation of the loop radius, × ply radius
  double hair_density = 3.0;          ///< hair-type flyaways (free fibre ends) per mm of ply
  double hair_span_mean = 0.6;        ///< radial distance a hair rises over its length, × ply radius (mean)
  double hair_span_sd = 0.2;          ///< standard deviation of the hair radial span, × ply radius
  double hair_angle_span_mean = 1.0;  ///< radians a hair turns about its ply centre (mean)
  double hair_angle_span_sd = 0.4;    ///< standard deviation of the hair angle span, radians
  double hair_length_mean = 0.25;     ///< mm, axial length of a hair (mean)
  double hair_length_sd = 0.08;       ///< mm, standard deviation of the hair axial length
  double sample_step = 0.02;          ///< mm, spacing of polyline points along every fibre
};

/// @brief One documented numeric field of YarnParams (the single source for JSON, `--help`
/// and docs/cloth.md).
struct YarnField {
  const char* name;
  const char* unit;
  const char* doc;
  bool integer;
  double YarnParams::*real;  ///< set when !integer
  int YarnParams::*whole;    ///< set when integer
};
/// All numeric yarn parameters in declaration order.
const std::vector<YarnField>& yarn_fields();

/// Named presets with plausible values (cotton, polyester, silk, wool, linen).
std::vector<std::string> yarn_preset_names();
/// The preset `name`; throws weft::Error listing the known names otherwise.
YarnParams yarn_preset(const std::string& name);
/// @brief The yarn's label, true to its fields (docs/cloth.md "Presets and explicit fields"): the
/// preset's name when every field has the preset's value, else "wool (modified: fiber_count,
/// ply_radius)" naming the fields that differ from it, in yarn_fields() order.
std::string yarn_label(const YarnParams& yarn);
/// The preset a label names: "wool" for "wool" and for "wool (modified: ...)".
std::string label_preset(const std::string& label);
/// Throws weft::Error naming `where.field` when a parameter is NaN, negative or inconsistent, or
/// the preset is unknown.
void validate(const YarnParams& yarn, const std::string& where);
/// Radius of the yarn's envelope (plies at their largest migration radius), mm; flyaways excluded.
double yarn_envelope_radius(const YarnParams& yarn);

/// @brief The whole generator input; `weft gen` writes it as cloth.json.
struct ClothSpec {
  /// plain, twill21, twill22, twill31, satin5, basket (woven); stockinette (knit); import (curves
  /// from `input`, a .bcc or .obj file).
  std::string pattern = "plain";
  int warp_count = 4;         ///< woven: warp yarns (along x); knit: courses (rows along x)
  int weft_count = 4;         ///< woven: weft yarns (along y); knit: wales (stitches per course)
  double warp_spacing = 0.0;  ///< mm between warp centrelines (knit: course spacing); 0 = from the yarn envelope
  double weft_spacing = 0.0;  ///< mm between weft centrelines (knit: wale spacing); 0 = from the yarn envelope
  double crimp = 0.0;  ///< mm, half the over/under height of the weave (knit: loop depth); 0 = from the yarn envelopes
  YarnParams warp_yarn;        ///< yarn of the warp (and of knit and imported curves)
  YarnParams weft_yarn;        ///< yarn of the weft
  std::string input;           ///< import: path of a .bcc or .obj file of yarn centrelines
  double input_scale = 1.0;    ///< import: factor from the file's units to mm
  double voxel_size = 0.01;    ///< mm, edge of a cubic voxel
  int samples_per_voxel = 4;   ///< voxelizer quadrature points per voxel edge (along and across a fibre)
  double max_memory_mb = 0.0;  ///< refuse voxelizations estimated above this (MiB); 0 = half the RAM
  std::uint64_t seed = 1;      ///< run seed; same seed, same cloth, whatever the thread count
  /// The cloth.json the values came from (`weft gen --config`), "" if none: named by the
  /// estimate's refusals beside the options, never written to cloth.json.
  std::string config;
};

/// Names accepted by ClothSpec::pattern.
std::vector<std::string> pattern_names();
/// The pattern a name stands for: the aliases twill, satin, knit are twill22, satin5, stockinette
/// (the commonest member of each family); any other name is itself. What resolve() stores and
/// every report names a cloth by, so an alias and its pattern are one cloth.
std::string canonical_pattern(const std::string& name);
/// Replaces the 0 = automatic spacings and crimp by their derived values and the pattern
/// aliases twill, satin, knit by twill22, satin5, stockinette (idempotent).
ClothSpec resolve(ClothSpec spec);
/// The voxelizer's bound on |voxel index| (its leaf keys hold 21 bits an axis, voxelize.cpp): a
/// cloth reaching kMaxVoxelIndex · voxel_size mm from the origin cannot be voxelized.
inline constexpr std::int64_t kMaxVoxelIndex = 1LL << 22;

/// The most yarns of one direction a cloth takes (warp_count, weft_count).
inline constexpr int kMaxYarnCount = 100000;
/// Throws weft::Error naming the parameter and its valid range when any value is NaN, negative,
/// out of range or unknown: voxel_size below volume::min_voxel_size, or a woven or knit cloth
/// that check_cloth_extent refuses. Best called before resolve: a spacing or crimp still 0 is
/// known to be automatic, and the yarn fields behind it are named instead.
void validate(const ClothSpec& spec);
/// Throws weft::Error when a woven or knit cloth reaches kMaxVoxelIndex voxels from the origin
/// (naming a given spacing or crimp, or, for an automatic one or a yarn wider than them, the yarn
/// radius and its fields, with the radius and the voxel_size that would fit), or when voxel_size
/// is not below the cloth's longest side (require_voxel_within). `spec` resolved or not.
void check_cloth_extent(const ClothSpec& spec);
/// Throws weft::Error unless `voxel_size` < `longest`, the longest side (mm) of `what`'s box: a
/// voxel that holds a whole cloth is no grid of it.
void require_voxel_within(const std::string& what, double longest, double voxel_size);
/// Parses cloth.json text; `where` names the source in errors. A yarn object's "preset" fills the
/// fields it does not give and explicit fields override it (the label is then recomputed,
/// yarn_label); a yarn that gives every field, all another preset's, under a preset's name is a
/// weft::Error naming both presets (docs/cloth.md "Presets and explicit fields").
ClothSpec cloth_spec_from_json(const std::string& text, const std::string& where);

}  // namespace weft::cloth
