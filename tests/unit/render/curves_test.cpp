// Fibre curves in scenes (Embree round linear curves): silhouettes against their closed-form
// screen coverage, JSON round trip, and bad curve files. Tolerances are 5 standard errors of the
// rendered estimate (per-pixel sample variances).
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "weft/core/error.h"
#include "weft/curves/curve_io.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"

namespace weft::render {
namespace {
namespace fs = std::filesystem;

class CurveScene : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("weft_render_curves_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  /// One straight segment a→b in a BCC file.
  fs::path segment_file(const curves::Point3& a, const curves::Point3& b) const {
    curves::Curve c;
    c.points = {a, b};
    const fs::path p = dir_ / "segment.bcc";
    curves::write_bcc(p, {c});
    return p;
  }

  fs::path dir_;
};

/// A black fibre of radius r in front of a white environment, camera at (0, 0, D) looking at the
/// origin (vertical fov 30°, 64×48 pixels): image mean = 1 − covered fraction.
std::string coverage_scene(const fs::path& bcc, double radius, double distance, int spp) {
  return fmt::format(R"({{
    "camera": {{"position": [0, 0, {}], "look_at": [0, 0, 0], "fov": 30, "width": 64, "height": 48}},
    "integrator": {{"spp": {}, "max_depth": 1, "seed": 5}},
    "materials": {{"black": {{"type": "diffuse", "albedo": 0}}}},
    "shapes": [{{"type": "curves", "file": "{}", "radius": {}, "material": "black"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                     distance, spp, bcc.string(), radius);
}

struct Coverage {
  double covered = 0.0;
  double stderr_ = 0.0;
};
Coverage covered_fraction(const Image& im) {
  double sum = 0.0;
  double var = 0.0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      sum += im.at(x, y, 0);
      var += im.var_at(x, y, 0);
    }
  const double n = static_cast<double>(im.width) * im.height;
  return {1.0 - sum / n, std::sqrt(var) / n};
}

// Seen from the side, a tube of radius r whose axis crosses the view at distance D covers the
// screen band |s_y| ≤ r/√(D² − r²) (the plane through the eye tangent to the tube), the same for
// every column: covered fraction = r/√(D² − r²) / tan(fov/2).
TEST_F(CurveScene, SegmentSeenSideOnCoversItsAnalyticBand) {
  const double r = 0.2;
  const double d = 4.0;
  const fs::path bcc = segment_file({-6, 0, 0}, {6, 0, 0});  // ends far outside the frame
  const RenderResult res = render(parse_scene(coverage_scene(bcc, r, d, 16), "test", "."));
  const double tan_half = std::tan(15.0 * std::numbers::pi / 180.0);
  const double expected = r / std::sqrt(d * d - r * r) / tan_half;
  const Coverage c = covered_fraction(res.image);
  EXPECT_NEAR(c.covered, expected, 5.0 * c.stderr_ + 1e-5) << "stderr " << c.stderr_;
  EXPECT_GT(c.stderr_, 0.0) << "edge pixels must be partly covered";
  EXPECT_TRUE(res.stats.features.curves);
  EXPECT_EQ(res.stats.integrator, "surfaces");
  const auto names = res.stats.features.names();
  EXPECT_NE(std::find(names.begin(), names.end(), "curves"), names.end());
}

// Seen head-on (along its axis), the silhouette is the near end's spherical cap: a disc of
// screen radius ρ = r/√(D² − r²) around the centre; the cone behind lies inside it.
TEST_F(CurveScene, SegmentSeenHeadOnCoversItsEndDisc) {
  const double r = 0.5;
  const double d = 4.0;
  const fs::path bcc = segment_file({0, 0, 0}, {0, 0, -5});
  const RenderResult res = render(parse_scene(coverage_scene(bcc, r, d, 16), "test", "."));
  const double tan_half = std::tan(15.0 * std::numbers::pi / 180.0);
  const double rho = r / std::sqrt(d * d - r * r);
  const double expected = std::numbers::pi * rho * rho / (2.0 * tan_half * (64.0 / 48.0) * 2.0 * tan_half);
  const Coverage c = covered_fraction(res.image);
  EXPECT_NEAR(c.covered, expected, 5.0 * c.stderr_ + 1e-5) << "stderr " << c.stderr_;
  EXPECT_GT(c.stderr_, 0.0);
}

// A bent polyline has no gaps at its joints: a closed square loop of fibre seen from the front
// covers the same as four separate straight segments would minus the joint overlaps; simplest
// invariant: its coverage must exceed that of the straight side-on band over the same width.
TEST_F(CurveScene, ClosedPolylineJointsLeaveNoGap) {
  // Square of side 2 centred at the origin, facing the camera; a ray through a corner's joint
  // must hit (the spheres at the joints fill the miter).
  curves::Curve sq;
  sq.points = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
  sq.closed = true;
  const fs::path p = dir_ / "square.bcc";
  curves::write_bcc(p, {sq});
  const RenderResult res = render(parse_scene(coverage_scene(p, 0.05, 6.0, 4), "test", "."));
  // Camera at (0,0,6), fov 30°: screen point of world (x, y, 0) is x/6; pixel of the corner (1, 1).
  const double tan_half = std::tan(15.0 * std::numbers::pi / 180.0);
  const auto pixel_of = [&](double x, double y) {
    const double sx = x / 6.0 / (tan_half * 64.0 / 48.0);
    const double sy = y / 6.0 / tan_half;
    return std::pair<int, int>{static_cast<int>((sx + 1.0) * 0.5 * 64.0), static_cast<int>((1.0 - sy) * 0.5 * 48.0)};
  };
  for (const auto& [x, y] : {std::pair{1.0, 1.0}, {-1.0, 1.0}, {1.0, -1.0}, {-1.0, -1.0}, {0.0, 1.0}}) {
    const auto [px, py] = pixel_of(x, y);
    EXPECT_LT(res.image.at(px, py, 0), 0.75) << "corner (" << x << ", " << y << ") pixel " << px << "," << py;
  }
  EXPECT_FLOAT_EQ(res.image.at(32, 24, 0), 1.0f) << "the centre of the loop is open";
}

TEST_F(CurveScene, RoundTripsThroughJson) {
  const fs::path bcc = segment_file({0, 0, 0}, {1, 2, 3});
  const std::string text = fmt::format(R"({{
    "materials": {{"fibre": {{"albedo": [0.7, 0.6, 0.5]}}}},
    "shapes": [{{"type": "curves", "file": "segment.bcc", "radius": 0.01, "scale": 2, "translate": [1, 0, -1],
                 "material": "fibre"}}]
  }})");
  const SceneDesc a = parse_scene(text, "curve scene", dir_);
  ASSERT_EQ(a.shapes.size(), 1U);
  EXPECT_EQ(a.shapes[0].kind, ShapeKind::curves);
  EXPECT_EQ(fs::path(a.shapes[0].file), dir_ / "segment.bcc");
  EXPECT_DOUBLE_EQ(a.shapes[0].radius, 0.01);
  EXPECT_DOUBLE_EQ(a.shapes[0].scale, 2.0);
  const std::string once = scene_to_json(a);
  const SceneDesc b = parse_scene(once, "curve scene (written)", ".");
  EXPECT_EQ(scene_to_json(b), once);
  EXPECT_EQ(b.shapes[0].kind, ShapeKind::curves);
  EXPECT_DOUBLE_EQ(b.shapes[0].radius, 0.01);
  EXPECT_EQ(b.shapes[0].translate, Vec3(1, 0, -1));
}

std::string error_of(const std::string& json, const fs::path& base) {
  try {
    // Curve files are read when the world is built (render/world), still before any render.
    (void)build_world(parse_scene(json, "s", base));
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST_F(CurveScene, MissingOrCorruptCurveFileIsOneLineError) {
  const std::string shape = R"({"materials": {"m": {}}, "shapes": [{"type": "curves", "file": "FILE", "radius": 0.1,
                                 "material": "m"}]})";
  auto with_file = [&](const std::string& f) {
    std::string s = shape;
    s.replace(s.find("FILE"), 4, f);
    return s;
  };
  const std::string missing = error_of(with_file("nope.bcc"), dir_);
  EXPECT_NE(missing.find("nope.bcc"), std::string::npos) << missing;
  EXPECT_NE(missing.find("does not exist"), std::string::npos) << missing;

  {
    std::ofstream out(dir_ / "bad.bcc", std::ios::binary);
    out << "NOT A BCC FILE, JUST SOME TEXT THAT IS LONGER THAN THE 64 BYTE HEADER OF A BCC FILE....";
  }
  const std::string corrupt = error_of(with_file("bad.bcc"), dir_);
  EXPECT_NE(corrupt.find("bad.bcc"), std::string::npos) << corrupt;
  EXPECT_NE(corrupt.find("signature"), std::string::npos) << corrupt;

  {
    std::string bytes = curves::bcc_bytes({curves::Curve{{{0, 0, 0}, {1, 0, 0}}, false}});
    bytes.resize(bytes.size() - 7);
    std::ofstream out(dir_ / "short.bcc", std::ios::binary);
    out << bytes;
  }
  const std::string truncated = error_of(with_file("short.bcc"), dir_);
  EXPECT_NE(truncated.find("short.bcc"), std::string::npos) << truncated;

  const std::string no_radius =
      error_of(R"({"materials": {"m": {}}, "shapes": [{"type": "curves", "file": "bad.bcc", "material": "m"}]})", dir_);
  EXPECT_NE(no_radius.find("radius"), std::string::npos) << no_radius;
  for (const auto& e : {missing, corrupt, truncated, no_radius}) {
    EXPECT_FALSE(e.empty());
    EXPECT_EQ(e.find('\n'), std::string::npos) << e;
  }
}

TEST_F(CurveScene, CurvesRefuseMediaEmissionAndGlass) {
  (void)segment_file({0, 0, 0}, {1, 0, 0});
  const std::string glass = error_of(R"({"materials": {"g": {"type": "dielectric"}},
      "shapes": [{"type": "curves", "file": "segment.bcc", "radius": 0.1, "material": "g"}]})",
                                     dir_);
  EXPECT_NE(glass.find("diffuse or mirror"), std::string::npos) << glass;
  const std::string emits = error_of(R"({"materials": {"m": {}},
      "shapes": [{"type": "curves", "file": "segment.bcc", "radius": 0.1, "material": "m", "emission": 1}]})",
                                     dir_);
  EXPECT_NE(emits.find("emit"), std::string::npos) << emits;
}

}  // namespace
}  // namespace weft::render
