#pragma once
/// @file
/// @brief Participating media that sample themselves: each kind draws its free flights and
/// evaluates its shadow transmittance for a segment that starts at a source or a scatterer
/// (the shapes of pbrt-v4's `SampleT_maj` and Tungsten's `sampleDistance`/`transmittance`).
/// The integrator calls `sample_flight` once per flight and `transmittance` once per shadow
/// segment and never asks which kind it holds (docs/render.md §2).

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/rng.h"
#include "weft/render/scene.h"
#include "weft/transmittance/pair.h"

namespace weft::volume {
class Grid;
class MajorantGrid;
}  // namespace weft::volume

namespace weft::render {

class LocalGammaField;

/// Builds the source/scatterer pair a medium description asks for. Throws weft::Error naming
/// `where` for an unknown law, bad parameters, or a reciprocal partner that does not exist.
[[nodiscard]] transmittance::TransmittancePair make_medium_pair(const MediumDesc& desc, const std::string& where);

/// The rate μ of `pair` when its transport is exponential (the given law's in reciprocal and
/// same mode; in explicit mode both laws', when they agree), or nothing. A grid medium's
/// extinction is μ times its values' scale (σ for a concentration grid, 1 for an extinction
/// grid): docs/scene-format.md "media".
[[nodiscard]] std::optional<double> exponential_pair_rate(const MediumDesc& desc,
                                                          const transmittance::TransmittancePair& pair);

/// What a medium is and how it is estimated: the integrator specialises on it and the run
/// summary prints it.
struct MediumTraits {
  std::string kind;       ///< "homogeneous", "grid", "local-gamma"
  std::string law;        ///< the law's name ("exponential", "gamma", …; "per-voxel gamma")
  std::string estimator;  ///< how flights and shadows are estimated
  /// Closed-form exponential flights in distance (ExponentialMedium): the exponential
  /// specialisation of the integrator may run.
  bool exponential = false;
  bool non_reciprocal = false;  ///< flights carry the T_S/(c·p_Q) ratio weights (same/explicit pairs)
  bool heterogeneous = false;   ///< density varies in space
  /// Extinction 0 everywhere (a grid whose active voxels are all 0, or a zero scale): the medium
  /// cannot change the image, which render/scene_checks warns about.
  bool empty = false;
  /// "grid medium, exponential law, delta + ratio tracking".
  [[nodiscard]] std::string describe() const;
};

/// Per-thread working state of one medium (DDA accessors, trackers); made by the medium.
class MediumScratch {
 public:
  virtual ~MediumScratch() = default;
};

/// Work a medium did on one thread's scratch (benchmarks: voxels crossed per second).
struct MediumWork {
  std::uint64_t cells = 0;    ///< voxels, tree nodes or majorant cells the DDA crossed
  std::uint64_t lookups = 0;  ///< density point lookups (tentative collisions)
};

/// One free flight: where it ended and the factor it puts on the path throughput.
struct Flight {
  bool collided = false;  ///< a real scattering/absorption event at t < t_max
  double t = 0.0;         ///< collision distance, or t_max
  double weight = 1.0;    ///< T_Q/T_S ratio weight (1 for reciprocal pairs and exponential media)
};

/// @brief A medium: albedo and phase function plus its own flights and shadows.
///
/// Segments run from `o` along the unit direction `d`; `origin` says whether the segment
/// starts at a source or surface (law T_Q) or at a scattering event (T_S). `scratch` is what
/// make_scratch() returned, owned by the calling thread (may be null when it returns null).
class Medium {
 public:
  Medium(Rgb albedo, double g) : albedo_(std::move(albedo)), g_(g) {}
  virtual ~Medium() = default;
  Medium(const Medium&) = delete;
  Medium& operator=(const Medium&) = delete;

  /// Samples the free flight of a segment that ends at a surface t_max away (∞ for none).
  [[nodiscard]] virtual Flight sample_flight(const Vec3& o, const Vec3& d, double t_max, transmittance::Origin origin,
                                             Pcg32& rng, MediumScratch* scratch) const = 0;
  /// Transmittance factor of a shadow segment of length t (an unbiased estimate for tracked
  /// media), the path weights of docs/render.md §2 included.
  [[nodiscard]] virtual double transmittance(const Vec3& o, const Vec3& d, double t, transmittance::Origin origin,
                                             Pcg32& rng, MediumScratch* scratch) const = 0;
  [[nodiscard]] virtual std::unique_ptr<MediumScratch> make_scratch() const { return nullptr; }
  [[nodiscard]] virtual MediumTraits traits() const = 0;
  /// What the flights and shadows on `scratch` cost so far (zero for closed-form media).
  [[nodiscard]] virtual MediumWork work(const MediumScratch* /*scratch*/) const { return {}; }

  [[nodiscard]] const Rgb& albedo() const { return albedo_; }
  [[nodiscard]] double g() const { return g_; }

 private:
  Rgb albedo_;
  double g_;
};

/// @brief The free-flight bookkeeping of a T_Q/T_S pair (derivation in docs/render.md §2).
///
/// The path tracer samples each flight from the law of the vertex it leaves (camera side);
/// the physical law of a segment is set by the vertex light comes from. The two differ by
/// ratios that are exactly 1 in reciprocal mode and for exponential media:
///   surface → collision at t:  w_in(t)  = T_S(t) / (c·p_Q(t))
///   collision → surface at t:  w_out(t) = c·p_Q(t) / T_S(t) = 1 / w_in(t)
///   shadow ray leaving a collision, first segment of length t: c·p_Q(t)  (= T_S(t) if reciprocal)
/// with c = ℓ_S when finite (else 1), a constant that cancels along every path. For grid media
/// every t is an optical depth τ.
class PairWeights {
 public:
  PairWeights(transmittance::TransmittancePair pair, bool unit_weights);
  [[nodiscard]] const transmittance::TransmittancePair& pair() const { return pair_; }
  [[nodiscard]] bool unit_weights() const { return unit_weights_; }
  /// w_in(t), evaluated in log space (T_S and p_Q may both underflow).
  [[nodiscard]] double entry_weight(double t) const;
  /// w_out(t).
  [[nodiscard]] double exit_weight(double t) const;
  /// The weight of a flight that ended at t (collided or at the segment's end).
  [[nodiscard]] double flight_weight(bool collided, transmittance::Origin origin, double t) const;
  /// Transmittance factor of a shadow segment of length t that starts at a vertex of kind `origin`.
  [[nodiscard]] double shadow_factor(transmittance::Origin origin, double t) const;

 private:
  transmittance::TransmittancePair pair_;
  bool unit_weights_;
  double c_ = 1.0;
};

/// e^{−μt} in a homogeneous medium: closed-form flights −log ξ/μ. Final, so the exponential
/// specialisation of the integrator calls it without a virtual call.
class ExponentialMedium final : public Medium {
 public:
  ExponentialMedium(double mu, Rgb albedo, double g) : Medium(std::move(albedo), g), mu_(mu) {}
  // Defined here so that the exponential specialisation inlines them (a call per flight and
  // per shadow segment otherwise).
  [[nodiscard]] Flight sample_flight(const Vec3& /*o*/, const Vec3& /*d*/, double t_max,
                                     transmittance::Origin /*origin*/, Pcg32& rng,
                                     MediumScratch* /*scratch*/) const override {
    Flight f;
    f.t = sample_distance(rng);
    f.collided = f.t < t_max;
    if (!f.collided) f.t = t_max;
    return f;
  }
  [[nodiscard]] double transmittance(const Vec3& /*o*/, const Vec3& /*d*/, double t, transmittance::Origin /*origin*/,
                                     Pcg32& /*rng*/, MediumScratch* /*scratch*/) const override {
    return mu_ == 0.0 ? 1.0 : std::exp(-mu_ * t);
  }
  [[nodiscard]] MediumTraits traits() const override;
  [[nodiscard]] double mu() const { return mu_; }
  /// The free-flight distance alone, one draw, before it is compared with any boundary: the
  /// flight is collided exactly when it is below the distance to the next surface.
  [[nodiscard]] double sample_distance(Pcg32& rng) const {
    return mu_ > 0.0 ? -std::log(rng.uniform_open()) / mu_ : std::numeric_limits<double>::infinity();
  }

 private:
  double mu_;
};

/// Any T_Q/T_S pair in a homogeneous medium: flights from the law of the vertex left
/// (inverse CDF or the law's own sampler), with the pair's ratio weights.
class PairMedium final : public Medium {
 public:
  PairMedium(PairWeights law, Rgb albedo, double g) : Medium(std::move(albedo), g), law_(std::move(law)) {}
  [[nodiscard]] Flight sample_flight(const Vec3& o, const Vec3& d, double t_max, transmittance::Origin origin,
                                     Pcg32& rng, MediumScratch* scratch) const override;
  [[nodiscard]] double transmittance(const Vec3& o, const Vec3& d, double t, transmittance::Origin origin, Pcg32& rng,
                                     MediumScratch* scratch) const override;
  [[nodiscard]] MediumTraits traits() const override;
  [[nodiscard]] const PairWeights& law() const { return law_; }

 private:
  PairWeights law_;
};

/// A voxel grid with an exponential law in optical depth, e^{−∫μ}, μ = scale·value: delta
/// tracking for flights and ratio tracking for shadows against the per-leaf majorant grid.
///
/// With three per-axis grids the extinction depends on the direction (docs/render.md §6d): along
/// a ray of unit direction ω, μ(x, ω) = scale·Σ_a ω_a² value_a(x). The same trackers run on the
/// weighted channels against one majorant grid over the three (their per-voxel maximum bounds
/// the weighted sum, since Σ ω_a² = 1).
class DeltaTrackingGridMedium final : public Medium {
 public:
  DeltaTrackingGridMedium(std::shared_ptr<const volume::Grid> grid, double scale, Rgb albedo, double g);
  /// The direction-dependent medium of the x, y and z grids (same voxel size and origin).
  DeltaTrackingGridMedium(const std::array<std::shared_ptr<const volume::Grid>, 3>& axes, double scale, Rgb albedo,
                          double g);
  ~DeltaTrackingGridMedium() override;
  [[nodiscard]] Flight sample_flight(const Vec3& o, const Vec3& d, double t_max, transmittance::Origin origin,
                                     Pcg32& rng, MediumScratch* scratch) const override;
  [[nodiscard]] double transmittance(const Vec3& o, const Vec3& d, double t, transmittance::Origin origin, Pcg32& rng,
                                     MediumScratch* scratch) const override;
  [[nodiscard]] std::unique_ptr<MediumScratch> make_scratch() const override;
  [[nodiscard]] MediumTraits traits() const override;
  [[nodiscard]] MediumWork work(const MediumScratch* scratch) const override;
  /// The grid (the x grid of a direction-dependent medium).
  [[nodiscard]] const volume::Grid& grid() const { return *channels_.front(); }
  [[nodiscard]] const volume::MajorantGrid& majorants() const { return *majorants_; }
  [[nodiscard]] double scale() const { return scale_; }
  [[nodiscard]] bool directional() const { return channels_.size() == 3; }

 private:
  DeltaTrackingGridMedium(std::vector<std::shared_ptr<const volume::Grid>> channels, double scale, Rgb albedo,
                          double g);
  std::vector<std::shared_ptr<const volume::Grid>> channels_;  ///< one grid, or x, y, z
  std::shared_ptr<const volume::MajorantGrid> majorants_;
  double scale_;
  bool empty_;  ///< MediumTraits::empty, found once when the medium is built
  /// Voxels so thick that walking them (volume::DepthTracker: the exponential flight placed at
  /// τ* = −log ξ, shadows e^{−τ} exactly) is cheaper than tracking (docs/render.md §5).
  bool exact_;
};

/// A voxel grid with any law in optical depth τ: the flight samples τ* from the law of its
/// origin and marches the DDA until τ reaches it (exact for piecewise-constant voxels); shadows
/// apply the law to the exact τ of the segment.
class OpticalDepthGridMedium final : public Medium {
 public:
  OpticalDepthGridMedium(std::shared_ptr<const volume::Grid> grid, double scale, PairWeights law, Rgb albedo, double g);
  [[nodiscard]] Flight sample_flight(const Vec3& o, const Vec3& d, double t_max, transmittance::Origin origin,
                                     Pcg32& rng, MediumScratch* scratch) const override;
  [[nodiscard]] double transmittance(const Vec3& o, const Vec3& d, double t, transmittance::Origin origin, Pcg32& rng,
                                     MediumScratch* scratch) const override;
  [[nodiscard]] std::unique_ptr<MediumScratch> make_scratch() const override;
  [[nodiscard]] MediumTraits traits() const override;
  [[nodiscard]] MediumWork work(const MediumScratch* scratch) const override;
  [[nodiscard]] const PairWeights& law() const { return law_; }

 private:
  std::shared_ptr<const volume::Grid> grid_;
  double scale_;
  PairWeights law_;
  bool empty_;  ///< MediumTraits::empty, found once when the medium is built
};

/// The local statistic fields of `weft fit --block` as per-voxel gamma laws (local_gamma.h):
/// flights by inverting the accumulated hazard of the segment's own law (T_Q from a source,
/// the per-voxel partner T_S from a scatterer), so their weights are 1.
class LocalGammaMedium final : public Medium {
 public:
  LocalGammaMedium(std::shared_ptr<const LocalGammaField> field, Rgb albedo, double g);
  ~LocalGammaMedium() override;
  [[nodiscard]] Flight sample_flight(const Vec3& o, const Vec3& d, double t_max, transmittance::Origin origin,
                                     Pcg32& rng, MediumScratch* scratch) const override;
  [[nodiscard]] double transmittance(const Vec3& o, const Vec3& d, double t, transmittance::Origin origin, Pcg32& rng,
                                     MediumScratch* scratch) const override;
  [[nodiscard]] std::unique_ptr<MediumScratch> make_scratch() const override;
  [[nodiscard]] MediumTraits traits() const override;

 private:
  std::shared_ptr<const LocalGammaField> field_;
};

/// Builds the medium a description asks for (reads its grid or fields). Throws weft::Error
/// naming `where` for bad laws, unreadable or empty grids, and delta tracking of a law that is
/// not exponential.
[[nodiscard]] std::shared_ptr<const Medium> make_medium(const MediumDesc& desc, const std::string& where);

}  // namespace weft::render
