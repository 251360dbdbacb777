#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <numbers>

#include "data_gen/cloth/yarn.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/core/progress.h"

namespace weft::cloth {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;

YarnParams no_flyaways(YarnParams y) {
  y.loop_density = 0.0;
  y.hair_density = 0.0;
  return y;
}

Curve straight_x(double length) {
  Curve c;
  c.points = {{0.0, 0.0, 0.0}, {length, 0.0, 0.0}};
  return c;
}

TEST(YarnModel, PlyAndFiberCountsMatchParameters) {
  for (const auto& name : yarn_preset_names()) {
    const YarnParams y = no_flyaways(yarn_preset(name));
    const FiberSet f = yarn_fibers(straight_x(1.0), y, 7, 3);
    ASSERT_EQ(f.size(), static_cast<std::size_t>(y.ply_count * y.fiber_count)) << name;
    std::vector<int> per_ply(static_cast<std::size_t>(y.ply_count), 0);
    for (std::size_t i = 0; i < f.size(); ++i) {
      ASSERT_GE(f.ply[i], 0);
      ASSERT_LT(f.ply[i], y.ply_count);
      ++per_ply[static_cast<std::size_t>(f.ply[i])];
      EXPECT_EQ(f.yarn[i], 3);
      EXPECT_EQ(f.kind[i], FiberKind::regular);
      EXPECT_DOUBLE_EQ(f.radius[i], y.fiber_radius);
    }
    for (int n : per_ply) EXPECT_EQ(n, y.fiber_count) << name;
  }
}

TEST(YarnModel, FlyawayCountsFollowTheirDensities) {
  YarnParams y = yarn_preset("cotton");
  y.loop_density = 0.0;
  y.hair_density = 10.0;  // per mm of ply: exactly 10·L·plies hairs (integer expectation)
  const FiberSet f = yarn_fibers(straight_x(2.0), y, 1, 0);
  int hairs = 0;
  for (auto k : f.kind) hairs += k == FiberKind::hair ? 1 : 0;
  EXPECT_EQ(hairs, 10 * 2 * y.ply_count);
  EXPECT_EQ(f.size(), static_cast<std::size_t>(y.ply_count * y.fiber_count + hairs));
  // Loop flyaways reach beyond the ply's regular envelope.
  y.hair_density = 0.0;
  y.loop_density = 5.0;
  y.loop_radius_mean = 2.0;
  y.loop_radius_sd = 0.0;
  const FiberSet g = yarn_fibers(straight_x(2.0), y, 1, 0);
  double reach = 0.0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    for (auto p = g.offsets[i]; p < g.offsets[i + 1]; ++p)
      reach = std::max(reach, std::hypot(g.points[p][1], g.points[p][2]));
  }
  EXPECT_GT(reach, yarn_envelope_radius(y) + 0.5 * y.ply_radius);
}

TEST(YarnModel, DeterministicForASeed) {
  const YarnParams y = yarn_preset("wool");
  const FiberSet a = yarn_fibers(straight_x(1.0), y, 42, 0);
  const FiberSet b = yarn_fibers(straight_x(1.0), y, 42, 0);
  const FiberSet c = yarn_fibers(straight_x(1.0), y, 43, 0);
  EXPECT_EQ(a.points, b.points);
  EXPECT_NE(a.points, c.points);
}

TEST(YarnModel, RadiusCdfMatchesClosedFormForFlatDensity) {
  // β = 0 or ε = ½ make p(R) constant, so R has density 2R and F(R) = R².
  for (double R : {0.1, 0.35, 0.5, 0.9}) {
    EXPECT_NEAR(fiber_radius_cdf(R, 0.2, 0.0), R * R, 1e-12);
  }
}

// χ² goodness of fit of sampled fibre radii against F(R) = ∫ r p(r) dr (areal density p).
// 20 bins of equal probability under F (edges by bisection), 19 degrees of freedom; the 0.999
// quantile of χ²(19) is 43.82, so a correct sampler fails with probability 0.001 (fixed seed:
// deterministic).
struct DensityCase {
  double epsilon;
  double beta;
};
class RadialDensity : public ::testing::TestWithParam<DensityCase> {};

TEST_P(RadialDensity, SampledRadiiMatchDensityByChiSquare) {
  YarnParams y = yarn_preset("cotton");
  y.density_epsilon = GetParam().epsilon;
  y.density_beta = GetParam().beta;
  y.fiber_min_spacing = 0.0;  // pure rejection sampling: the distribution under test
  constexpr int n = 40000;
  constexpr int bins = 20;
  std::vector<double> edges(bins + 1, 1.0);
  edges[0] = 0.0;
  for (int b = 1; b < bins; ++b) {
    double lo = 0.0, hi = 1.0;
    for (int it = 0; it < 50; ++it) {
      const double mid = 0.5 * (lo + hi);
      (fiber_radius_cdf(mid, y.density_epsilon, y.density_beta) < static_cast<double>(b) / bins ? lo : hi) = mid;
    }
    edges[static_cast<std::size_t>(b)] = 0.5 * (lo + hi);
  }
  Pcg32 rng = stream_for(2024, 1);
  const auto seeds = sample_ply_cross_section(y, n, rng);
  ASSERT_EQ(seeds.size(), static_cast<std::size_t>(n));
  std::vector<int> counts(bins, 0);
  for (const auto& s : seeds) {
    ASSERT_GE(s.R, 0.0);
    ASSERT_LE(s.R, 1.0);
    const auto b = std::upper_bound(edges.begin() + 1, edges.end() - 1, s.R) - (edges.begin() + 1);
    ++counts[static_cast<std::size_t>(b)];
  }
  const double expected = static_cast<double>(n) / bins;
  double chi2 = 0.0;
  for (int c : counts) chi2 += (c - expected) * (c - expected) / expected;
  EXPECT_LT(chi2, 43.82) << "epsilon " << GetParam().epsilon << " beta " << GetParam().beta;
}

INSTANTIATE_TEST_SUITE_P(Densities, RadialDensity,
                         ::testing::Values(DensityCase{0.05, 0.6}, DensityCase{0.0, 0.0}, DensityCase{0.0, 3.0},
                                           DensityCase{0.49, 1.0}, DensityCase{0.01, 8.0}));

TEST(YarnModel, DensityIsStableAtTheEdge) {
  EXPECT_DOUBLE_EQ(fiber_density(1.0, 0.1, 2.0), 0.1);  // (e − e¹) = 0 exactly: only ε remains
  EXPECT_DOUBLE_EQ(fiber_density(0.0, 0.1, 2.0), 0.9);
  EXPECT_EQ(fiber_density(1.5, 0.1, 2.0), 0.0);
  EXPECT_GT(fiber_density(1.0 - 1e-12, 0.0, 0.5), 0.0);
}

TEST(YarnModel, MinimumSpacingIsHonoured) {
  YarnParams y = yarn_preset("cotton");
  y.fiber_min_spacing = 1.0;
  Pcg32 rng = stream_for(5, 0);
  const auto seeds = sample_ply_cross_section(y, y.fiber_count, rng);
  const double d = 2.0 * y.fiber_radius;
  for (std::size_t i = 0; i < seeds.size(); ++i) {
    for (std::size_t j = i + 1; j < seeds.size(); ++j) {
      const double dx =
          y.ply_radius * y.ellipse_n * (seeds[i].R * std::cos(seeds[i].theta) - seeds[j].R * std::cos(seeds[j].theta));
      const double dy =
          y.ply_radius * y.ellipse_b * (seeds[i].R * std::sin(seeds[i].theta) - seeds[j].R * std::sin(seeds[j].theta));
      ASSERT_GE(std::hypot(dx, dy), d * (1.0 - 1e-12)) << i << " " << j;
    }
  }
}

TEST(YarnModel, OverfullPlyIsRejected) {
  YarnParams y = yarn_preset("cotton");
  y.fiber_count = 2000;  // 2000 discs of radius 6 µm cannot sit 12 µm apart in a 0.08 mm ply
  Pcg32 rng = stream_for(5, 0);
  EXPECT_THROW(sample_ply_cross_section(y, y.fiber_count, rng), Error);
}

// Angle of p about the straight x axis in the frame the generator uses (n = z, b = t × n = −y).
double angle_about_x(const Point3& p) { return std::atan2(-p[1], p[2]); }

double fitted_slope(const std::vector<double>& s, std::vector<double> angle) {
  for (std::size_t i = 1; i < angle.size(); ++i) {
    while (angle[i] - angle[i - 1] > std::numbers::pi) angle[i] -= kTwoPi;
    while (angle[i] - angle[i - 1] < -std::numbers::pi) angle[i] += kTwoPi;
  }
  double ms = 0, ma = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    ms += s[i];
    ma += angle[i];
  }
  ms /= static_cast<double>(s.size());
  ma /= static_cast<double>(s.size());
  double num = 0, den = 0;
  for (std::size_t i = 0; i < s.size(); ++i) {
    num += (s[i] - ms) * (angle[i] - ma);
    den += (s[i] - ms) * (s[i] - ms);
  }
  return num / den;
}

TEST(YarnModel, FiberTwistPitchMeasuredFromCurves) {
  // One centred circular ply without migration: a fibre turns about the axis at the ply rate
  // plus its own rate in the ply frame, 2π(t_p/ply_pitch + t_p·t_f/fiber_pitch).
  YarnParams y = no_flyaways(yarn_preset("cotton"));
  y.ply_count = 1;
  y.ply_offset = 0.0;
  y.ellipse_n = y.ellipse_b = 1.0;
  y.rho_min = y.rho_max = 1.0;
  y.fiber_count = 10;
  y.sample_step = 0.005;
  const FiberSet f = yarn_fibers(straight_x(4.0), y, 3, 0);
  const double expected = kTwoPi * (y.ply_twist / y.ply_pitch + y.ply_twist * y.fiber_twist / y.fiber_pitch);
  for (std::size_t i = 0; i < f.size(); ++i) {
    std::vector<double> s, a;
    for (auto p = f.offsets[i]; p < f.offsets[i + 1]; ++p) {
      if (std::hypot(f.points[p][1], f.points[p][2]) < 1e-6) continue;  // a fibre on the axis has no angle
      s.push_back(f.points[p][0]);
      a.push_back(angle_about_x(f.points[p]));
    }
    if (s.size() < 10) continue;
    EXPECT_NEAR(fitted_slope(s, a), expected, 1e-6 * std::abs(expected)) << "fibre " << i;
  }
}

TEST(YarnModel, PlyTwistPitchMeasuredFromCurves) {
  // Plies far thinner than their offset: every fibre follows its ply centre, whose angle about
  // the yarn axis advances 2π/ply_pitch per mm.
  YarnParams y = no_flyaways(yarn_preset("polyester"));
  y.ply_radius = 1e-5;
  y.fiber_radius = 1e-7;
  y.fiber_count = 4;
  y.sample_step = 0.01;
  y.ply_twist = -1;
  const FiberSet f = yarn_fibers(straight_x(3.0), y, 9, 0);
  for (std::size_t i = 0; i < f.size(); ++i) {
    std::vector<double> s, a;
    for (auto p = f.offsets[i]; p < f.offsets[i + 1]; ++p) {
      s.push_back(f.points[p][0]);
      a.push_back(angle_about_x(f.points[p]));
    }
    const double measured_pitch = kTwoPi / std::abs(fitted_slope(s, a));
    EXPECT_NEAR(measured_pitch, y.ply_pitch, 1e-3 * y.ply_pitch) << "fibre " << i;
    EXPECT_LT(fitted_slope(s, a), 0.0);  // left-handed (S) twist
  }
}

TEST(YarnModel, FramesDoNotTwistAlongACurvedCentreline) {
  // A planar curve's rotation-minimising frame keeps its normal in or out of the plane.
  Curve arc;
  for (int i = 0; i <= 100; ++i) {
    const double t = 0.02 * i;
    arc.points.push_back({std::cos(t), std::sin(t), 0.0});
  }
  const auto st = centerline_stations(arc, 0.01);
  for (const auto& s : st) {
    EXPECT_NEAR(std::abs(s.n[2]), 1.0, 1e-9);
    EXPECT_NEAR(s.t[0] * s.n[0] + s.t[1] * s.n[1] + s.t[2] * s.n[2], 0.0, 1e-12);
  }
  EXPECT_NEAR(st.back().s, 2.0, 1e-3);
}

TEST(YarnModel, InvalidParametersAreNamed) {
  const auto message = [](YarnParams y) {
    try {
      validate(y, "warp_yarn");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  YarnParams y = yarn_preset("cotton");
  y.fiber_radius = std::nan("");
  EXPECT_NE(message(y).find("warp_yarn.fiber_radius"), std::string::npos);
  y = yarn_preset("cotton");
  y.ply_pitch = -1.0;
  EXPECT_NE(message(y).find("warp_yarn.ply_pitch"), std::string::npos);
  y = yarn_preset("cotton");
  y.rho_min = 2.0;
  EXPECT_NE(message(y).find("rho_min"), std::string::npos);
  y = yarn_preset("cotton");
  y.density_epsilon = 0.5;
  EXPECT_NE(message(y).find("density_epsilon"), std::string::npos);
  EXPECT_THROW(yarn_preset("kevlar"), Error);
}

// A long yarn is cut into pieces (build_yarns): the pieces are built in parallel, yet the fibres
// are the same bits for any thread count, stay whole polylines without a jump at a piece
// boundary, and loops and hairs occur all along the yarn at their densities.
TEST(YarnModel, LongYarnPiecesAreThreadCountInvariantAndSeamless) {
  YarnParams y = yarn_preset("cotton");
  y.fiber_count = 12;
  Curve c;
  for (int k = 0; k <= 600; ++k) c.points.push_back({0.1 * k, 0.5 * std::sin(0.05 * k), 0.2 * std::cos(0.03 * k)});
  std::vector<FiberSet> runs;
  for (const unsigned threads : {1U, 2U}) {
    const ThreadLimit limit(threads);
    runs.push_back(yarn_fibers(c, y, 5, 2));
  }
  const FiberSet& f = runs[0];
  const std::size_t stations = f.offsets[1] - f.offsets[0];
  ASSERT_GT(stations, 2 * kPieceStations) << "the test yarn must span several pieces";
  ASSERT_EQ(f.points.size(), runs[1].points.size());
  EXPECT_EQ(0, std::memcmp(f.points.data(), runs[1].points.data(), f.points.size() * sizeof(Point3)));
  EXPECT_EQ(f.offsets, runs[1].offsets);
  EXPECT_EQ(f.kind, runs[1].kind);
  // Seamless: consecutive points of a regular fibre are never much further apart than a step
  // along its helix.
  double worst = 0.0;
  std::size_t loops = 0;
  std::size_t hairs = 0;
  std::vector<double> hair_roots;
  for (std::size_t i = 0; i < f.size(); ++i) {
    if (f.kind[i] == FiberKind::hair) {
      ++hairs;
      hair_roots.push_back(f.points[f.offsets[i]][0]);
      continue;
    }
    loops += f.kind[i] == FiberKind::loop ? 1 : 0;
    for (std::uint64_t k = f.offsets[i] + 1; k < f.offsets[i + 1]; ++k) {
      const auto& a = f.points[k - 1];
      const auto& b = f.points[k];
      worst = std::max(worst, std::hypot(b[0] - a[0], b[1] - a[1], b[2] - a[2]));
    }
  }
  EXPECT_LT(worst, 3.0 * y.sample_step);
  EXPECT_GT(loops, 0U);
  // Hairs: a Poisson-like count with mean density × length per ply (±5σ), roots along the whole yarn.
  const double length = curve_length(c);
  const double expected = y.hair_density * length * y.ply_count;
  EXPECT_NEAR(static_cast<double>(hairs), expected, 5.0 * std::sqrt(expected));
  EXPECT_LT(*std::min_element(hair_roots.begin(), hair_roots.end()), 0.1 * 60.0);
  EXPECT_GT(*std::max_element(hair_roots.begin(), hair_roots.end()), 0.9 * 60.0);
}

// Loops reshape regular fibres and add none; the set counts the loops drawn: density × length
// per ply, each ply's count within one of its mean (floor plus a Bernoulli draw, one piece).
TEST(YarnModel, LoopsAddNoFibreAndAreCountedAtTheirDensity) {
  YarnParams y = no_flyaways(yarn_preset("cotton"));
  const FiberSet none = yarn_fibers(straight_x(2.0), y, 3, 0);
  y.loop_density = 123.4;
  const FiberSet f = yarn_fibers(straight_x(2.0), y, 3, 0);
  EXPECT_EQ(f.size(), none.size());
  EXPECT_EQ(none.loops, 0U);
  EXPECT_NEAR(static_cast<double>(f.loops), y.loop_density * 2.0 * y.ply_count, y.ply_count);
  EXPECT_GT(f.count(FiberKind::loop), 0U);
  EXPECT_EQ(f.count(FiberKind::loop) + f.count(FiberKind::regular), none.size());
}

/// Counts progress reports; throws Cancelled at report `stop_at` (0: never).
class CountingSink final : public ProgressSink {
 public:
  explicit CountingSink(std::uint64_t stop_at = 0) : stop_at_(stop_at) {}
  void begin(std::string_view, std::uint64_t total) override { total_ = total; }
  void advance(std::uint64_t done) override {
    done_ = std::max(done_.load(), done);
    if (++reports_ == stop_at_) throw Cancelled();
  }
  void end() noexcept override {}
  [[nodiscard]] std::uint64_t reports() const { return reports_.load(); }
  [[nodiscard]] std::uint64_t done() const { return done_.load(); }
  [[nodiscard]] std::uint64_t total() const { return total_; }

 private:
  std::uint64_t stop_at_;
  std::uint64_t total_ = 0;
  std::atomic<std::uint64_t> reports_{0};
  std::atomic<std::uint64_t> done_{0};
};

// Dense loops make a point cost 1 + its loops: progress comes every kReportSteps of that work,
// not once per piece of yarn, so a Cancelled from the sink stops the build within it.
TEST(YarnModel, DenseLoopsReportProgressByWorkAndStopWhenCancelled) {
  YarnParams y = no_flyaways(yarn_preset("cotton"));
  y.loop_density = 4e4;  // 1200 loops over each fibre point
  const Curve c = straight_x(2.0);
  const std::vector<YarnJob> jobs{YarnJob{&c, &y, 0}};
  CountingSink sink;
  const FiberSet f = build_yarns(jobs, 9, sink);
  // The bar ends full: one unit per regular fibre point.
  EXPECT_EQ(sink.total(), f.points.size());
  EXPECT_EQ(sink.done(), sink.total());
  const double work = static_cast<double>(f.points.size()) * loop_coverage(y);
  // Half the expected count: the loops over a point are Poisson around loop_coverage. One unit
  // per (ply, piece), as before, would give 2 x 2 reports here.
  EXPECT_GE(static_cast<double>(sink.reports()), 0.5 * work / static_cast<double>(kReportSteps)) << work;
  EXPECT_GT(sink.reports(), 3U * static_cast<std::uint64_t>(y.ply_count));
  CountingSink stopper(3);
  EXPECT_THROW((void)build_yarns(jobs, 9, stopper), Cancelled);
}

}  // namespace
}  // namespace weft::cloth
