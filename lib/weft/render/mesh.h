#pragma once
/// @file
/// @brief Triangle meshes: a strict Wavefront OBJ reader (v and f records; polygons fanned) and
/// PLY through VTK.

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

/// @brief Reads a Stanford PLY file (ASCII or binary) with VTK's vtkPLYReader and triangulates
/// its polygons (vtkTriangleFilter). The file is first checked against its own header (element
/// counts, list lengths and byte/token counts must fit the file, `vertex` needs x, y, z and
/// `face` a `vertex_indices` list), so malformed input is a weft::Error naming the file and
/// never reaches VTK's C parser; face indices out of range and non-finite coordinates are
/// refused too. VTK's messages are kept off the terminal.
[[nodiscard]] TriangleMesh load_ply(const std::filesystem::path& path);

/// @brief load_ply for `.ply` files (any case), load_obj otherwise.
[[nodiscard]] TriangleMesh load_mesh(const std::filesystem::path& path);

/// Whether the mesh bounds an inside: every edge (between vertices taken by position, so a mesh
/// that repeats a vertex per face counts as joined) is crossed as often in one direction as in
/// the other by the triangles' windings. `open`: an edge with an odd number of triangles (a
/// border); `misoriented`: the triangles meet in pairs but some are wound against their
/// neighbours (a flipped triangle: its inside and outside swap). Two closed parts sharing an edge
/// (four triangles there) are closed.
enum class Closure { closed, open, misoriented };
[[nodiscard]] Closure closure(const TriangleMesh& mesh);

/// The 12 outward-facing triangles of an axis-aligned box.
[[nodiscard]] TriangleMesh box_mesh(const Vec3& min, const Vec3& max);

/// Two triangles spanning corner + [0,1]·edge_u + [0,1]·edge_v, facing edge_u × edge_v.
[[nodiscard]] TriangleMesh rectangle_mesh(const Vec3& corner, const Vec3& edge_u, const Vec3& edge_v);

}  // namespace weft::render
