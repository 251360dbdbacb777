#include "weft/render/local_gamma_beam.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "error_matchers.h"
#include "weft/core/parallel.h"
#include "weft/core/rng.h"
#include "weft/fit/local_fields.h"
#include "weft/render/local_gamma.h"
#include "weft/volume/grid.h"

namespace weft::render {
namespace {

namespace fs = std::filesystem;
using transmittance::MemoryRule;

/// A box of nx × ny × nz voxels of width h from index `lo`, each value from `value(i, j, k)`
/// (local indices).
template <typename F>
volume::Grid box_grid(double h, std::array<int, 3> lo, std::array<int, 3> n, F&& value) {
  volume::Grid g(h, "density");
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i) g.set_value(lo[0] + i, lo[1] + j, lo[2] + k, value(i, j, k));
  return g;
}

/// A fibre-like random field: about half the voxels empty, the rest uniform in (0, 1].
volume::Grid random_grid(std::array<int, 3> lo, std::uint64_t seed) {
  Pcg32 rng(seed);
  return box_grid(0.05, lo, {20, 16, 12}, [&](int, int, int) {
    const double u = rng.uniform();
    return u < 0.5 ? 0.0f : static_cast<float>(rng.uniform() * 0.999 + 0.001);
  });
}

fs::path write_fields_of(const volume::Grid& g, int block, const std::string& name) {
  fs::path path = fs::temp_directory_path() / ("weft_fields_beam_" + name + ".vdb");
  fit::save_local_fields(fit::local_fields(g, block), path, fit::FieldChannels::render);
  return path;
}

volume::BeamSpec beam(std::array<double, 3> d, int rays = 1) {
  volume::BeamSpec s;
  s.direction = d;
  s.rays_per_column = rays;
  s.jitter = rays > 1;
  s.seed = 7;
  return s;
}

const std::array<std::array<double, 3>, 4> kDirections{{{0, 0, 1}, {0, 0, -1}, {0.3, -0.5, 0.8}, {0, 1, 1}}};

// A uniform box whose blocks are whole is a field of one mean and zero variance: its law is the
// exponential of the same extinction, so along every ray of any beam the prediction is the voxel
// beam's T itself, depth by depth (the same rays, entries and depth grid).
TEST(FieldsBeam, UniformBoxIsTheVoxelBeamAlongAnyDirection) {
  const double c = 0.3, sigma = 20.0;
  const volume::Grid g = box_grid(0.1, {-8, 4, 12}, {16, 12, 8}, [&](int, int, int) { return static_cast<float>(c); });
  const fs::path f = write_fields_of(g, 4, "uniform");
  for (const auto& d : kDirections) {
    volume::BeamSpec spec = beam(d, 3);
    spec.scale = sigma;
    const volume::TransmittanceCurve truth = volume::measure_beam(g, spec);
    for (const MemoryRule rule : transmittance::kMemoryRules) {
      const volume::TransmittanceCurve p = predict_fields_beam({f, sigma, false, rule}, g, spec);
      ASSERT_EQ(p.size(), truth.size());
      for (std::size_t k = 0; k < p.size(); ++k) {
        EXPECT_NEAR(p.log_t[k], truth.log_t[k], 1e-9 * (1.0 + std::abs(truth.log_t[k])))
            << volume::direction_label(d) << " depth " << p.depth[k];
      }
      EXPECT_LT(p.transmittance(p.size() - 1), 0.9) << "the beam crosses the box";
    }
  }
}

// One walk for every depth gives what one walk per depth gives, under every rule and from both
// origins, through a field with vacuum, jumps and zero variances.
TEST(FieldsBeam, ProfileOfOneWalkIsTheWalkToEachEnd) {
  const fs::path f = write_fields_of(random_grid({0, 0, 0}, 3), 4, "profile");
  Pcg32 rng(11);
  for (const MemoryRule rule : transmittance::kMemoryRules) {
    LocalGammaField field(f, 30.0, rule);
    for (int n = 0; n < 60; ++n) {
      const std::array<double, 3> o{rng.uniform() * 1.0, rng.uniform() * 0.8, -0.2};
      std::array<double, 3> d{rng.uniform() - 0.5, rng.uniform() - 0.5, 0.6 + rng.uniform()};
      const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
      for (double& x : d) x /= len;
      const volume::Ray ray{o, d};
      std::vector<double> ends;
      for (double t = -0.05; t < 1.2; t += 0.037) ends.push_back(t);
      for (const auto origin : {transmittance::Origin::source, transmittance::Origin::scatterer}) {
        std::vector<double> out(ends.size());
        field.log_transmittance_profile(ray, 0.0, ends, out, origin);
        for (std::size_t k = 0; k < ends.size(); ++k) {
          const double one = ends[k] > 0.0 ? field.log_transmittance(ray, 0.0, ends[k], origin) : 0.0;
          EXPECT_NEAR(out[k], one, 1e-12 * (1.0 + std::abs(one))) << "end " << ends[k];
        }
      }
    }
  }
}

TEST(FieldsBeam, SameBytesForAnyThreadCount) {
  const volume::Grid g = random_grid({0, 0, 0}, 5);
  const fs::path f = write_fields_of(g, 4, "threads");
  const volume::BeamSpec spec = beam({0.3, -0.5, 0.8}, 2);
  volume::TransmittanceCurve one;
  volume::TransmittanceCurve two;
  {
    const ThreadLimit limit(1);
    one = predict_fields_beam({f, 30.0}, g, spec);
  }
  {
    const ThreadLimit limit(2);
    two = predict_fields_beam({f, 30.0}, g, spec);
  }
  EXPECT_EQ(one.log_t, two.log_t);
  EXPECT_EQ(one.rel_stderr, two.rel_stderr);
  EXPECT_EQ(one.rays, two.rays);
}

// The blocks are anchored to the cloth (volume/block_lattice.h), so the same voxels at another
// index origin give the same fields and the same prediction.
TEST(FieldsBeam, TranslatedGridGivesTheSamePrediction) {
  const volume::Grid a = random_grid({0, 0, 0}, 9);
  const volume::Grid b = random_grid({37, -1029, 5}, 9);
  const fs::path fa = write_fields_of(a, 4, "at_zero");
  const fs::path fb = write_fields_of(b, 4, "moved");
  for (const auto& d : kDirections) {
    const volume::TransmittanceCurve pa = predict_fields_beam({fa, 30.0}, a, beam(d));
    const volume::TransmittanceCurve pb = predict_fields_beam({fb, 30.0}, b, beam(d));
    ASSERT_EQ(pa.size(), pb.size());
    EXPECT_EQ(pa.rays, pb.rays);
    for (std::size_t k = 0; k < pa.size(); ++k) EXPECT_NEAR(pa.log_t[k], pb.log_t[k], 1e-9) << k;
  }
}

TEST(FieldsBeam, FieldsNotOnTheGridAreRefused) {
  const volume::Grid g = random_grid({0, 0, 0}, 13);
  const fs::path f = write_fields_of(g, 4, "own");
  // Other voxels: cells of 1.5 voxels of a grid of 0.1/3.
  const volume::Grid fine = box_grid(0.05 * 4 / 1.5, {0, 0, 0}, {4, 4, 4}, [](int, int, int) { return 0.5f; });
  EXPECT_THAT(
      [&] {
        (void)predict_fields_beam({f, 30.0}, fine, beam({0, 0, 1}));
      },
      test::throws_one_line_error_with({"not a whole number of grid 'density''s voxels"}));
  // Half a voxel off.
  volume::Grid shifted = random_grid({0, 0, 0}, 13);
  shifted.set_origin({0.025, 0.0, 0.0});
  EXPECT_THAT(
      [&] {
        (void)predict_fields_beam({f, 30.0}, shifted, beam({0, 0, 1}));
      },
      test::throws_one_line_error_with({"not on grid 'density''s voxel corners"}));
  // Elsewhere.
  const volume::Grid far = random_grid({400, 0, 0}, 13);
  EXPECT_THAT(
      [&] {
        (void)predict_fields_beam({f, 30.0}, far, beam({0, 0, 1}));
      },
      test::throws_one_line_error_with({"do not overlap grid 'density'"}));
  // The medium's own checks, naming the file.
  EXPECT_THAT(
      [&] {
        (void)predict_fields_beam({fs::temp_directory_path() / "no_such_fields.vdb", 30.0}, g, beam({0, 0, 1}));
      },
      test::throws_one_line_error_with({"no_such_fields.vdb"}));
}

// Fields must be the grid's own block means (docs/validate.md "Fields along any direction"): of
// another cloth on the same box, of a part of it, of a larger cloth, they are refused by
// check_fields, naming the file and the cell; the same cloth refined (h/2, blocks of 8) is the
// grid's own fields. Python's words name no CLI option.
TEST(FieldsBeam, FieldsOfAnotherClothAreRefused) {
  const volume::Grid g = random_grid({0, 0, 0}, 21);
  const auto refused = [&](const fs::path& f, const volume::Grid& grid) {
    EXPECT_THAT(
        [&] {
          (void)check_fields({f, 30.0}, grid);
        },
        test::throws_one_line_error_with(
            {f.string(), "not grid 'density''s fields", "its cell at", "weft fit --grid GRID --block B"}))
        << f;
  };
  // Another cloth on the same box (another seed).
  refused(write_fields_of(random_grid({0, 0, 0}, 22), 4, "other_seed"), g);
  // A part of it: the same voxels but the last four layers.
  const volume::Grid part =
      box_grid(0.05, {0, 0, 0}, {20, 16, 8}, [&](int i, int j, int k) { return g.value(i, j, k); });
  refused(write_fields_of(part, 4, "part"), g);
  // A larger cloth: the grid and a slab beyond it.
  volume::Grid larger = random_grid({0, 0, 0}, 21);
  for (int i = 0; i < 20; ++i)
    for (int j = 0; j < 16; ++j) larger.set_value(i, j, 14, 0.5f);
  refused(write_fields_of(larger, 4, "larger"), g);
  // The same cloth refined: each voxel 2×2×2 of half the width.
  volume::Grid refined(0.025, "density");
  refined.set_origin(g.origin());  // the same world box
  for (int i = 0; i < 40; ++i)
    for (int j = 0; j < 32; ++j)
      for (int k = 0; k < 24; ++k) {
        const float v = g.value(i / 2, j / 2, k / 2);
        if (v > 0.0f) refined.set_value(i, j, k, v);
      }
  const fs::path own = write_fields_of(refined, 8, "refined");
  EXPECT_NO_THROW((void)check_fields({own, 30.0}, g));
  EXPECT_NO_THROW((void)check_fields({write_fields_of(g, 4, "own21"), 30.0}, refined));
  // Python's words.
  FieldsSpec py{write_fields_of(part, 4, "part_py"), 30.0};
  py.asker = FrontEnd::python;
  EXPECT_THAT([&] { (void)check_fields(py, g); },
              test::throws_one_line_error_with({"not grid 'density''s fields", "weft.local_fields(grid, B)"}));
}

// Fields that record a value kind other than the grid's are another grid's: the advice is one the
// caller can follow (--values only when the grid records no kind, and only on the command line).
TEST(FieldsBeam, FieldsOfTheOtherValueKindAreRefusedWithAdviceForTheCaller) {
  volume::Grid g = random_grid({0, 0, 0}, 23);
  volume::Grid as_extinction = g.deep_copy();
  as_extinction.set_metadata("weft:value_kind", "extinction");
  const fs::path f = write_fields_of(as_extinction, 4, "extinction_kind");
  // The grid records no kind, read as concentration.
  FieldsSpec spec{f, 30.0};
  EXPECT_THAT([&] { (void)check_fields(spec, g); },
              test::throws_one_line_error_with({f.string(), "values are extinction", "no kind recorded",
                                                "pass --values extinction", "weft fit --grid GRID --block B"}));
  spec.asker = FrontEnd::python;
  const auto python_message = [&] {
    try {
      (void)check_fields(spec, g);
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  }();
  EXPECT_THAT(python_message, ::testing::HasSubstr("grid.set_metadata('weft:value_kind', 'extinction')"));
  EXPECT_THAT(python_message, ::testing::Not(::testing::HasSubstr("--values")));
  // The grid records concentration: no option helps, only fields of this grid.
  g.set_metadata("weft:value_kind", "concentration");
  spec.asker = FrontEnd::cli;
  EXPECT_THAT([&] { (void)check_fields(spec, g); },
              test::throws_one_line_error_with(
                  {"grid 'density''s say concentration", "fields of another grid", "weft fit --grid GRID --block B"}));
  EXPECT_THAT([&] { (void)check_fields(spec, g); }, ::testing::Not(test::throws_one_line_error_with({"--values"})));
  // Read as extinction, as the fields say: taken.
  EXPECT_NO_THROW((void)check_fields({f, 1.0, true}, as_extinction));
}

}  // namespace
}  // namespace weft::render

namespace weft::render {
namespace {

// A uniform slab crossed obliquely: the rays that cross it face to face all have T = e^{−μ·depth}
// at the last depth, the ones through its sides more. full_chords keeps exactly the former, in the
// voxel beam and in the fields' prediction alike.
TEST(FieldsBeam, FullChordsKeepTheRaysThatCrossTheSlabFaceToFace) {
  const double c = 0.5, sigma = 10.0;
  const volume::Grid g = box_grid(0.1, {0, 0, 0}, {24, 24, 4}, [&](int, int, int) { return static_cast<float>(c); });
  const fs::path f = write_fields_of(g, 4, "slab");
  volume::BeamSpec spec = beam({0.0, 0.6, 0.8}, 2);
  spec.scale = sigma;
  const volume::TransmittanceCurve all = volume::measure_beam(g, spec);
  spec.full_chords = true;
  const volume::TransmittanceCurve face = volume::measure_beam(g, spec);
  const volume::TransmittanceCurve pred = predict_fields_beam({f, sigma}, g, spec);
  const std::size_t last = face.size() - 1;
  const double depth = face.depth[last];
  EXPECT_NEAR(depth, 0.4 / 0.8, 1e-12);
  EXPECT_NEAR(face.log_t[last], -sigma * c * depth, 1e-9);
  EXPECT_NEAR(pred.log_t[last], -sigma * c * depth, 1e-9);
  EXPECT_EQ(pred.rays, face.rays);
  EXPECT_LT(face.rays, all.rays);
  EXPECT_GT(all.transmittance(last), 1.05 * face.transmittance(last)) << "side rays raise the mean";
  // An axis beam crosses the whole box anyway: the same curve either way.
  volume::BeamSpec axis = beam({0.0, 0.0, 1.0});
  axis.scale = sigma;
  const volume::TransmittanceCurve a0 = volume::measure_beam(g, axis);
  axis.full_chords = true;
  EXPECT_EQ(volume::measure_beam(g, axis).log_t, a0.log_t);
}

}  // namespace
}  // namespace weft::render
