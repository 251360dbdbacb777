// Scene files: parsing, checking, round trips and the one-line errors of bad input.
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include "weft/core/error.h"
#include "weft/core/json_input.h"
#include "weft/render/builtin_scenes.h"
#include "weft/render/cloth_scene.h"
#include "weft/render/mesh.h"
#include "weft/render/scene.h"
#include "weft/render/world.h"
#include "weft/volume/grid.h"
#include "weft/volume/provenance.h"

namespace weft::render {
namespace {

namespace fs = std::filesystem;

std::string error_of(const std::string& text) {
  try {
    (void)parse_scene(text, "test.json", fs::temp_directory_path());
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

const char* kMinimal = R"({
  "materials": {"white": {"type": "diffuse", "albedo": 0.5}},
  "shapes": [{"type": "sphere", "radius": 1, "material": "white"}],
  "lights": [{"type": "environment", "radiance": 1}]
})";

TEST(SceneFile, MinimalSceneParsesWithDefaults) {
  const SceneDesc s = parse_scene(kMinimal, "test.json", ".");
  ASSERT_EQ(s.shapes.size(), 1U);
  EXPECT_EQ(s.shapes[0].kind, ShapeKind::sphere);
  EXPECT_EQ(s.materials.at("white").albedo[1], 0.5);
  EXPECT_EQ(s.camera.width, 256);
  EXPECT_EQ(s.lights[0].kind, LightKind::environment);
}

TEST(SceneFile, ALeadingUtf8ByteOrderMarkIsSkipped) {
  // Windows editors save JSON with a byte order mark; it is not part of the scene.
  const std::string text = "\xEF\xBB\xBF" + std::string(kMinimal);
  EXPECT_EQ(parse_scene(text, "test.json", ".").shapes.size(), 1U);
  const fs::path path = fs::temp_directory_path() / "weft_bom_scene.json";
  std::ofstream(path, std::ios::binary) << text;
  EXPECT_EQ(load_scene(path).materials.at("white").albedo[1], 0.5);
  fs::remove(path);
  // Line and column still count from the first character after the mark.
  const std::string e = error_of("\xEF\xBB\xBF{\n  \"camera\": {\n    \"fov\": 40,,\n  }\n}");
  EXPECT_NE(e.find("test.json:3:15"), std::string::npos) << e;
}

TEST(SceneFile, InvalidJsonReportsLineAndColumn) {
  const std::string text = "{\n  \"camera\": {\n    \"fov\": 40,,\n  }\n}";
  const std::string e = error_of(text);
  EXPECT_NE(e.find("test.json:3:15"), std::string::npos) << e;
  EXPECT_NE(e.find("invalid JSON"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << "one line: " << e;
}

TEST(SceneFile, AKeyGivenTwiceIsAnErrorNamingItAndItsObject) {
  // nlohmann keeps the last of two equal keys: "spp": 16, "spp": 4 rendered at 4 without a word.
  const std::string e = error_of(R"({"integrator": {"spp": 16, "spp": 4}})");
  EXPECT_NE(e.find("key 'spp' appears twice in 'integrator'"), std::string::npos) << e;
  EXPECT_EQ(e.find('\n'), std::string::npos) << "one line: " << e;
  const std::string m =
      error_of(R"({"media": {"m": {"albedo": 0.5, "law": {"name": "exponential", "mu": 1, "mu": 2}}}})");
  EXPECT_NE(m.find("key 'mu' appears twice in 'media.m.law'"), std::string::npos) << m;
  const std::string top = error_of(R"({"shapes": [], "shapes": []})");
  EXPECT_NE(top.find("key 'shapes' appears twice in the top-level object"), std::string::npos) << top;
  const std::string in_array = error_of(R"({"shapes": [{"type": "sphere", "type": "box"}]})");
  EXPECT_NE(in_array.find("key 'type' appears twice in 'shapes[]'"), std::string::npos) << in_array;
  // Equal keys in different objects are no duplicate.
  EXPECT_NO_THROW((void)parse_scene(
      R"({"camera": {"fov": 30}, "media": {"a": {"law": {"name": "exponential", "mu": 1}}, "b": {"law": {"name": "exponential", "mu": 1}}}})",
      "t.json", "."));
}

TEST(SceneFile, PositionOfCountsLinesAndColumnsFromOne) {
  EXPECT_EQ(position_of("ab\ncd", 0).line, 1U);
  EXPECT_EQ(position_of("ab\ncd", 4).line, 2U);
  EXPECT_EQ(position_of("ab\ncd", 4).column, 2U);
}

TEST(SceneFile, UnknownKeyIsNamedWithClosestSuggestion) {
  const std::string e = error_of(R"({"camera": {"fvo": 30}})");
  EXPECT_NE(e.find("unknown key 'fvo'"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'fov'"), std::string::npos) << e;
}

TEST(SceneFile, UnknownTypeIsNamedWithClosestSuggestion) {
  const std::string e = error_of(R"({"shapes": [{"type": "sphre", "radius": 1}]})");
  EXPECT_NE(e.find("unknown shape type 'sphre'"), std::string::npos) << e;
  EXPECT_NE(e.find("did you mean 'sphere'"), std::string::npos) << e;
  const std::string m = error_of(R"({"materials": {"a": {"type": "difuse"}}})");
  EXPECT_NE(m.find("did you mean 'diffuse'"), std::string::npos) << m;
}

TEST(SceneFile, UnknownLawIsReportedAtLoad) {
  const std::string e = error_of(R"({"media": {"m": {"law": {"name": "gama", "mean_extinction": 1, "alpha": 2}}}})");
  EXPECT_NE(e.find("media.m"), std::string::npos) << e;
  EXPECT_NE(e.find("gama"), std::string::npos) << e;
}

TEST(SceneFile, NegativeAndOutOfRangeParametersAreRejected) {
  EXPECT_NE(error_of(R"({"shapes": [{"type": "sphere", "radius": -1, "material": "w"}]})").find("'radius' must be > 0"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"materials": {"w": {"albedo": -0.1}}})").find("'albedo' must be >= 0"), std::string::npos);
  EXPECT_NE(error_of(R"({"camera": {"fov": 0}})").find("'fov' must be > 0"), std::string::npos);
  EXPECT_NE(error_of(R"({"camera": {"width": 0}})").find("'width' must be in"), std::string::npos);
  EXPECT_NE(error_of(R"({"media": {"m": {"law": {"name": "exponential", "mu": -2}}}})").find("mu"), std::string::npos);
  EXPECT_NE(
      error_of(R"({"media": {"m": {"law": "exponential", "g": 1.5}}})").find("'g' must be in [-0.999999, 0.999999]"),
      std::string::npos);
}

TEST(SceneFile, KeysThatDoNotApplyOrAreEmptyAreSaidAsSuch) {
  // parse_scene checks that the grid file exists, not what it holds: any file will do.
  const fs::path grid = fs::temp_directory_path() / fmt::format("weft-scene-keys-{}.vdb", ::getpid());
  std::ofstream(grid) << "x";
  const std::string medium = fmt::format(R"("type": "grid", "file": "{}")", grid.filename().string());
  const auto media = [&](const std::string& keys) { return fmt::format(R"({{"media": {{"m": {{{}}}}}}})", keys); };
  // σ scales concentration values (μ = σ·C); extinction values are μ: a sigma there is not a typo.
  EXPECT_THAT(error_of(media(medium + R"(, "values": "extinction", "sigma": 3)")),
              ::testing::HasSubstr("media.m: 'sigma' does not apply to \"values\": \"extinction\""));
  EXPECT_EQ(error_of(media(medium + R"(, "values": "concentration", "sigma": 3)")), "");
  EXPECT_EQ(error_of(media(medium + R"(, "values": "extinction")")), "");
  // A file key given empty or null is not a missing key.
  EXPECT_THAT(error_of(media(R"("type": "grid", "file": "")")), ::testing::HasSubstr("media.m: 'file' is empty"));
  EXPECT_THAT(error_of(media(R"("type": "grid", "file": null)")), ::testing::HasSubstr("media.m: 'file' is null"));
  EXPECT_THAT(error_of(media(R"("type": "grid")")), ::testing::HasSubstr("media.m: missing required key 'file'"));
  EXPECT_THAT(error_of(media(R"("type": "local-gamma", "fields": "")")),
              ::testing::HasSubstr("media.m: 'fields' is empty (give the .vdb written by `weft fit --block`)"));
  fs::remove(grid);
}

TEST(SceneFile, AnAlbedoAboveOneIsRefusedForEveryMaterialAndMedium) {
  // Each multiplies the throughput at a bounce: above 1 it creates energy (a dielectric sphere of
  // albedo 3 under an environment of 1 rendered a mean of 6.75).
  for (const char* text : {R"({"materials": {"w": {"type": "diffuse", "albedo": 1.5}}})",
                           R"({"materials": {"w": {"type": "mirror", "albedo": [0.5, 1.5, 0.5]}}})",
                           R"({"materials": {"w": {"type": "dielectric", "ior": 1.5, "albedo": 3.0}}})",
                           R"({"media": {"m": {"law": "exponential", "albedo": 1.01}}})"}) {
    const std::string e = error_of(text);
    EXPECT_NE(e.find("'albedo' must be <= 1 to conserve energy, got "), std::string::npos) << text << ": " << e;
  }
  for (const char* kind : {"diffuse", "mirror", "dielectric"}) {
    EXPECT_EQ(error_of(fmt::format(R"({{"materials": {{"w": {{"type": "{}", "albedo": 1}}}}}})", kind)), "") << kind;
  }
}

TEST(SceneFile, DanglingNamesSuggestTheClosestDefinedOne) {
  const std::string e = error_of(R"({"materials": {"white": {}}, "shapes": [{"type": "sphere", "material": "whte"}]})");
  EXPECT_NE(e.find("material 'whte' is not defined (did you mean 'white'?)"), std::string::npos) << e;
}

TEST(SceneFile, MissingMeshFileIsNamed) {
  const std::string e =
      error_of(R"({"materials": {"w": {}}, "shapes": [{"type": "mesh", "file": "nope.obj", "material": "w"}]})");
  EXPECT_NE(e.find("nope.obj"), std::string::npos) << e;
  EXPECT_NE(e.find("does not exist"), std::string::npos) << e;
}

TEST(SceneFile, ReciprocalPartnerThatDoesNotExistIsAnError) {
  // Gamma path length with k < 1 has p_Q(0) = ∞: T_S = p_Q/p_Q(0) does not exist.
  const std::string e =
      error_of(R"({"media": {"m": {"law": {"name": "gamma-path", "k": 0.5, "theta": 1}, "mode": "reciprocal"}}})");
  EXPECT_NE(e.find("media.m"), std::string::npos) << e;
  EXPECT_FALSE(e.empty());
  // The same law given as the scatterer's law has a source partner (ℓ_S finite).
  EXPECT_EQ(error_of(R"({"media": {"m": {"law": {"name": "gamma-path", "k": 0.5, "theta": 1},
                                      "mode": "reciprocal", "given": "scatterer"}}})"),
            "");
}

TEST(SceneFile, RoundTripsThroughJson) {
  for (const auto& name : builtin_scene_names()) {
    const SceneDesc a = parse_scene(builtin_scene(name), name, ".");
    const std::string once = scene_to_json(a);
    const SceneDesc b = parse_scene(once, name + " (written)", ".");
    EXPECT_EQ(scene_to_json(b), once) << name;
    EXPECT_EQ(a.shapes.size(), b.shapes.size());
    EXPECT_EQ(a.media.size(), b.media.size());
  }
}

// A relative file name is relative to the scene file's folder, resolved once: the written scene
// loads again against the same folder (the image study re-reads its target this way) and from
// a file saved anywhere, whatever the working folder (docs/scene-format.md).
TEST(SceneFile, RelativeFilesResolveOnceAgainstTheSceneFolder) {
  const fs::path root = fs::temp_directory_path() / fmt::format("weft-scene-paths-{}", ::getpid());
  fs::remove_all(root);
  fs::create_directories(root / "scene_dir");
  std::ofstream(root / "scene_dir" / "tri.obj") << "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
  const std::string text =
      R"({"materials": {"w": {}}, "shapes": [{"type": "mesh", "file": "tri.obj", "material": "w"}]})";
  const fs::path cwd = fs::current_path();
  fs::current_path(root);  // the scene folder as a relative path, as `weft render scene_dir/scene.json`
  const SceneDesc a = parse_scene(text, "scene_dir/scene.json", "scene_dir");
  const std::string written = scene_to_json(a);
  const SceneDesc again = parse_scene(written, "again", "scene_dir");
  fs::current_path(cwd);
  const SceneDesc elsewhere = parse_scene(written, "saved elsewhere", fs::temp_directory_path());
  EXPECT_TRUE(fs::equivalent(a.shapes[0].file, root / "scene_dir" / "tri.obj")) << a.shapes[0].file;
  EXPECT_EQ(again.shapes[0].file, a.shapes[0].file);
  EXPECT_EQ(elsewhere.shapes[0].file, a.shapes[0].file);
  fs::remove_all(root);
}

// Embree stores floats: a shape scaled out of float's range would silently vanish from the image
// or abort inside Embree; beyond its kind's reach (docs/render.md §1) it is refused.
TEST(SceneFile, CoordinatesBeyondFloatRangeAreAnError) {
  const SceneDesc s = parse_scene(
      R"({"materials": {"w": {}}, "shapes": [{"type": "sphere", "radius": 1e300, "material": "w"}]})", "big.json", ".");
  EXPECT_THAT([&] { (void)build_world(s); },
              ::testing::ThrowsMessage<Error>(::testing::HasSubstr("big.json: shapes[0]: coordinates reach")));
}

// A camera far beyond the shapes (docs/render.md §1, kMaxExtentsAway of the smallest shape): a camera
// or lens beyond it is refused before any ray is traced (it used to abort inside Embree).
TEST(SceneFile, CameraBeyondWhatEmbreeTracesIsAnError) {
  const std::string shapes = R"("materials": {"w": {}}, "shapes": [{"type": "sphere", "material": "w"}])";
  const std::pair<std::string, std::string> cases[] = {
      {R"("position": [0, 0, 1e20])", "far.json: camera.position reaches 1e+20"},
      {R"("position": [0, 0, 5], "aperture_radius": 1e20)",
       "far.json: camera.position plus camera.aperture_radius reaches"}};
  for (const auto& [camera, expected] : cases) {
    const SceneDesc s = parse_scene("{\"camera\": {" + camera + "}, " + shapes + "}", "far.json", ".");
    EXPECT_THAT([&] { (void)build_world(s); }, ::testing::ThrowsMessage<Error>(::testing::HasSubstr(expected)))
        << camera;
  }
}

TEST(SceneFile, BuiltInScenesIncludeTheExamples) {
  const auto names = builtin_scene_names();
  for (const char* required : {"cloth_patch", "cornell_media", "furnace"})
    EXPECT_NE(std::find(names.begin(), names.end(), required), names.end()) << required;
  EXPECT_THROW((void)builtin_scene("furnase"), Error);
}

TEST(ClothScene, FromTheGridInMemoryIsTheSceneOfItsSavedFile) {
  // `weft gen` writes scene.json from the grid it holds (no second copy of the tree read back
  // from cloth.vdb): it must be the scene the file gives.
  volume::Grid g(0.02, "density");
  g.set_origin({0.1, -0.3, 0.05});
  for (int i = 0; i < 30; ++i) g.set_value(i, i % 7, 3 - i % 4, 0.25f + 0.01f * static_cast<float>(i));
  volume::Provenance prov;
  prov.units = "mm";
  prov.sigma = 123.5;
  volume::write_provenance(g, prov);
  const fs::path p = fs::temp_directory_path() / "weft_render_cloth_scene.vdb";
  g.save(p);
  const std::string from_memory = cloth_scene_json(g, "cloth.vdb");
  EXPECT_EQ(from_memory, cloth_scene_json(p, "cloth.vdb"));
  EXPECT_NE(from_memory.find("\"sigma\": 123.5"), std::string::npos) << from_memory;
  EXPECT_EQ(cloth_look(g, p).sigma, 123.5);
  fs::remove(p);
  EXPECT_THROW((void)cloth_scene_json(volume::Grid(0.02), "empty.vdb"), Error);
}

TEST(ObjReader, ReadsPolygonsAndNegativeIndices) {
  const fs::path p = fs::temp_directory_path() / "weft_render_quad.obj";
  {
    std::ofstream out(p);
    out << "# quad\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvn 0 0 1\nf 1/1/1 2/2/1 3/3/1 4/4/1\nf -4 -3 -2\n";
  }
  const TriangleMesh m = load_obj(p);
  EXPECT_EQ(m.vertices.size(), 4U);
  ASSERT_EQ(m.triangles.size(), 3U);
  EXPECT_EQ(m.triangles[1][2], 3U);
  EXPECT_EQ(m.triangles[2][0], 0U);
  fs::remove(p);
}

TEST(ObjReader, ReadsSignedNumbersTrailingCommentsAndContinuations) {
  const fs::path p = fs::temp_directory_path() / "weft_render_forms.obj";
  std::ofstream(p) << "v +0 0 0\nv 1 0 0 # x\nv 1 \\\n 1 0\nf 1 2 3 # one triangle\n";
  const TriangleMesh m = load_obj(p);
  ASSERT_EQ(m.triangles.size(), 1U);
  EXPECT_EQ(m.vertices[2][1], 1.0);
  fs::remove(p);
}

TEST(ObjReader, BadIndexNamesFileAndLine) {
  const fs::path p = fs::temp_directory_path() / "weft_render_bad.obj";
  {
    std::ofstream out(p);
    out << "v 0 0 0\nv 1 0 0\nf 1 2 3\n";
  }
  EXPECT_THAT([&] { (void)load_obj(p); }, ::testing::ThrowsMessage<Error>(::testing::HasSubstr("line 3")));
  fs::remove(p);
}

TEST(BoxMesh, TrianglesFaceOutward) {
  const TriangleMesh m = box_mesh(Vec3(-1, -2, -3), Vec3(1, 2, 3));
  for (const auto& t : m.triangles) {
    const Vec3 a = m.vertices[t[0]];
    const Vec3 n = (m.vertices[t[1]] - a).cross(m.vertices[t[2]] - a);
    const Vec3 centre = (a + m.vertices[t[1]] + m.vertices[t[2]]) / 3.0;
    EXPECT_GT(n.dot(centre), 0.0);
  }
}

}  // namespace
}  // namespace weft::render

TEST(ShrinkFilm, KeepsTheViewAndTheAspectOnTheLongestSide) {
  // --quick's film (docs/render.md §6c): the longest side as asked, the other side rounded to
  // the same aspect, never below one pixel; a film already that size is unchanged.
  weft::render::CameraDesc wide;
  wide.width = 640;
  wide.height = 480;
  weft::render::shrink_film(wide, 48);
  EXPECT_EQ(wide.width, 48);
  EXPECT_EQ(wide.height, 36);
  weft::render::CameraDesc tall;
  tall.width = 100;
  tall.height = 1000;
  weft::render::shrink_film(tall, 48);
  EXPECT_EQ(tall.width, 5);
  EXPECT_EQ(tall.height, 48);
  weft::render::CameraDesc sliver;
  sliver.width = 1000;
  sliver.height = 1;
  weft::render::shrink_film(sliver, 48);
  EXPECT_EQ(sliver.width, 48);
  EXPECT_EQ(sliver.height, 1);
}
