#pragma once
/// @file
/// @brief Yarn and fibre curves in files: Cem Yuksel's binary curve collections (.bcc) and OBJ
/// polylines (`l` elements).

#include <filesystem>
#include <string>
#include <vector>

#include "data_gen/cloth/fibers.h"

namespace weft::cloth {

/// @brief Reads a .bcc file (64-byte little-endian header "BCC", 0x44 = 4-byte integers and
/// floats, curve type "PL" (polyline) or "C0" (uniform Catmull–Rom), 3 dimensions, curve and
/// control-point counts, 40 bytes of info; then per curve an int32 point count, negative for a
/// closed curve, and that many float xyz triples).
///
/// Catmull–Rom curves come back as polylines with `catmull_rom_subdivisions` points per span;
/// open curves get phantom end points P₋₁ = 2P₀ − P₁ (and likewise at the end) so the curve
/// passes through every control point. The header's counts are checked against the file length
/// before anything is allocated; a wrong signature, unsupported type, truncated or oversized
/// file, inconsistent count or non-finite coordinate throws weft::Error naming the file.
std::vector<Curve> read_bcc(const std::filesystem::path& path, int catmull_rom_subdivisions = 8);

/// @brief Writes curves as a polyline ("PL") .bcc file atomically (closed curves get a negative
/// count). Coordinates are stored as 32-bit floats.
void write_bcc(const std::filesystem::path& path, const std::vector<Curve>& curves, const std::string& info = "weft");

/// @brief Reads the `l` elements of an OBJ file as polylines (1-based or negative vertex indices;
/// `v/vt` forms accepted). A two-point `l` that starts where the previous polyline ended extends
/// it, so edge-by-edge exports chain back into curves. Malformed lines, indices out of range or
/// a file without polylines throw weft::Error naming the file and line.
std::vector<Curve> read_obj_curves(const std::filesystem::path& path);

/// Writes curves as OBJ `v` and `l` elements atomically (closed curves repeat the first index).
void write_obj_curves(const std::filesystem::path& path, const std::vector<Curve>& curves);

/// Reads a .bcc or .obj file by its extension.
std::vector<Curve> read_curves(const std::filesystem::path& path);

/// The fibres as open curves (for write_bcc / write_obj_curves).
std::vector<Curve> fiber_curves(const FiberSet& fibers);

}  // namespace weft::cloth
