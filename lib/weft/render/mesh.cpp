#include "weft/render/mesh.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>
#include <string>

#include "weft/core/error.h"

namespace weft::render {

TriangleMesh load_obj(const std::filesystem::path& path) {
  std::ifstream in(path);
  if (!in) fail("mesh file '{}' cannot be opened (missing or unreadable)", path.string());
  TriangleMesh mesh;
  std::string line;
  std::size_t line_no = 0;
  auto bad = [&](const std::string& why) { fail("mesh file '{}', line {}: {}", path.string(), line_no, why); };
  while (std::getline(in, line)) {
    ++line_no;
    std::istringstream words(line);
    std::string tag;
    if (!(words >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      Vec3 v;
      for (int k = 0; k < 3; ++k) {
        std::string w;
        if (!(words >> w)) bad("a vertex needs 3 coordinates");
        double x = 0.0;
        const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), x);
        if (ec != std::errc() || end != w.data() + w.size() || !std::isfinite(x)) bad("bad coordinate '" + w + "'");
        v[k] = x;
      }
      mesh.vertices.push_back(v);
    } else if (tag == "f") {
      std::vector<std::uint32_t> face;
      std::string w;
      while (words >> w) {
        const std::string index_text = w.substr(0, w.find('/'));
        long long index = 0;
        const auto [end, ec] = std::from_chars(index_text.data(), index_text.data() + index_text.size(), index);
        if (ec != std::errc() || end != index_text.data() + index_text.size() || index == 0)
          bad("bad face index '" + w + "'");
        const auto count = static_cast<long long>(mesh.vertices.size());
        if (index < 0) index += count + 1;  // OBJ: negative indices count back from the last vertex
        if (index < 1 || index > count) bad("face index " + w + " out of range");
        face.push_back(static_cast<std::uint32_t>(index - 1));
      }
      if (face.size() < 3) bad("a face needs at least 3 vertices");
      for (std::size_t k = 1; k + 1 < face.size(); ++k) mesh.triangles.push_back({face[0], face[k], face[k + 1]});
    }
  }
  if (mesh.triangles.empty()) fail("mesh file '{}' has no faces", path.string());
  return mesh;
}

TriangleMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  // Quads listed counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.triangles.push_back({std::uint32_t(q[0]), std::uint32_t(q[1]), std::uint32_t(q[2])});
    m.triangles.push_back({std::uint32_t(q[0]), std::uint32_t(q[2]), std::uint32_t(q[3])});
  }
  return m;
}

TriangleMesh rectangle_mesh(const Vec3& corner, const Vec3& u, const Vec3& v) {
  TriangleMesh m;
  m.vertices = {corner, corner + u, corner + u + v, corner + v};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

}  // namespace weft::render
