#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "data_gen/cloth/cloth.h"
#include "data_gen/cloth/grid_fibres.h"
#include "data_gen/cloth/pattern.h"
#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/volume/dense.h"
#include "weft/volume/grid.h"

namespace weft::cloth {
namespace {
namespace fs = std::filesystem;

ClothSpec small_spec() {
  ClothSpec spec = default_cloth_spec();
  spec.warp_count = 2;
  spec.weft_count = 2;
  spec.pattern = "twill21";
  spec.voxel_size = 0.02;
  spec.seed = 77;
  return resolve(spec);
}

bool same_grid(const volume::Grid& a, const volume::Grid& b) {
  if (a.active_voxel_count() != b.active_voxel_count() || a.voxel_size() != b.voxel_size()) return false;
  const auto box = a.active_bbox();
  for (int i = box.min[0]; i <= box.max[0]; ++i) {
    for (int j = box.min[1]; j <= box.max[1]; ++j) {
      for (int k = box.min[2]; k <= box.max[2]; ++k) {
        if (a.value(i, j, k) != b.value(i, j, k)) return false;
      }
    }
  }
  return true;
}

TEST(Cloth, WarnsOfSaturatedLoopsAndOfALargeClampedOverlap) {
  EXPECT_TRUE(cloth_warnings(build_cloth(small_spec(), null_progress())).empty());
  // Yarns 10 µm apart lie in one another.
  ClothSpec close = small_spec();
  close.warp_spacing = close.weft_spacing = 0.01;
  const ClothBuild b = build_cloth(close, null_progress());
  ASSERT_GT(b.report.overlap_fraction, kOverlapWarning);
  const auto w = cloth_warnings(b);
  ASSERT_EQ(w.size(), 1U);
  EXPECT_NE(w[0].find("of the fibre volume overlaps other fibres and was clamped at C = 1 (over 10 %)"),
            std::string::npos)
      << w[0];
  // Loops: 3 over each fibre point, said once for both directions' equal yarns, in each front
  // end's words; a knit has one yarn.
  ClothSpec loops = small_spec();
  loops.warp_yarn.loop_density = loops.weft_yarn.loop_density = 100.0;
  const ClothBuild l = build_cloth(loops, null_progress());
  const auto cli = cloth_warnings(l);
  ASSERT_EQ(cli.size(), 1U);
  EXPECT_EQ(cli[0].rfind("yarns: --set loop_density=100 puts 3 loop flyaways over each fibre point", 0), 0U) << cli[0];
  const auto py = cloth_warnings(l, FrontEnd::python);
  ASSERT_EQ(py.size(), 1U);
  EXPECT_EQ(py[0].rfind("yarns: loop_density=100 puts", 0), 0U) << py[0];
  loops.weft_yarn.loop_density = 2.0;
  const auto warp_only = cloth_warnings(build_cloth(loops, null_progress()));
  ASSERT_EQ(warp_only.size(), 1U);
  EXPECT_EQ(warp_only[0].rfind("warp yarn: ", 0), 0U) << warp_only[0];
}

TEST(Cloth, JsonRoundTripRebuildsAnIdenticalGrid) {
  const ClothSpec spec = small_spec();
  const ClothBuild first = build_cloth(spec, null_progress());
  const std::string text = cloth_spec_json(first.spec);
  const ClothSpec back = cloth_spec_from_json(text, "cloth.json");
  EXPECT_EQ(cloth_spec_json(back), text);
  const ClothBuild second = build_cloth(back, null_progress());
  EXPECT_EQ(first.fibers.points, second.fibers.points);
  EXPECT_TRUE(same_grid(first.grid, second.grid));
  EXPECT_GT(first.grid.active_voxel_count(), 1000U);
  // Another seed gives another cloth.
  ClothSpec other = spec;
  other.seed = 78;
  EXPECT_FALSE(same_grid(first.grid, build_cloth(other, null_progress()).grid));
}

TEST(Cloth, GridCarriesProvenanceAndConservesVolume) {
  const ClothBuild b = build_cloth(small_spec(), null_progress());
  const auto meta = b.grid.metadata();
  EXPECT_EQ(meta.at("units"), "mm");
  EXPECT_EQ(meta.at("seed"), "77");
  EXPECT_EQ(std::stod(meta.at("voxel_size")), 0.02);
  EXPECT_EQ(cloth_spec_from_json(meta.at("generator"), "metadata").seed, 77U);
  EXPECT_EQ(b.report.fiber_count, b.fibers.size());
  // Σ C·h³ + clamped overlap = Σ length·πr² (the quadrature conserves volume for any h).
  EXPECT_NEAR(b.report.grid_volume + b.report.overlap_fraction * b.report.fiber_volume, b.report.fiber_volume,
              1e-5 * b.report.fiber_volume);
  EXPECT_NEAR(b.grid.sum() * std::pow(0.02, 3), b.report.grid_volume, 1e-5 * b.report.grid_volume);
}

/// The voxels of `g` at index `min`, origin `origin` and voxel size `h`, with its metadata.
volume::Grid placed(const volume::Grid& g, const std::array<int, 3>& min, const std::array<double, 3>& origin,
                    double h) {
  const volume::IndexBox box = g.active_bbox();
  const std::vector<float> values = volume::to_dense(g, box, volume::dense_bytes(box));
  volume::Grid out(h, g.name());
  out.set_origin(origin);
  volume::from_dense(out, min, box.extent(), values.data());
  for (const auto& [k, v] : g.metadata()) out.set_metadata(k, v);
  return out;
}

// docs/validate.md §Fibre ground truth: a grid is compared with its fibres only on the lattice
// weft gen voxelized them on (recorded voxel size, origin and active box), within rounding; a
// tolerance of two voxels once let a grid moved by half a voxel, one or two voxels through.
TEST(Cloth, FibresAreComparedOnlyWithTheGridOnTheirLattice) {
  const ClothBuild b = build_cloth(small_spec(), null_progress());
  const volume::Grid& g = b.grid;
  const double h = g.voxel_size();
  const volume::IndexBox box = g.active_bbox();
  ASSERT_EQ(g.origin(), (std::array<double, 3>{0.0, 0.0, 0.0}));  // the voxelizer's lattice
  EXPECT_NO_THROW(check_voxelized_lattice(g, "cloth"));
  EXPECT_EQ(fibers_of_grid(g, "cloth").points, b.fibers.points);
  // The same world at other indices, near 0 and 10⁶ voxels out (the origin moved back), and
  // through a file: the same lattice up to rounding.
  for (int shift : {-3, 1000000}) {
    const std::array<int, 3> min{box.min[0] + shift, box.min[1], box.min[2] - shift};
    const volume::Grid same = placed(g, min, {-shift * h, 0.0, shift * h}, h);
    EXPECT_NO_THROW(check_voxelized_lattice(same, "same")) << shift;
  }
  const fs::path file = fs::temp_directory_path() / "weft_lattice_check.vdb";
  g.save(file);
  EXPECT_NO_THROW(check_voxelized_lattice(volume::Grid::load(file), "loaded"));
  fs::remove(file);
  // Moved by a thousandth of a voxel, half a voxel, one voxel: refused, saying by how much.
  const auto moved = [&](const volume::Grid& m, const std::string& by) {
    EXPECT_THAT([&] { check_voxelized_lattice(m, "moved.vdb"); },
                weft::test::throws_one_line_error_with(
                    {"moved.vdb: the grid was moved relative to its fibres: its active box's low corner by (" + by,
                     "where weft gen voxelized its fibres on"}));
    EXPECT_THAT([&] { (void)fibers_of_grid(m, "moved.vdb"); },
                weft::test::throws_one_line_error_with({"moved relative to its fibres"}));
  };
  moved(placed(g, box.min, {1e-3 * h, 0.0, 0.0}, h), "+0.001, +0, +0) voxels");
  moved(placed(g, box.min, {-0.5 * h, -0.5 * h, -0.5 * h}, h), "-0.5, -0.5, -0.5) voxels");
  moved(placed(g, {box.min[0], box.min[1] + 1, box.min[2]}, {0.0, 0.0, 0.0}, h), "+0, +1, +0) voxels");
  EXPECT_THAT(
      [&] {
        check_voxelized_lattice(placed(g, box.min, {0.0, 0.0, 0.0}, 2.0 * h), "coarse.vdb");
      },
      weft::test::throws_one_line_error_with(
          {"coarse.vdb: the grid was resampled relative to its fibres: voxels of 0.04 against the 0.02"}));
  // No record (an earlier weft gen) or a broken one: refused, never trusted.
  volume::Grid legacy(h, "density");
  legacy.set_origin({0.0, 0.0, 0.0});
  legacy.set_value(0, 0, 0, 0.5f);
  legacy.set_metadata("generator", g.metadata().at("generator"));
  EXPECT_THAT([&] { check_voxelized_lattice(legacy, "old.vdb"); },
              weft::test::throws_one_line_error_with(
                  {"old.vdb: the grid does not record the lattice its fibres were voxelized on", "weft gen --config"}));
  legacy.set_metadata(kVoxelizedLatticeKey, "{\"voxel_size\": 0.02}");
  EXPECT_THAT([&] { check_voxelized_lattice(legacy, "old.vdb"); },
              weft::test::throws_one_line_error_with({"old.vdb: metadata 'voxelized_lattice' is not a lattice"}));
  // Indices are read strictly: one beyond the index range (2^40 was once cut to its low 32 bits,
  // +0 here) or not an integer (-6.5 was once read as -6) makes the record invalid, not another box.
  auto record = nlohmann::json::parse(g.metadata().at(kVoxelizedLatticeKey));
  const auto with_index = [&](const std::string& key, const nlohmann::json& v) {
    auto r = record;
    r[key][0] = v;
    volume::Grid copy = g.deep_copy();
    copy.set_metadata(kVoxelizedLatticeKey, r.dump());
    return copy;
  };
  EXPECT_NO_THROW(check_voxelized_lattice(with_index("active_index_max", record["active_index_max"][0]), "same"));
  for (const auto& bad : std::vector<std::pair<std::string, nlohmann::json>>{
           {"active_index_max", std::int64_t{1} << 40},
           {"active_index_max", std::uint64_t{1} << 63},
           {"active_index_min", record["active_index_min"][0].get<double>() - 0.5},
           {"active_index_min", -2147479552},
           {"active_index_min", "-6"}}) {
    const std::string& key = bad.first;
    const nlohmann::json& v = bad.second;
    EXPECT_THAT([&] { check_voxelized_lattice(with_index(key, v), "bad.vdb"); },
                weft::test::throws_one_line_error_with(
                    {"bad.vdb: metadata 'voxelized_lattice' is not a lattice: index " + v.dump(), "2147479551"}))
        << v.dump();
    EXPECT_THAT([&] { (void)read_voxelized_lattice(with_index(key, v), "bad.vdb"); },
                weft::test::throws_one_line_error_with({"is not a lattice"}));
  }
  // The lattice read is the one recorded, and a grid is checked against another grid's lattice.
  const VoxelizedLattice lattice = read_voxelized_lattice(g, "cloth");
  EXPECT_EQ(lattice.voxel_size, h);
  EXPECT_EQ(lattice.active.min, box.min);
  EXPECT_EQ(lattice.active.max, box.max);
  EXPECT_NO_THROW(
      check_on_lattice(legacy.deep_copy(), VoxelizedLattice{h, {0.0, 0.0, 0.0}, {{0, 0, 0}, {0, 0, 0}}}, "one"));
  EXPECT_THAT([&] { check_on_lattice(legacy, lattice, "other.vdb"); },
              weft::test::throws_one_line_error_with({"other.vdb: the grid was moved relative to its fibres"}));
}

TEST(Cloth, SpecJsonRejectsBadFields) {
  const std::string good = cloth_spec_json(small_spec());
  const auto with = [&](const std::string& key, const nlohmann::json& value) {
    auto j = nlohmann::json::parse(good);
    j[key] = value;
    return j.dump();
  };
  const std::vector<std::pair<std::string, std::string>> cases = {
      {with("voxel_size", -1.0), "voxel_size"},
      {with("warp_spacing", "wide"), "warp_spacing"},
      {with("colour", 3), "colour"},
      {with("warp_count", 2.5), "warp_count"},
      {"{ not json", "invalid JSON"},
      {R"({"pattern": "plain", "pattern": "twill"})", "key 'pattern' appears twice"},
  };
  for (const auto& [text, expected] : cases) {
    // An init-capture: clang before 16 (clang-tidy here is 14) cannot capture a structured binding.
    EXPECT_THAT([&json = text] { cloth_spec_from_json(json, "in.json"); },
                weft::test::throws_one_line_error_with({expected, "in.json"}))
        << text;
  }
  auto j = nlohmann::json::parse(good);
  j["warp_yarn"]["fiber_radius"] = -0.1;
  EXPECT_THROW(cloth_spec_from_json(j.dump(), "in.json"), Error);
  EXPECT_THROW(load_cloth_spec("/nonexistent/cloth.json"), Error);
}

TEST(Cloth, AnInputScaleThatBreaksTheCurvesNamesTheFileAndTheScale) {
  const fs::path obj = fs::temp_directory_path() / "weft_scaled_curve.obj";
  std::ofstream(obj) << "v 0 0 0\nv 2 0 0\nl 1 2\n";
  const auto message = [&](double scale) {
    ClothSpec spec = default_cloth_spec();
    spec.pattern = "import";
    spec.input = obj.string();
    spec.input_scale = scale;
    try {
      (void)cloth_centerlines(resolve(spec));
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string tiny = message(1e-300);
  EXPECT_NE(tiny.find(obj.string() + ": curve 0 at input_scale 1e-300 has fewer than two distinct"), std::string::npos)
      << tiny;
  const std::string short_one = message(1e-6);
  EXPECT_NE(short_one.find("at input_scale 1e-06 is 2e-06 mm long, under a thousandth"), std::string::npos)
      << short_one;
  const std::string huge = message(1e308);
  EXPECT_NE(huge.find("input_scale 1e+308 takes curve 0 beyond the range of numbers"), std::string::npos) << huge;
  EXPECT_EQ(message(1.0), "accepted");
  fs::remove(obj);
}

// The message of a refused spec, or "accepted".
std::string refusal(const ClothSpec& spec) {
  try {
    validate(spec);
  } catch (const Error& e) {
    return e.what();
  }
  return "accepted";
}

// The number after `before` in `text` (a bound the message gives), NaN when absent.
double number_after(const std::string& text, const std::string& before) {
  const auto at = text.find(before);
  return at == std::string::npos ? std::nan("") : std::stod(text.substr(at + before.size()));
}

TEST(Cloth, AClothPastTheIndexRangeNamesTheInputThatPutsItThere) {
  // As `weft gen` builds it: automatic (0) spacings and crimp, from the yarn radius (resolve).
  ClothSpec spec = default_cloth_spec();
  spec.warp_count = spec.weft_count = 2;
  spec.warp_spacing = spec.weft_spacing = spec.crimp = 0.0;
  const auto with_yarns = [&](double ply_radius, double ply_offset) {
    ClothSpec s = spec;
    for (YarnParams* y : {&s.warp_yarn, &s.weft_yarn}) {
      y->ply_radius = ply_radius;
      y->ply_offset = ply_offset;
    }
    return s;
  };
  // A huge ply radius or offset: the yarn's field is named, not the automatic crimp it makes.
  const std::string radius = refusal(with_yarns(1e6, 0.07));
  EXPECT_EQ(radius.rfind("the warp_yarn radius 1e+06 mm (ply_offset 0.07 + ply_radius 1e+06 x", 0), 0U) << radius;
  EXPECT_THAT(radius, ::testing::HasSubstr("through the automatic warp_count x warp_spacing (2 x 3.6e+06 mm)"));
  const std::string offset = refusal(with_yarns(0.08, 1e7));
  EXPECT_EQ(offset.rfind("the warp_yarn radius 1e+07 mm (ply_offset 1e+07 + ply_radius 0.08", 0), 0U) << offset;
  // The bounds given are the real ones: the yarns scaled to just under the radius named fit, just
  // over it do not, and so for the voxel size.
  const double r = yarn_envelope_radius(with_yarns(1e6, 0.07).warp_yarn);
  const double fits = number_after(radius, "the yarn radius must be below ");
  const double h = number_after(radius, "or voxel_size above ");
  ASSERT_TRUE(fits > 0.0 && h > 0.0) << radius;
  EXPECT_EQ(refusal(with_yarns(1e6 * 0.98 * fits / r, 0.07 * 0.98 * fits / r)), "accepted");
  EXPECT_NE(refusal(with_yarns(1e6 * 1.02 * fits / r, 0.07 * 1.02 * fits / r)), "accepted");
  ClothSpec coarse = with_yarns(1e6, 0.07);
  coarse.voxel_size = 1.02 * h;
  EXPECT_EQ(refusal(coarse), "accepted");
  coarse.voxel_size = 0.98 * h;
  EXPECT_NE(refusal(coarse), "accepted");
  // A crimp given is named as before; given placements under the range with a yarn that is not, the yarn.
  ClothSpec crimp = spec;
  crimp.crimp = 1e300;
  EXPECT_EQ(refusal(crimp).rfind("crimp 1e+300 mm puts the yarns 1e+300 mm from the origin", 0), 0U) << refusal(crimp);
  // A crimp given under the range by less than the yarn's radius is named, not the radius, with a
  // bound of its own that is the real one; the voxel size that fits is above the one given.
  ClothSpec near = spec;
  near.crimp = static_cast<double>(kMaxVoxelIndex) * near.voxel_size * (1.0 - 1e-9);
  const std::string past = refusal(near);
  EXPECT_EQ(past.rfind("crimp ", 0), 0U) << past;
  const double crimp_fits = number_after(past, "crimp must be below ");
  ASSERT_LT(crimp_fits, near.crimp) << past;
  near.crimp = crimp_fits;
  EXPECT_EQ(refusal(near), "accepted");
  near.crimp = 1.0001 * (static_cast<double>(kMaxVoxelIndex) * spec.voxel_size - yarn_envelope_radius(spec.warp_yarn));
  EXPECT_NE(refusal(near), "accepted");
  EXPECT_GT(number_after(past, "or voxel_size above "), spec.voxel_size) << past;
  ClothSpec given = with_yarns(1e6, 0.07);
  given.crimp = 0.1;
  given.warp_spacing = given.weft_spacing = 1.0;
  EXPECT_THAT(refusal(given), ::testing::HasSubstr("the warp_yarn radius 1e+06 mm"));
  EXPECT_THAT(refusal(given), ::testing::HasSubstr("through warp_count x warp_spacing (2 x 1 mm),"));

  // The voxel size, with its range: OpenVDB's smallest voxel, and no larger than the cloth.
  ClothSpec voxel = spec;
  voxel.voxel_size = 1e-300;
  EXPECT_EQ(refusal(voxel).rfind("voxel_size 1e-300 mm is below the smallest voxel OpenVDB represents", 0), 0U)
      << refusal(voxel);
  voxel.voxel_size = volume::min_voxel_size();
  EXPECT_EQ(refusal(voxel), "accepted");
  voxel.voxel_size = 1e300;
  const std::string huge = refusal(voxel);
  EXPECT_EQ(huge.rfind("voxel_size 1e+300 mm holds all of the cloth", 0), 0U) << huge;
  voxel.voxel_size = 0.98 * number_after(huge, "voxel_size must be < ");
  EXPECT_EQ(refusal(voxel), "accepted");
}

TEST(Cloth, ALeadingUtf8ByteOrderMarkIsSkipped) {
  const std::string text = "\xEF\xBB\xBF" + cloth_spec_json(small_spec());
  EXPECT_EQ(cloth_spec_from_json(text, "in.json").pattern, "twill21");
  const fs::path path = fs::temp_directory_path() / "weft_bom_cloth.json";
  std::ofstream(path, std::ios::binary) << text;
  EXPECT_EQ(load_cloth_spec(path).seed, 77U);
  fs::remove(path);
}

TEST(Cloth, ARelativeInputInAConfigIsBesideTheConfigNotTheWorkingFolder) {
  // docs/cloth.md "Patterns": a config and its curves move together; the path is kept absolute.
  const fs::path dir = fs::temp_directory_path() / "weft_cloth_relative_input";
  fs::remove_all(dir);
  fs::create_directories(dir / "imp" / "curves");
  std::ofstream(dir / "imp" / "rel_cloth.json") << R"({"pattern": "import", "input": "curves/../curves/c.obj"})";
  std::ofstream(dir / "imp" / "abs_cloth.json") << R"({"pattern": "import", "input": "/data/c.obj"})";
  const fs::path cwd = fs::current_path();
  fs::current_path(dir);  // the relative config path too, as `weft gen --config imp/rel_cloth.json`
  const ClothSpec rel = load_cloth_spec("imp/rel_cloth.json");
  const ClothSpec abs = load_cloth_spec(dir / "imp" / "abs_cloth.json");
  fs::current_path(cwd);
  EXPECT_EQ(rel.input, (dir / "imp" / "curves" / "c.obj").string());
  EXPECT_EQ(abs.input, "/data/c.obj");
  // From text alone (Python's spec dicts) there is no folder: the name is kept as given.
  EXPECT_EQ(cloth_spec_from_json(R"({"pattern": "import", "input": "c.obj"})", "in.json").input, "c.obj");
  fs::remove_all(dir);
}

TEST(Cloth, PresetFillsUnsetFieldsAndTheLabelRecordsEveryChange) {
  EXPECT_EQ(yarn_label(yarn_preset("silk")), "silk");
  EXPECT_EQ(label_preset("wool (modified: fiber_count, ply_radius)"), "wool");
  EXPECT_EQ(label_preset("wool"), "wool");
  auto j = nlohmann::json::parse(cloth_spec_json(small_spec()));
  j["warp_yarn"] = {{"preset", "wool"}, {"fiber_count", 30}};
  j["weft_yarn"] = {{"preset", "wool"}};
  const ClothSpec spec = cloth_spec_from_json(j.dump(), "in.json");
  const YarnParams wool = yarn_preset("wool");
  EXPECT_EQ(spec.warp_yarn.fiber_count, 30);
  EXPECT_EQ(spec.warp_yarn.ply_radius, wool.ply_radius);  // filled by the preset, not cotton's default
  EXPECT_EQ(yarn_label(spec.warp_yarn), "wool (modified: fiber_count)");
  EXPECT_EQ(yarn_label(spec.weft_yarn), "wool");
  // Written and read back, the label stays true and the spec the same.
  const std::string text = cloth_spec_json(spec);
  EXPECT_EQ(nlohmann::json::parse(text)["warp_yarn"]["preset"], "wool (modified: fiber_count)");
  EXPECT_EQ(cloth_spec_json(cloth_spec_from_json(text, "cloth.json")), text);
}

TEST(Cloth, AFullYarnOfOnePresetUnderAnotherNameIsRefusedNamingBoth) {
  auto j = nlohmann::json::parse(cloth_spec_json(small_spec()));  // every field: cotton's
  j["warp_yarn"]["preset"] = "wool";
  EXPECT_THAT([&] { cloth_spec_from_json(j.dump(), "in.json"); },
              weft::test::throws_one_line_error_with(
                  {"in.json", "warp_yarn.preset", "'wool'", "cotton's", "ply_radius 0.08, wool's 0.11"}))
      << "a cotton yarn labelled wool";
  // A full yarn with an edited field is a modification, recorded, not an error.
  j["warp_yarn"]["preset"] = "cotton";
  j["warp_yarn"]["fiber_count"] = 20;
  EXPECT_EQ(yarn_label(cloth_spec_from_json(j.dump(), "in.json").warp_yarn), "cotton (modified: fiber_count)");
  j["warp_yarn"]["preset"] = "lace";
  EXPECT_THROW(cloth_spec_from_json(j.dump(), "in.json"), Error);
}

TEST(Cloth, ImportedCurvesGetFibres) {
  const fs::path dir = fs::temp_directory_path() / "weft_cloth_import_test";
  fs::create_directories(dir);
  {
    std::ofstream out(dir / "yarn.obj");
    out << "v 0 0 0\nv 0.3 0.05 0\nv 0.6 0 0.02\nv 0.9 -0.05 0\nl 1 2 3 4\n";
  }
  ClothSpec spec = small_spec();
  spec.pattern = "import";
  spec.input = (dir / "yarn.obj").string();
  const ClothBuild b = build_cloth(spec, null_progress());
  EXPECT_EQ(b.centerlines.curves.size(), 1U);
  EXPECT_GE(b.fibers.size(), static_cast<std::size_t>(spec.warp_yarn.ply_count * spec.warp_yarn.fiber_count));
  EXPECT_GT(b.grid.active_voxel_count(), 0U);
  spec.input = (dir / "missing.bcc").string();
  EXPECT_THROW(build_cloth(spec, null_progress()), Error);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace weft::cloth
