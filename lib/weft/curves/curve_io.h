#pragma once
/// @file
/// @brief Curves in files: Cem Yuksel's binary curve collections (.bcc) and OBJ polylines (`l`
/// elements). Yarn centrelines and fibres travel between `weft gen`, other tools and the renderer
/// in these formats.

#include <array>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace weft::curves {

/// @brief A point in the file's units (weft writes millimetres).
using Point3 = std::array<double, 3>;

/// @brief A polyline; `closed` joins the last point back to the first.
struct Curve {
  std::vector<Point3> points;
  bool closed = false;
};

/// @brief Parses the bytes of a .bcc file (64-byte little-endian header "BCC", 0x44 = 4-byte
/// integers and floats, curve type "PL" (polyline) or "C0" (uniform Catmull–Rom), 3 dimensions,
/// curve and control-point counts, 40 bytes of info; then per curve an int32 point count,
/// negative for a closed curve, and that many float xyz triples).
///
/// Catmull–Rom curves come back as polylines with `catmull_rom_subdivisions` points per span;
/// open curves get phantom end points P₋₁ = 2P₀ − P₁ (and likewise at the end) so the curve
/// passes through every control point. The header's counts are checked against the byte count
/// before anything is allocated; a wrong signature, unsupported type, truncated or oversized
/// data, inconsistent count or non-finite coordinate throws weft::Error starting with `name`.
std::vector<Curve> parse_bcc(std::string_view bytes, const std::string& name = "<bcc>",
                             int catmull_rom_subdivisions = 8);

/// @brief Reads a .bcc file (see parse_bcc); a missing or unreadable file throws weft::Error
/// naming it.
std::vector<Curve> read_bcc(const std::filesystem::path& path, int catmull_rom_subdivisions = 8);

/// @brief The bytes of a polyline ("PL") .bcc file holding `curves` (closed curves get a negative
/// count; coordinates stored as 32-bit floats; `info` truncated to 39 characters).
std::string bcc_bytes(const std::vector<Curve>& curves, const std::string& info = "weft");

/// @brief Writes bcc_bytes(curves, info) to `path` atomically.
void write_bcc(const std::filesystem::path& path, const std::vector<Curve>& curves, const std::string& info = "weft");

/// @brief Reads the `l` elements of an OBJ file as polylines (1-based or negative vertex indices;
/// `v/vt` forms accepted). A two-point `l` that starts where the previous polyline ended extends
/// it, so edge-by-edge exports chain back into curves. Malformed lines, indices out of range or
/// a file without polylines throw weft::Error naming the file and line.
std::vector<Curve> read_obj_curves(const std::filesystem::path& path);

/// @brief Writes curves as OBJ `v` and `l` elements atomically (closed curves repeat the first
/// index).
void write_obj_curves(const std::filesystem::path& path, const std::vector<Curve>& curves);

/// @brief Reads a .bcc or .obj file by its (case-insensitive) extension.
std::vector<Curve> read_curves(const std::filesystem::path& path);

}  // namespace weft::curves
