// PLY meshes through VTK's vtkPLYReader: the same mesh as OBJ and as PLY (ASCII and binary)
// gives the same triangles and the same image; malformed files are one-line errors, never a
// crash, and VTK prints nothing.
#include <algorithm>
#include <array>
#include <bit>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/render/mesh.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"

namespace weft::render {
namespace {
namespace fs = std::filesystem;

class PlyFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("weft_render_ply_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path write(const std::string& name, const std::string& bytes) const {
    const fs::path p = dir_ / name;
    std::ofstream out(p, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    return p;
  }
  fs::path dir_;
};

struct Polygons {
  std::vector<Vec3> vertices;
  std::vector<std::vector<int>> faces;
};

/// A unit cube with quads (counter-clockwise from outside) and one face split into two triangles.
Polygons cube() {
  const TriangleMesh m = box_mesh(Vec3(-1, -1, -1), Vec3(1, 1, 1));
  Polygons p;
  p.vertices = m.vertices;
  for (const auto& t : m.triangles) p.faces.push_back({int(t[0]), int(t[1]), int(t[2])});
  return p;
}

/// A tetrahedron and a planar pentagon (a polygon VTK must triangulate).
Polygons tetra_and_pentagon() {
  Polygons p;
  p.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  p.faces = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  for (int k = 0; k < 5; ++k) {
    const double a = 2.0 * 3.14159265358979 * k / 5.0;
    p.vertices.emplace_back(3.0 + std::cos(a), std::sin(a), 0.5);
  }
  p.faces.push_back({4, 5, 6, 7, 8});
  return p;
}

std::string obj_text(const Polygons& p) {
  std::string s;
  for (const auto& v : p.vertices) s += fmt::format("v {} {} {}\n", v.x(), v.y(), v.z());
  for (const auto& f : p.faces) {
    s += "f";
    for (int i : f) s += fmt::format(" {}", i + 1);
    s += "\n";
  }
  return s;
}

std::string ply_ascii(const Polygons& p) {
  std::string s = fmt::format(
      "ply\nformat ascii 1.0\ncomment weft test\nelement vertex {}\nproperty float x\nproperty float y\n"
      "property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
      p.vertices.size(), p.faces.size());
  for (const auto& v : p.vertices) s += fmt::format("{} {} {}\n", v.x(), v.y(), v.z());
  for (const auto& f : p.faces) {
    s += fmt::format("{}", f.size());
    for (int i : f) s += fmt::format(" {}", i);
    s += "\n";
  }
  return s;
}

std::string ply_binary(const Polygons& p) {
  std::string s = fmt::format(
      "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\n"
      "property float z\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
      p.vertices.size(), p.faces.size());
  const auto put32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) s.push_back(static_cast<char>((v >> (8 * i)) & 0xFFU));
  };
  for (const auto& v : p.vertices)
    for (int k = 0; k < 3; ++k) put32(std::bit_cast<std::uint32_t>(static_cast<float>(v[k])));
  for (const auto& f : p.faces) {
    s.push_back(static_cast<char>(f.size()));
    for (int i : f) put32(static_cast<std::uint32_t>(i));
  }
  return s;
}

using Triangle = std::array<std::array<float, 3>, 3>;

/// Triangles by position, each rotated so its smallest corner comes first (winding kept).
std::multiset<Triangle> triangle_set(const TriangleMesh& m) {
  std::multiset<Triangle> out;
  for (const auto& t : m.triangles) {
    Triangle tri;
    for (int c = 0; c < 3; ++c)
      for (int k = 0; k < 3; ++k) tri[c][k] = static_cast<float>(m.vertices[t[c]][k]);
    const auto first = std::min_element(tri.begin(), tri.end()) - tri.begin();
    std::rotate(tri.begin(), tri.begin() + first, tri.end());
    out.insert(tri);
  }
  return out;
}

double area(const TriangleMesh& m, Vec3* normal_sum = nullptr) {
  double a = 0.0;
  for (const auto& t : m.triangles) {
    const Vec3 n = (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]);
    a += 0.5 * n.norm();
    if (normal_sum != nullptr) *normal_sum += 0.5 * n;
  }
  return a;
}

TEST_F(PlyFiles, TrianglesAreTheSameAsFromObj) {
  const Polygons p = cube();
  const TriangleMesh obj = load_mesh(write("c.obj", obj_text(p)));
  const TriangleMesh ascii = load_mesh(write("c.ply", ply_ascii(p)));
  const TriangleMesh binary = load_mesh(write("c_bin.PLY", ply_binary(p)));
  ASSERT_EQ(obj.triangles.size(), 12U);
  EXPECT_EQ(triangle_set(ascii), triangle_set(obj));
  EXPECT_EQ(triangle_set(binary), triangle_set(obj));
}

TEST_F(PlyFiles, PolygonsAreTriangulatedKeepingAreaAndOrientation) {
  const Polygons p = tetra_and_pentagon();
  const TriangleMesh obj = load_mesh(write("t.obj", obj_text(p)));
  const TriangleMesh ply = load_mesh(write("t.ply", ply_ascii(p)));
  ASSERT_EQ(ply.triangles.size(), 4U + 3U);  // a pentagon is three triangles however it is split
  Vec3 n_obj = Vec3::Zero();
  Vec3 n_ply = Vec3::Zero();
  EXPECT_NEAR(area(ply, &n_ply), area(obj, &n_obj), 1e-6);
  EXPECT_NEAR((n_ply - n_obj).norm(), 0.0, 1e-6) << "winding changed";
}

TEST_F(PlyFiles, PlyCubeRendersLikeObjCube) {
  const Polygons p = cube();
  write("c.obj", obj_text(p));
  write("c.ply", ply_binary(p));
  const std::string scene = R"({
    "camera": {"position": [2.5, 3, 4], "look_at": [0, 0, 0], "width": 24, "height": 24},
    "integrator": {"spp": 8, "seed": 2},
    "materials": {"white": {"albedo": 0.7}},
    "shapes": [{"type": "mesh", "file": "FILE", "scale": 0.5, "material": "white"}],
    "lights": [{"type": "point", "position": [3, 5, 2], "intensity": 20}, {"type": "environment", "radiance": 0.2}]
  })";
  auto with = [&](const std::string& f) {
    std::string s = scene;
    s.replace(s.find("FILE"), 4, f);
    return render(parse_scene(s, "ply scene", dir_)).image;
  };
  const Image a = with("c.obj");
  const Image b = with("c.ply");
  double total = 0.0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    EXPECT_NEAR(a.rgb[i], b.rgb[i], 1e-5 * (1.0 + a.rgb[i]));
    total += a.rgb[i];
  }
  EXPECT_GT(total, 0.0);
}

struct BadPly {
  const char* name;
  std::string bytes;
  const char* expected;
};

TEST_F(PlyFiles, MalformedFilesAreOneLineErrorsAndVtkStaysQuiet) {
  const Polygons p = tetra_and_pentagon();
  const std::string good = ply_ascii(p);
  const std::string good_bin = ply_binary(p);
  auto replaced = [](std::string s, const std::string& from, const std::string& to) {
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  std::string nan_vertex = good;
  nan_vertex.replace(nan_vertex.find("end_header\n") + 11, 1, "nan");
  const std::vector<BadPly> cases = {
      {"empty", "", "does not start with 'ply'"},
      {"not_ply", "solid cube\nfacet normal 0 0 1\n", "does not start with 'ply'"},
      {"no_end_header", replaced(good, "end_header", "end_headr"), "end_header"},
      {"huge_count", replaced(good, "element vertex 9", "element vertex 99999999999"), "more than the file holds"},
      {"bad_count", replaced(good, "element face 5", "element face five"), "element count"},
      {"bad_format", replaced(good, "format ascii", "format morse"), "unknown format"},
      {"no_z", replaced(good, "property float z", "property float w"), "'z'"},
      {"no_faces", replaced(good, "vertex_indices", "vertex_index_list"), "vertex_indices"},
      {"bad_type", replaced(good, "property float y", "property quad y"), "unknown property type"},
      {"truncated_ascii", good.substr(0, good.size() - 12), "ends inside element 'face'"},
      {"too_many_values", replaced(good, "3 0 2 1", "3 0 2 1 7"), "too many values"},
      {"text_value", replaced(good, "3 0 2 1", "3 0 two 1"), "not a finite number"},
      {"nan_vertex", nan_vertex, "not a finite number"},
      {"index_out_of_range", replaced(good, "3 0 2 1", "3 0 2 42"), "uses vertex 42"},
      {"negative_index", replaced(good, "3 0 2 1", "3 0 -2 1"), "uses vertex -2"},
      {"two_vertex_face", replaced(good, "3 0 2 1", "2 0 2"), "fewer than 3"},
      {"truncated_binary", good_bin.substr(0, good_bin.size() - 3), "ends inside element 'face'"},
      {"huge_binary_list",
       replaced(good_bin, std::string("\x03\x00\x00\x00\x00", 5), std::string("\xff\x00\x00\x00\x00", 5)),
       "ends inside"},
  };
  for (const auto& c : cases) {
    const fs::path path = write(std::string(c.name) + ".ply", c.bytes);
    ::testing::internal::CaptureStderr();
    EXPECT_THAT([&] { (void)load_mesh(path); }, weft::test::throws_one_line_error_with({path.string(), c.expected}))
        << c.name;
    EXPECT_EQ(::testing::internal::GetCapturedStderr(), "") << c.name;
  }
  EXPECT_THROW((void)load_mesh(dir_ / "missing.ply"), Error);
}

}  // namespace
}  // namespace weft::render
