// weft export's NanoVDB grid read back with NanoVDB's own reader and compared with the source
// grid (values at every active voxel and around it, transform), the .vol header layout, and the
// scenes' comment headers (what the values are, their units, pbrt-v4's interpolation).
#include <gtest/gtest.h>

#include <unistd.h>
#include <filesystem>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>

#include <fmt/format.h>
#include <nanovdb/util/IO.h>

#include "counting_sink.h"
#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/core/progress.h"
#include "weft/core/rng.h"
#include "weft/volume/grid.h"
#include "weft/volume/renderer_export.h"

namespace weft::volume {
namespace {
namespace fs = std::filesystem;

Grid random_grid(std::uint64_t seed) {
  Grid g(0.125, "density");
  g.set_origin({1.5, -2.0, 0.25});
  Pcg32 rng = stream_for(seed, 0);
  for (int i = -3; i < 9; ++i)
    for (int j = 2; j < 7; ++j)
      for (int k = -1; k < 4; ++k)
        if (rng.uniform() < 0.6) g.set_value(i, j, k, static_cast<float>(rng.uniform()));
  return g;
}

fs::path temp_path(const std::string& name) {
  return fs::temp_directory_path() / fmt::format("weft_export_{}_{}", ::getpid(), name);
}

TEST(RendererExport, NanoVdbReadsBackWithSameValuesAndTransform) {
  const Grid g = random_grid(3);
  const fs::path path = temp_path("g.nvdb");
  write_nanovdb(g, path);
  const auto handle = nanovdb::io::readGrid(path.string(), "density");
  fs::remove(path);
  const nanovdb::FloatGrid* nano = handle.grid<float>();
  ASSERT_NE(nano, nullptr);
  EXPECT_EQ(nano->activeVoxelCount(), g.active_voxel_count());
  EXPECT_DOUBLE_EQ(nano->voxelSize()[0], g.voxel_size());
  // Transform: NanoVDB index (i, j, k) is the centre of weft's voxel (i, j, k).
  const auto o = g.origin();
  const nanovdb::Vec3d w = nano->indexToWorld(nanovdb::Vec3d(2.0, 3.0, -1.0));
  EXPECT_NEAR(w[0], o[0] + 0.125 * 2.5, 1e-12);
  EXPECT_NEAR(w[1], o[1] + 0.125 * 3.5, 1e-12);
  EXPECT_NEAR(w[2], o[2] + 0.125 * -0.5, 1e-12);
  const auto acc = nano->getAccessor();
  const IndexBox box = g.active_bbox();
  std::uint64_t compared = 0;
  for (int i = box.min[0] - 1; i <= box.max[0] + 1; ++i)
    for (int j = box.min[1] - 1; j <= box.max[1] + 1; ++j)
      for (int k = box.min[2] - 1; k <= box.max[2] + 1; ++k) {
        ASSERT_EQ(acc.getValue(nanovdb::Coord(i, j, k)), g.value(i, j, k)) << i << "," << j << "," << k;
        ++compared;
      }
  EXPECT_GT(compared, g.active_voxel_count());
  const auto bbox = nano->indexBBox();
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(bbox.min()[a], box.min[a]);
    EXPECT_EQ(bbox.max()[a], box.max[a]);
  }
}

TEST(RendererExport, WorldBoxCoversTheActiveVoxels) {
  const Grid g = random_grid(4);
  const IndexBox b = g.active_bbox();
  const WorldBox w = world_box(g, b);
  EXPECT_DOUBLE_EQ(w.min[0], 1.5 + 0.125 * b.min[0]);
  EXPECT_DOUBLE_EQ(w.max[2], 0.25 + 0.125 * (b.max[2] + 1));
  EXPECT_THROW((void)world_box(Grid(1.0), Grid(1.0).active_bbox()), Error);
}

TEST(RendererExport, VolRefusesAboveTheMemoryLimit) {
  const Grid g = random_grid(5);
  const fs::path path = temp_path("g.vol");
  EXPECT_THROW(write_mitsuba_vol(g, g.active_bbox(), path, 100), Error);
  EXPECT_FALSE(fs::exists(path));  // nothing written
}

// The first coordinate at which a float's spacing exceeds kFloatVoxelShare of a voxel of size h:
// spacings are 2^(e - 23) on [2^e, 2^(e + 1)), so it is 2^24 · share · h.
double float_edge(double h) { return std::ldexp(1.0, std::numeric_limits<float>::digits) * kFloatVoxelShare * h; }

TEST(RendererExport, WorldCoordinatesBeyondFloatResolutionAreRefused) {
  const double h = 0.25;
  const int last = static_cast<int>(float_edge(h) / h) - 1;  // its far face at the edge
  for (const ExportFormat format : {ExportFormat::mitsuba, ExportFormat::pbrt}) {
    Grid inside(h);
    inside.set_origin({0.0, 0.0, 0.0});
    inside.set_value(last - 1, 0, 0, 0.5F);
    EXPECT_NO_THROW(check_float_resolution(inside, inside.active_bbox(), format, "in.vdb"));
    Grid beyond(h);
    beyond.set_origin({0.0, 0.0, 0.0});
    beyond.set_value(last, 0, 0, 0.5F);
    EXPECT_THAT([&] { check_float_resolution(beyond, beyond.active_bbox(), format, "far.vdb: grid 'density'"); },
                test::throws_one_line_error_with(
                    {"far.vdb: grid 'density'", "world coordinates", "single precision", "nearer the world origin"}));
  }
}

// pbrt-v4 looks voxels up at float index coordinates (worldToIndexF): a grid near the world origin
// but at large indices is refused for pbrt only; Mitsuba's box-relative coordinates are small.
TEST(RendererExport, IndexCoordinatesBeyondFloatResolutionAreRefusedForPbrt) {
  const double h = 0.25;
  const int edge = static_cast<int>(float_edge(1.0));  // index faces at i ± 0.5
  for (const int i : {edge - 1, edge, 1 << 30, -(1 << 30)}) {
    Grid g(h);
    g.set_origin({-h * i, 0.0, 0.0});  // voxel i at the world origin
    g.set_value(i, 0, 0, 0.5F);
    EXPECT_NO_THROW(check_float_resolution(g, g.active_bbox(), ExportFormat::mitsuba, "g.vdb"));
    if (i == edge - 1) {
      EXPECT_NO_THROW(check_float_resolution(g, g.active_bbox(), ExportFormat::pbrt, "g.vdb"));
    } else {
      EXPECT_THAT([&] { check_float_resolution(g, g.active_bbox(), ExportFormat::pbrt, "g.vdb"); },
                  test::throws_one_line_error_with({"g.vdb", "pbrt-v4", "index coordinates", "indices nearer 0"}));
    }
  }
}

TEST(RendererExport, BothConversionsStopAtTheirProgressSinksCancel) {
  const Grid g = random_grid(6);
  const fs::path path = temp_path("stopped.nvdb");
  test::CountingSink at_nvdb(2);
  EXPECT_THROW(NanoVdbGrid(g, path, at_nvdb), Cancelled);
  EXPECT_FALSE(fs::exists(path));
  test::CountingSink at_vol(2);
  EXPECT_THROW((void)mitsuba_volume(g, g.active_bbox(), temp_path("stopped.vol"), 1U << 20U, at_vol), Cancelled);
}

TEST(RendererExport, BadMediumIsRefused) {
  ExportMedium m;
  ExportView v;
  m.albedo = {0.5, 1.5, 0.5};
  EXPECT_THROW(validate(m, v), Error);
  m.albedo = {0.5, 0.5, 0.5};
  m.g = 1.0;
  EXPECT_THROW(validate(m, v), Error);
  m.g = 0.0;
  m.sigma = std::nan("");
  EXPECT_THROW(validate(m, v), Error);
  m.sigma = 2.0;
  v.spp = 0;
  EXPECT_THROW(validate(m, v), Error);
  v.spp = 1;
  EXPECT_NO_THROW(validate(m, v));
}

/// The comment lines before the first statement of a scene: up to "<scene" or "LookAt".
std::string header_of(const std::string& scene) {
  const auto end = std::min(scene.find("\n<scene"), scene.find("\nLookAt")) + 1;
  return scene.substr(0, end);
}

TEST(RendererExport, HeadersSayWhatTheValuesAreAndTheirUnits) {
  const WorldBox box{{0.0, 0.0, 0.0}, {1.0, 2.0, 0.5}};
  const ExportView view;
  ExportMedium extinction;
  extinction.extinction = true;
  extinction.units = "mm";
  ExportMedium concentration;  // a grid without metadata: no units recorded
  concentration.sigma = 106.0;
  for (const auto& [medium, holds, units] :
       {std::tuple{extinction, "the values are extinction in 1/mm", "lengths in mm"},
        std::tuple{concentration, "the values are concentration", "no units recorded"}}) {
    for (const std::string& header : {header_of(mitsuba_scene_xml(box, "cloth.vol", medium, view)),
                                      header_of(pbrt_scene(box, "cloth.nvdb", medium, view))}) {
      EXPECT_NE(header.find(holds), std::string::npos) << header;
      EXPECT_NE(header.find(units), std::string::npos) << header;
      EXPECT_EQ(header.find(medium.extinction ? "concentration" : "extinction"), std::string::npos) << header;
      EXPECT_EQ(header.find("(mm)"), std::string::npos) << header;
    }
  }
  // A unit that would end a pbrt comment (a newline) or an XML comment ("--", "-->") stays inside it.
  ExportMedium odd;
  odd.units = "m\nCamera -->";
  const std::string pbrt = header_of(pbrt_scene(box, "cloth.nvdb", odd, view));
  EXPECT_NE(pbrt.find("lengths in m?Camera -"), std::string::npos) << pbrt;
  for (std::size_t at = 0; at < pbrt.size(); at = pbrt.find('\n', at) + 1) EXPECT_EQ(pbrt[at], '#') << pbrt;
  const std::string xml = header_of(mitsuba_scene_xml(box, "cloth.vol", odd, view));
  EXPECT_NE(xml.find("lengths in m?Camera -"), std::string::npos) << xml;
  EXPECT_EQ(xml.find("--", xml.find("<!--") + 4), xml.rfind("-->")) << xml;  // the comment's own end only
}

TEST(RendererExport, HeadersKeepAUtf8UnitAsItIs) {
  // Both scenes are UTF-8 text: "µm" is written as it is; a byte that starts no valid UTF-8
  // sequence (0xFF, the overlong 0xC0 0xAF for '/') and a C1 control (U+0085, a line end to some
  // readers) are '?'.
  const WorldBox box{{0.0, 0.0, 0.0}, {1.0, 2.0, 0.5}};
  const ExportView view;
  ExportMedium medium;
  medium.extinction = true;
  for (const auto& [units, written] : {std::tuple{std::string("\xC2\xB5m"), std::string("\xC2\xB5m")},
                                       std::tuple{std::string("\xFFm\xC0\xAF\xC2\x85"), std::string("?m???")}}) {
    medium.units = units;
    for (const std::string& header : {header_of(mitsuba_scene_xml(box, "cloth.vol", medium, view)),
                                      header_of(pbrt_scene(box, "cloth.nvdb", medium, view))}) {
      EXPECT_NE(header.find("extinction in 1/" + written + ","), std::string::npos) << header;
      EXPECT_NE(header.find("lengths in " + written + " (the grid's units)"), std::string::npos) << header;
    }
  }
}

TEST(RendererExport, ABlankUnitIsNoUnit) {
  const WorldBox box{{0.0, 0.0, 0.0}, {1.0, 2.0, 0.5}};
  const ExportView view;
  ExportMedium medium;
  for (const std::string units : {"   ", " \t"}) {
    medium.units = units;
    for (const std::string& header : {header_of(mitsuba_scene_xml(box, "cloth.vol", medium, view)),
                                      header_of(pbrt_scene(box, "cloth.nvdb", medium, view))}) {
      EXPECT_NE(header.find("lengths in the grid's own units (no units recorded)"), std::string::npos) << header;
      EXPECT_NE(header.find("in 1/length;"), std::string::npos) << header;
    }
  }
}

TEST(RendererExport, ThePbrtSceneSaysItInterpolatesTheDensity) {
  // pbrt-v4's nanovdb medium samples the density trilinearly (docs/export.md): only its scene says so.
  const WorldBox box{{0.0, 0.0, 0.0}, {1.0, 1.0, 1.0}};
  const std::string pbrt = header_of(pbrt_scene(box, "cloth.nvdb", ExportMedium{}, ExportView{}));
  EXPECT_NE(pbrt.find("# Not weft's medium: " + pbrt_interpolation_note()), std::string::npos) << pbrt;
  EXPECT_NE(pbrt_interpolation_note().find("trilinearly"), std::string::npos);
  EXPECT_EQ(header_of(mitsuba_scene_xml(box, "cloth.vol", ExportMedium{}, ExportView{})).find("trilinear"),
            std::string::npos);
}

}  // namespace
}  // namespace weft::volume
