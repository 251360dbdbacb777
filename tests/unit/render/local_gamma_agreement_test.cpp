// The predicted local-gamma beam (fit::predict_axis) and an albedo-0 render through the same
// local fields (render's local-gamma medium) are one model: both walk the same
// transmittance::GammaHazard, so the image's mean is the predicted T at the slab's thickness
// within its standard error (docs/render.md §5b, docs/validate.md "The models").
#include <cmath>
#include <filesystem>
#include <string>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "image_mean.h"
#include "weft/fit/local_fields.h"
#include "weft/fit/models.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"
#include "weft/volume/grid.h"

namespace weft::render {
namespace {

namespace fs = std::filesystem;

constexpr int kN = 16;      // fine voxels per edge
constexpr double kH = 0.1;  // fine voxel size: the slab is [0, 1.6]³
constexpr int kBlock = 8;   // 2 × 2 × 2 coarse blocks
constexpr double kSigma = 1.2;

/// A fine grid whose columns along z are correlated (a column's level is set by (i, j)) and vary
/// along z, every voxel positive (all active): blocks have a mean and a column-mean variance.
volume::Grid fine_grid() {
  volume::Grid g(kH, "density");
  g.set_origin({0.0, 0.0, 0.0});
  for (int i = 0; i < kN; ++i)
    for (int j = 0; j < kN; ++j) {
      const double level = 0.05 + 2.0 * std::pow(static_cast<double>((i * 7 + j * 13) % 17) / 16.0, 3.0);
      for (int k = 0; k < kN; ++k) {
        const double along = 1.0 + 0.6 * std::sin(0.9 * k + 0.4 * i) + (k >= kBlock && (i + j) % 5 == 0 ? 1.5 : 0.0);
        g.set_value(i, j, k, static_cast<float>(level * along));
      }
    }
  return g;
}

using test::Estimate;
using test::image_mean;

/// A far pinhole camera on −z whose film covers exactly the slab's face z = 0, looking along +z
/// (rays within 1e-3 rad of the axis), an albedo-0 local-gamma slab and a white environment.
std::string slab_scene(const fs::path& fields, const std::string& memory_key) {
  const double d = 1000.0;
  const double fov = 2.0 * std::atan(0.8 / d) * 180.0 / M_PI;
  return fmt::format(R"({{
    "camera": {{"position": [0.8, 0.8, {}], "look_at": [0.8, 0.8, 0], "fov": {:.17g}, "width": 32, "height": 32}},
    "integrator": {{"spp": 96, "max_depth": 8, "rr_depth": 8, "seed": 5}},
    "materials": {{"boundary": {{"type": "null"}}}},
    "media": {{"m": {{"type": "local-gamma", "fields": "{}", "sigma": {}, "albedo": 0{}}}}},
    "shapes": [{{"type": "box", "min": [0, 0, 0], "max": [1.6, 1.6, 1.6], "material": "boundary", "interior": "m"}}],
    "lights": [{{"type": "environment", "radiance": 1}}]
  }})",
                     -d, fov, fields.string(), kSigma, memory_key);
}

double predicted(const volume::Grid& g, const std::string& model) {
  fit::PredictionSpec spec;
  spec.direction = {0, 0, 1};
  spec.sigma = kSigma;
  spec.scale = kBlock * kH;
  for (const auto& m : fit::predict_axis(g, spec, {kN * kH}))
    if (m.name == model) return std::exp(m.log_t.at(0));
  ADD_FAILURE() << "no model " << model;
  return 0.0;
}

TEST(LocalGammaAgreement, PredictedCurveEqualsAlbedoZeroRender) {
  const volume::Grid g = fine_grid();
  const fs::path fields = fs::temp_directory_path() / "weft_lg_agreement_fields.vdb";
  fit::save_local_fields(fit::local_fields(g, kBlock), fields, fit::FieldChannels::render);
  const double t = predicted(g, "local-gamma");
  // fit::predict_axis's local-gamma model carries its memory by distance: the `segment` rule
  // (docs/render.md §5e), named here because the medium's default is optical-depth.
  const RenderResult r = render(parse_scene(slab_scene(fields, R"(, "memory": "segment")"), "agreement", "."), {});
  const Estimate e = image_mean(r.image);
  EXPECT_GT(e.stderr_, 0.0);
  EXPECT_NEAR(e.mean, t, 5.0 * e.stderr_) << "predicted " << t << ", rendered " << e.mean << " ± " << e.stderr_;
  // The test can tell the memory apart: the renewal model differs by many standard errors.
  EXPECT_GT(std::abs(predicted(g, "local-gamma-renewal") - t), 10.0 * e.stderr_);
}

}  // namespace
}  // namespace weft::render
