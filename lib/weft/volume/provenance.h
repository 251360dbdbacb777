#pragma once
/// @file
/// @brief What a grid's metadata says about the medium it holds: units, the physical extinction
/// cross-section σ per unit concentration, and the yarn scale (docs/validate.md, "σ: physical by default").
///
/// `weft gen` writes these keys (prefixed "weft:" so that downsampled grids and local fields
/// carry them on):
///   weft:units                    length unit of the grid's world space ("mm")
///   weft:sigma_per_concentration  σ [1/length]: μ = σ·C for the fibres of this cloth
///   weft:sigma_rule               how σ was derived (text)
///   weft:fiber_radius             fibre radius [length] (fibre-volume-weighted mean radius)
///   weft:yarn_diameter            yarn diameter [length] (2 × envelope radius, mean of the presets)
/// Grids written by earlier versions of weft hold only "units" and the generator's JSON
/// ("generator"); their σ and yarn scale are derived from that JSON with the same rules.

#include <optional>
#include <string>

#include "weft/core/front_end.h"
#include "weft/volume/grid.h"

namespace weft::volume {

struct Provenance {
  std::string units;                    ///< "" when unknown
  std::optional<double> sigma;          ///< σ per unit concentration [1/length]
  std::string sigma_rule;               ///< derivation of σ, e.g. "2/(pi r_f), opaque fibres across the beam"
  std::optional<double> fiber_radius;   ///< [length]
  std::optional<double> yarn_diameter;  ///< [length]
  std::string value_kind;               ///< "concentration", "extinction" or ""
  std::string source;                   ///< "weft gen", "weft gen (legacy metadata)" or ""
  [[nodiscard]] bool from_weft() const { return !source.empty(); }
};

/// Reads the provenance keys above. A key that is present but malformed (not a positive
/// finite number) throws weft::Error naming the key: a grid never silently loses its σ.
[[nodiscard]] Provenance read_provenance(const Grid& grid);

/// Writes the keys of `p` that are set (used by the cloth generator).
void write_provenance(Grid& grid, const Provenance& p);

/// Who reads a grid's values as a kind: `weft <command> --values` or a scene's grid medium ("values").
enum class ValuesAsker { cli, scene };

/// The one rule for a value kind given against the grid's metadata (docs/robustness.md, "Value
/// kind"): when the grid records its kind (weft:value_kind, "concentration" or "extinction"), reading
/// it as the other kind is refused: C read as μ is a medium σ times too thin, μ read as C σ times too
/// thick, and no output would show it. Throws weft::Error "<what>: the grid's metadata says its values
/// are <kind>; pass --values <kind>" (a scene: set "values": "<kind>"). A grid with no recorded kind
/// (or another word) is read as the caller says.
void require_value_kind(const Provenance& p, bool read_as_extinction, const std::string& what,
                        ValuesAsker asker = ValuesAsker::cli);

/// σ used for μ = σ·value, and why (`sigma_source` in every report).
struct SigmaChoice {
  double sigma = 1.0;
  std::string source;  ///< "--sigma" / "sigma=", "<grid> provenance: <rule>", "values are extinction (mu), sigma = 1"
};

/// The one rule that picks σ (docs/validate.md, "σ: physical by default"): values that are
/// extinction → σ = 1; else the σ the user gave (`given`, checked > 0 by the front end); else the
/// provenance's σ; else weft::Error saying what to pass, never a silent σ = 1. `what` starts the
/// error; on the command line it names the grid (a file, "cloth") and so also the source
/// ("<what> provenance: …"), in Python it names the call and the grid is the argument `grid`.
[[nodiscard]] SigmaChoice resolve_sigma(const Provenance& p, std::optional<double> given, bool extinction,
                                        const std::string& what, FrontEnd asker = FrontEnd::cli);

/// σ per unit concentration of opaque cylindrical fibres of radius r crossed by a beam
/// perpendicular to them: projected area per unit length 2r over volume per unit length π r².
[[nodiscard]] double fibre_sigma(double fiber_radius);

}  // namespace weft::volume
