#include "weft/render/medium.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "weft/core/error.h"
#include "weft/render/local_gamma.h"
#include "weft/transmittance/exponential.h"
#include "weft/volume/grid.h"
#include "weft/volume/majorants.h"
#include "weft/volume/provenance.h"

namespace weft::render {

using transmittance::Origin;
using transmittance::PairMode;
using transmittance::TransmittancePair;

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();

volume::Ray to_ray(const Vec3& o, const Vec3& d) { return {{o.x(), o.y(), o.z()}, {d.x(), d.y(), d.z()}}; }

/// The rate of an exponential law, or nothing. The one place that asks what a law is: the
/// factory below turns the answer into a medium class, and everything after asks the medium.
std::optional<double> exponential_rate(const transmittance::Law& law) {
  if (const auto* e = dynamic_cast<const transmittance::Exponential*>(&law)) return e->mu();
  return std::nullopt;
}

std::string pair_estimator(const PairWeights& w, const std::string& sampling) {
  return sampling + (w.unit_weights() ? "" : ", T_S/(c·p_Q) path weights");
}
}  // namespace

std::optional<double> exponential_pair_rate(const MediumDesc& desc, const TransmittancePair& pair) {
  // An exponential law is its own reciprocal partner (T_S = p_Q/p_Q(0) = e^{−μt}), so the
  // given law decides in reciprocal and same mode; explicit pairs must agree.
  if (desc.mode == PairMode::explicit_) {
    const auto q = exponential_rate(pair.law(Origin::source));
    const auto s = exponential_rate(pair.law(Origin::scatterer));
    if (q && s && *q == *s) return q;
    return std::nullopt;
  }
  return exponential_rate(pair.law(desc.given));
}

std::string MediumTraits::describe() const { return kind + " medium, " + law + " law, " + estimator; }

TransmittancePair make_medium_pair(const MediumDesc& desc, const std::string& where) {
  try {
    const transmittance::LawPtr given = transmittance::make_law(desc.law);
    switch (desc.mode) {
      case PairMode::reciprocal:
        // An exponential law is its own reciprocal partner (T_S = p_Q/p_Q(0) = e^{−μt}), μ = 0
        // (a vacuum, T ≡ 1, the limit μ → 0 of the pair) included, where p_Q ≡ 0 leaves the
        // quotient undefined and the general construction refuses it.
        if (exponential_rate(*given)) return TransmittancePair::same(given);
        return TransmittancePair::reciprocal(given, desc.given);
      case PairMode::same:
        return TransmittancePair::same(given);
      case PairMode::explicit_: {
        const transmittance::LawPtr other = transmittance::make_law(desc.scatterer_law);
        return desc.given == Origin::source ? TransmittancePair::explicit_pair(given, other)
                                            : TransmittancePair::explicit_pair(other, given);
      }
    }
  } catch (const Error& e) {
    fail("{}: {}", where, e.what());
  }
  fail("{}: unknown pair mode", where);
}

// ---- PairWeights ---------------------------------------------------------------------------

PairWeights::PairWeights(TransmittancePair pair, bool unit_weights)
    : pair_(std::move(pair)), unit_weights_(unit_weights) {
  const double ell_s = pair_.law(Origin::scatterer).mean_free_path();
  c_ = std::isfinite(ell_s) && ell_s > 0.0 ? ell_s : 1.0;
}

double PairWeights::entry_weight(double t) const {
  if (unit_weights_) return 1.0;
  const auto& law_q = pair_.law(Origin::source);
  const auto& law_s = pair_.law(Origin::scatterer);
  // T_S/(c p_Q) = exp(log T_S − log T_Q − log Σ_Q − log c): stays finite where T's underflow.
  const double log_w =
      law_s.log_transmittance(t) - law_q.log_transmittance(t) - std::log(law_q.hazard(t)) - std::log(c_);
  return std::exp(log_w);
}

double PairWeights::exit_weight(double t) const {
  if (unit_weights_) return 1.0;
  const auto& law_q = pair_.law(Origin::source);
  const auto& law_s = pair_.law(Origin::scatterer);
  const double log_t_s = law_s.log_transmittance(t);
  if (log_t_s == -kInf) return 0.0;  // the flight cannot pass here
  const double log_w = std::log(c_) + std::log(law_q.hazard(t)) + law_q.log_transmittance(t) - log_t_s;
  return std::exp(log_w);
}

double PairWeights::flight_weight(bool collided, Origin origin, double t) const {
  if (unit_weights_) return 1.0;
  if (collided && origin == Origin::source) return entry_weight(t);
  if (!collided && origin == Origin::scatterer) return exit_weight(t);
  return 1.0;
}

double PairWeights::shadow_factor(Origin origin, double t) const {
  if (origin == Origin::source) return pair_.transmittance(Origin::source, t);
  if (unit_weights_) return pair_.transmittance(Origin::scatterer, t);
  const auto& law_q = pair_.law(Origin::source);
  const double log_t_q = law_q.log_transmittance(t);
  if (log_t_q == -kInf) return 0.0;
  return std::exp(std::log(c_) + std::log(law_q.hazard(t)) + log_t_q);
}

// ---- homogeneous media -----------------------------------------------------------------------

MediumTraits ExponentialMedium::traits() const {
  MediumTraits t;
  t.kind = "homogeneous";
  t.law = "exponential";
  t.estimator = "closed-form flights";
  t.exponential = true;
  t.empty = mu_ == 0.0;
  return t;
}

Flight PairMedium::sample_flight(const Vec3&, const Vec3&, double t_max, Origin origin, Pcg32& rng,
                                 MediumScratch*) const {
  // Free flight from the law of the vertex we leave; the pair's ratio weights turn the
  // camera-side sampling into the physical, light-side law (docs/render.md §2).
  Flight f;
  f.t = law_.pair().sample(origin, rng);
  f.collided = f.t < t_max;
  if (!f.collided) f.t = t_max;
  f.weight = law_.flight_weight(f.collided, origin, f.t);
  return f;
}

double PairMedium::transmittance(const Vec3&, const Vec3&, double t, Origin origin, Pcg32&, MediumScratch*) const {
  return law_.shadow_factor(origin, t);
}

MediumTraits PairMedium::traits() const {
  MediumTraits t;
  t.kind = "homogeneous";
  t.law = law_.pair().law(Origin::source).name();
  t.estimator = pair_estimator(law_, "T_Q/T_S flights (" + law_.pair().law(Origin::source).sampling_method() + ")");
  t.non_reciprocal = !law_.unit_weights();
  return t;
}

// ---- grid media ------------------------------------------------------------------------------

namespace {
struct MajorantScratch final : MediumScratch {
  volume::MajorantTracker tracker;
  std::vector<double> weights;  ///< directional media: ω_a² of the current ray
  MajorantScratch(const std::vector<const volume::Grid*>& channels, const volume::MajorantGrid& m)
      : tracker(channels, m), weights(channels.size() == 1 ? 0 : channels.size()) {}
  /// ω_a²/|ω|² for a direction that need not be unit: the weights sum to 1 (to rounding).
  void set_direction(const Vec3& d) {
    const double n2 = d.squaredNorm();
    for (std::size_t a = 0; a < weights.size(); ++a)
      weights[a] = d[static_cast<Eigen::Index>(a)] * d[static_cast<Eigen::Index>(a)] / n2;
  }
};
std::vector<const volume::Grid*> pointers(const std::vector<std::shared_ptr<const volume::Grid>>& grids) {
  std::vector<const volume::Grid*> out;
  out.reserve(grids.size());
  for (const auto& g : grids) out.push_back(g.get());
  return out;
}
struct DepthScratch final : MediumScratch {
  volume::DepthTracker tracker;
  explicit DepthScratch(const volume::Grid& g) : tracker(g) {}
};

/// Voxels a ray crosses per voxel length, averaged over directions (E|ω_x| + E|ω_y| + E|ω_z|).
constexpr double kVoxelCrossings = 1.5;

/// Whether a grid's voxels are optically thick enough that walking them exactly costs less than
/// tracking against its majorants (docs/render.md §5): delta and ratio tracking make
/// ≈ μ̄ tentative collisions per unit length (μ̄ the majorant), each a draw, a logarithm and a
/// point lookup; the exact walk one DDA step per voxel, ≈ 1.5/h per unit length. The mean
/// majorant over the active cells stands for μ̄. Only the cost depends on the answer: both
/// estimate e^{−∫μ} without bias. Dimensionless (μ̄h), so no voxel size or origin decides it.
bool walk_exactly(const volume::MajorantGrid& m, double scale, double voxel_size, std::size_t channels) {
  const std::uint64_t cells = m.active_cells();
  if (channels != 1 || cells == 0 || !(scale > 0.0)) return false;
  const double mean_majorant = scale * m.cells().sum() / static_cast<double>(cells);
  return mean_majorant * voxel_size > kVoxelCrossings;
}
}  // namespace

DeltaTrackingGridMedium::DeltaTrackingGridMedium(std::shared_ptr<const volume::Grid> grid, double scale, Rgb albedo,
                                                 double g)
    : DeltaTrackingGridMedium(std::vector<std::shared_ptr<const volume::Grid>>{std::move(grid)}, scale,
                              std::move(albedo), g) {}
DeltaTrackingGridMedium::DeltaTrackingGridMedium(const std::array<std::shared_ptr<const volume::Grid>, 3>& axes,
                                                 double scale, Rgb albedo, double g)
    : DeltaTrackingGridMedium(std::vector<std::shared_ptr<const volume::Grid>>(axes.begin(), axes.end()), scale,
                              std::move(albedo), g) {}
DeltaTrackingGridMedium::DeltaTrackingGridMedium(std::vector<std::shared_ptr<const volume::Grid>> channels,
                                                 double scale, Rgb albedo, double g)
    : Medium(std::move(albedo), g),
      channels_(std::move(channels)),
      majorants_(std::make_shared<const volume::MajorantGrid>(pointers(channels_))),
      scale_(scale),
      empty_(scale_ == 0.0 ||
             std::all_of(channels_.begin(), channels_.end(), [](const auto& c) { return c->sum() == 0.0; })),
      exact_(walk_exactly(*majorants_, scale_, channels_.front()->voxel_size(), channels_.size())) {}
DeltaTrackingGridMedium::~DeltaTrackingGridMedium() = default;

Flight DeltaTrackingGridMedium::sample_flight(const Vec3& o, const Vec3& d, double t_max, Origin, Pcg32& rng,
                                              MediumScratch* scratch) const {
  Flight f;
  if (exact_) {
    // The exponential free flight in optical depth, τ* = −log ξ, placed by the exact walk.
    const double tau_star = -std::log(rng.uniform_open());
    const volume::DepthHit hit =
        static_cast<DepthScratch*>(scratch)->tracker.march_to(to_ray(o, d), 0.0, t_max, scale_, tau_star);
    f.collided = hit.reached && hit.t < t_max;
    f.t = f.collided ? hit.t : t_max;
    return f;
  }
  auto& s = *static_cast<MajorantScratch*>(scratch);
  volume::TrackedCollision c;
  if (directional()) {
    s.set_direction(d);
    c = s.tracker.delta_track(to_ray(o, d), 0.0, t_max, scale_, s.weights, rng);
  } else {
    c = s.tracker.delta_track(to_ray(o, d), 0.0, t_max, scale_, rng);
  }
  f.collided = c.collided;
  f.t = c.collided ? c.t : t_max;
  return f;
}

double DeltaTrackingGridMedium::transmittance(const Vec3& o, const Vec3& d, double t, Origin, Pcg32& rng,
                                              MediumScratch* scratch) const {
  if (exact_) return static_cast<DepthScratch*>(scratch)->tracker.transmittance(to_ray(o, d), 0.0, t, scale_, rng);
  auto& s = *static_cast<MajorantScratch*>(scratch);
  if (!directional()) return s.tracker.ratio_track(to_ray(o, d), 0.0, t, scale_, rng);
  s.set_direction(d);
  return s.tracker.ratio_track(to_ray(o, d), 0.0, t, scale_, s.weights, rng);
}

std::unique_ptr<MediumScratch> DeltaTrackingGridMedium::make_scratch() const {
  if (exact_) return std::make_unique<DepthScratch>(*channels_.front());
  return std::make_unique<MajorantScratch>(pointers(channels_), *majorants_);
}

MediumWork DeltaTrackingGridMedium::work(const MediumScratch* scratch) const {
  if (scratch == nullptr) return {};
  const auto& c = exact_ ? static_cast<const DepthScratch*>(scratch)->tracker.counters()
                         : static_cast<const MajorantScratch*>(scratch)->tracker.counters();
  return {c.cells, c.lookups};
}

MediumTraits DeltaTrackingGridMedium::traits() const {
  MediumTraits t;
  t.kind = "grid";
  t.law = "exponential";
  t.estimator = directional() ? "delta + ratio tracking, direction-dependent extinction (3 axis grids)"
                : exact_      ? "exact voxel walk (optically thick voxels)"
                              : "delta + ratio tracking";
  t.heterogeneous = true;
  t.empty = empty_;
  return t;
}

OpticalDepthGridMedium::OpticalDepthGridMedium(std::shared_ptr<const volume::Grid> grid, double scale, PairWeights law,
                                               Rgb albedo, double g)
    : Medium(std::move(albedo), g),
      grid_(std::move(grid)),
      scale_(scale),
      law_(std::move(law)),
      empty_(scale_ == 0.0 || grid_->sum() == 0.0) {}

Flight OpticalDepthGridMedium::sample_flight(const Vec3& o, const Vec3& d, double t_max, Origin origin, Pcg32& rng,
                                             MediumScratch* scratch) const {
  auto& tracker = static_cast<DepthScratch*>(scratch)->tracker;
  const double tau_star = law_.pair().sample(origin, rng);
  const volume::DepthHit hit = tracker.march_to(to_ray(o, d), 0.0, t_max, scale_, tau_star);
  Flight f;
  f.collided = hit.reached && hit.t < t_max;
  f.t = f.collided ? hit.t : t_max;
  f.weight = law_.flight_weight(f.collided, origin, f.collided ? tau_star : hit.tau);
  return f;
}

double OpticalDepthGridMedium::transmittance(const Vec3& o, const Vec3& d, double t, Origin origin, Pcg32&,
                                             MediumScratch* scratch) const {
  auto& tracker = static_cast<DepthScratch*>(scratch)->tracker;
  return law_.shadow_factor(origin, tracker.optical_depth(to_ray(o, d), 0.0, t, scale_));
}

std::unique_ptr<MediumScratch> OpticalDepthGridMedium::make_scratch() const {
  return std::make_unique<DepthScratch>(*grid_);
}

MediumWork OpticalDepthGridMedium::work(const MediumScratch* scratch) const {
  if (scratch == nullptr) return {};
  const auto& c = static_cast<const DepthScratch*>(scratch)->tracker.counters();
  return {c.cells, c.lookups};
}

MediumTraits OpticalDepthGridMedium::traits() const {
  MediumTraits t;
  t.kind = "grid";
  t.law = law_.pair().law(Origin::source).name();
  t.estimator = pair_estimator(law_, "optical-depth flights (exact DDA)");
  t.non_reciprocal = !law_.unit_weights();
  t.heterogeneous = true;
  t.empty = empty_;
  return t;
}

// ---- local-gamma media -----------------------------------------------------------------------

namespace {
struct FieldScratch final : MediumScratch {
  std::unique_ptr<LocalGammaField> field;
};
}  // namespace

LocalGammaMedium::LocalGammaMedium(std::shared_ptr<const LocalGammaField> field, Rgb albedo, double g)
    : Medium(std::move(albedo), g), field_(std::move(field)) {}
LocalGammaMedium::~LocalGammaMedium() = default;

Flight LocalGammaMedium::sample_flight(const Vec3& o, const Vec3& d, double t_max, Origin origin, Pcg32& rng,
                                       MediumScratch* scratch) const {
  // Invert the accumulated hazard of the segment's own law (T_Q or the per-voxel T_S): the
  // flight is drawn from the law that weights it, so its weight is 1.
  LocalGammaField& field = *static_cast<FieldScratch*>(scratch)->field;
  Flight f;
  f.t = field.sample_distance(to_ray(o, d), 0.0, t_max, -std::log(rng.uniform_open()), origin);
  f.collided = f.t < t_max;
  if (!f.collided) f.t = t_max;
  return f;
}

double LocalGammaMedium::transmittance(const Vec3& o, const Vec3& d, double t, Origin origin, Pcg32& rng,
                                       MediumScratch* scratch) const {
  return static_cast<FieldScratch*>(scratch)->field->transmittance(to_ray(o, d), 0.0, t, origin, rng);
}

std::unique_ptr<MediumScratch> LocalGammaMedium::make_scratch() const {
  auto s = std::make_unique<FieldScratch>();
  s->field = field_->clone();
  return s;
}

MediumTraits LocalGammaMedium::traits() const {
  MediumTraits t;
  t.kind = "local-gamma";
  t.law = "per-voxel gamma";
  t.estimator = fmt::format("hazard inversion, {} memory", transmittance::memory_rule_name(field_->memory()));
  t.heterogeneous = true;
  return t;
}

// ---- factory ---------------------------------------------------------------------------------

std::shared_ptr<const Medium> make_medium(const MediumDesc& desc, const std::string& where) {
  if (desc.kind == MediumKind::local_gamma) {
    std::shared_ptr<const LocalGammaField> field;
    try {
      field = std::make_shared<const LocalGammaField>(desc.file, desc.sigma, desc.memory);
    } catch (const Error& e) {
      fail("{}: {}", where, e.what());
    }
    return std::make_shared<const LocalGammaMedium>(std::move(field), desc.albedo, desc.g);
  }
  TransmittancePair pair = make_medium_pair(desc, where);
  const std::optional<double> mu = exponential_pair_rate(desc, pair);
  const bool unit_weights = mu.has_value() || desc.mode == PairMode::reciprocal;
  if (desc.kind == MediumKind::homogeneous) {
    if (mu) return std::make_shared<const ExponentialMedium>(*mu, desc.albedo, desc.g);
    return std::make_shared<const PairMedium>(PairWeights(std::move(pair), unit_weights), desc.albedo, desc.g);
  }
  const auto load = [&](const std::string& name) {
    std::shared_ptr<const volume::Grid> g;
    try {
      g = std::make_shared<const volume::Grid>(volume::Grid::load(desc.file, name));
    } catch (const Error& e) {
      fail("{}: {}", where, e.what());
    }
    if (g->active_voxel_count() == 0) fail("{}: grid '{}' in '{}' is empty", where, g->name(), desc.file);
    // "values" against the kind the grid records: the same rule as --values (docs/robustness.md, "Value kind").
    try {
      volume::require_value_kind(volume::read_provenance(*g), !desc.concentration, desc.file,
                                 volume::ValuesAsker::scene);
    } catch (const Error& e) {
      fail("{}: {}", where, e.what());
    }
    return g;
  };
  // μ = 0 is a vacuum for any tracking: the zero scale says so to the medium (MediumTraits::empty).
  const double scale = mu && *mu == 0.0 ? 0.0 : desc.concentration ? desc.sigma : 1.0;
  if (!desc.axis_grids.empty()) {
    if (!mu) fail("{}: 'axis_grids' (a direction-dependent extinction) needs an exponential law", where);
    std::array<std::shared_ptr<const volume::Grid>, 3> axes;
    for (std::size_t a = 0; a < 3; ++a) axes[a] = load(desc.axis_grids.at(a));
    try {
      return std::make_shared<const DeltaTrackingGridMedium>(axes, *mu * scale, desc.albedo, desc.g);
    } catch (const Error& e) {
      fail("{}: {}", where, e.what());  // grids of different voxel sizes or origins
    }
  }
  std::shared_ptr<const volume::Grid> grid = load(desc.grid_name);
  if (desc.tracking == Tracking::delta) {
    if (!mu) fail("{}: delta tracking needs an exponential law; use \"tracking\": \"optical-depth\"", where);
    return std::make_shared<const DeltaTrackingGridMedium>(std::move(grid), *mu * scale, desc.albedo, desc.g);
  }
  return std::make_shared<const OpticalDepthGridMedium>(
      std::move(grid), scale, PairWeights(std::move(pair), unit_weights), desc.albedo, desc.g);
}

}  // namespace weft::render
