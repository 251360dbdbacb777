// The voxel rules (docs/validate.md §Voxelization error): linear μ = σC, opaque
// μ = −max(σ, 1/h)·ln(1 − C) with full voxels floored at T = kOpaqueFloor per voxel edge.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>

#include "weft/core/error.h"
#include "weft/volume/provenance.h"
#include "weft/volume/voxel_rule.h"

namespace weft::volume {
namespace {

TEST(VoxelRule, LinearAndOpaqueValues) {
  Grid g(0.01);
  g.set_value(0, 0, 0, 0.5f);
  g.set_value(1, 0, 0, 1.0f);
  g.set_value(2, 0, 0, 0.001f);
  const double sigma = 40.0;  // σh = 0.4 < 1: the exponent is 1 (μ = −ln(1 − C)/h)
  const Grid lin = extinction_grid(g, sigma, VoxelRule::linear);
  EXPECT_FLOAT_EQ(lin.value(0, 0, 0), static_cast<float>(sigma * 0.5));
  const Grid opq = extinction_grid(g, sigma, VoxelRule::opaque);
  EXPECT_FLOAT_EQ(opq.value(0, 0, 0), static_cast<float>(-std::log(0.5) / 0.01));
  EXPECT_NEAR(std::exp(-static_cast<double>(opq.value(1, 0, 0)) * 0.01), kOpaqueFloor, 1e-9);
  // Large voxels (σh > 1): the Boolean law, σC to first order in C.
  const Grid big = extinction_grid(g, 400.0, VoxelRule::opaque);
  EXPECT_NEAR(big.value(2, 0, 0), 400.0 * 0.001, 400.0 * 0.001 * 1e-3);
  EXPECT_EQ(parse_voxel_rule("opaque"), VoxelRule::opaque);
  EXPECT_THROW((void)parse_voxel_rule("cubic"), Error);
  g.set_value(3, 0, 0, 1.5f);
  EXPECT_THROW((void)extinction_grid(g, sigma, VoxelRule::opaque), Error);
}

// A grid of μ says so in the key read_provenance reads first: copied from a weft gen grid
// ("weft:value_kind" = concentration) it was read as C again, and every beam on it multiplied μ
// by the source's σ (σ² C).
TEST(VoxelRule, TheExtinctionGridsProvenanceSaysExtinction) {
  Grid g(0.01);
  g.set_value(0, 0, 0, 0.5f);
  Provenance p;
  p.value_kind = "concentration";
  p.sigma = 40.0;
  write_provenance(g, p);
  ASSERT_EQ(read_provenance(g).value_kind, "concentration");
  for (VoxelRule rule : {VoxelRule::linear, VoxelRule::opaque}) {
    const Grid mu = extinction_grid(g, 40.0, rule);
    const Provenance q = read_provenance(mu);
    EXPECT_EQ(q.value_kind, "extinction") << to_string(rule);
    EXPECT_EQ(resolve_sigma(q, std::nullopt, q.value_kind == "extinction", "mu").sigma, 1.0);
  }
}

}  // namespace
}  // namespace weft::volume
