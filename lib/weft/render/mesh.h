#pragma once
/// @file
/// @brief Triangle meshes: a strict Wavefront OBJ reader (v and f records; polygons fanned).

#include <array>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "weft/render/scene.h"

namespace weft::render {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< counter-clockwise seen from outside
};

/// Reads `v x y z` and `f a b c ...` records (indices may be negative or carry /vt/vn parts,
/// which are ignored); other records (vn, vt, o, g, s, usemtl, mtllib, #) are skipped.
/// Throws weft::Error naming the file and line for a missing file, a malformed number, an
/// index out of range, or a mesh without triangles.
[[nodiscard]] TriangleMesh load_obj(const std::filesystem::path& path);

/// The 12 outward-facing triangles of an axis-aligned box.
[[nodiscard]] TriangleMesh box_mesh(const Vec3& min, const Vec3& max);

/// Two triangles spanning corner + [0,1]·edge_u + [0,1]·edge_v, facing edge_u × edge_v.
[[nodiscard]] TriangleMesh rectangle_mesh(const Vec3& corner, const Vec3& edge_u, const Vec3& edge_v);

}  // namespace weft::render
