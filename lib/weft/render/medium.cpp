#include "weft/render/medium.h"

#include <algorithm>
#include <cmath>

#include <openvdb/tools/Count.h>

#include "weft/core/error.h"
#include "weft/transmittance/exponential.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::render {

using transmittance::Origin;
using transmittance::PairMode;
using transmittance::TransmittancePair;

TransmittancePair make_medium_pair(const MediumDesc& desc, const std::string& where) {
  try {
    const transmittance::LawPtr given = transmittance::make_law(desc.law);
    switch (desc.mode) {
      case PairMode::reciprocal:
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

namespace {
double max_value(const volume::Grid& grid) {
  const auto range = openvdb::tools::minMax(grid.impl().grid->tree());
  return std::max(0.0, static_cast<double>(range.max()));
}

/// Per-block maxima of μ = mu_scale·value over the active box, blocks of kBlock³ voxels; each
/// active value also raises the blocks of its neighbours, so a lookup that rounds across a
/// block face still finds μ ≤ majorant.
std::shared_ptr<const MajorantGrid> build_majorants(const volume::Grid& grid, double mu_scale) {
  constexpr int kBlock = 8;
  const volume::IndexBox box = grid.active_bbox();
  auto g = std::make_shared<MajorantGrid>();
  const double h = grid.voxel_size();
  const auto origin = grid.origin();
  g->cell = kBlock * h;
  for (int a = 0; a < 3; ++a) {
    g->lo[a] = origin[a] + h * box.min[a];
    g->n[a] = static_cast<int>((static_cast<std::int64_t>(box.max[a]) - box.min[a] + kBlock) / kBlock);
  }
  g->mu.assign(static_cast<std::size_t>(g->n[0]) * g->n[1] * g->n[2], 0.0);
  for (auto it = grid.impl().grid->cbeginValueOn(); it; ++it) {
    openvdb::CoordBBox bb;
    it.getBoundingBox(bb);
    const double mu = mu_scale * static_cast<double>(*it);
    std::array<int, 3> lo{};
    std::array<int, 3> hi{};
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::clamp((bb.min()[a] - 1 - box.min[a]) / kBlock, 0, g->n[a] - 1);
      hi[a] = std::clamp((bb.max()[a] + 1 - box.min[a]) / kBlock, 0, g->n[a] - 1);
    }
    for (int k = lo[2]; k <= hi[2]; ++k)
      for (int j = lo[1]; j <= hi[1]; ++j)
        for (int i = lo[0]; i <= hi[0]; ++i) {
          double& m = g->mu[(static_cast<std::size_t>(k) * g->n[1] + j) * g->n[0] + i];
          m = std::max(m, mu);
        }
  }
  return g;
}

const transmittance::Exponential* as_exponential(const transmittance::Law& law) {
  return dynamic_cast<const transmittance::Exponential*>(&law);
}
}  // namespace

Medium make_medium(const MediumDesc& desc, const std::string& where) {
  if (desc.kind == MediumKind::local_gamma) {
    // The pair is not used (the field carries its own T_Q/T_S); an exponential placeholder keeps
    // Medium a value type.
    Medium m(TransmittancePair::same(std::make_shared<transmittance::Exponential>(1.0)));
    m.albedo = desc.albedo;
    m.g = desc.g;
    m.unit_weights = true;
    try {
      m.local_gamma = std::make_shared<const LocalGammaField>(desc.file, desc.sigma);
    } catch (const Error& e) {
      fail("{}: {}", where, e.what());
    }
    return m;
  }
  Medium m(make_medium_pair(desc, where));
  m.albedo = desc.albedo;
  m.g = desc.g;
  // An exponential law is its own reciprocal partner (T_S = p_Q/p_Q(0) = e^{−μt}), so the
  // given law decides in reciprocal and same mode; explicit pairs must agree.
  // Keep the law alive while `given` points into it (fuzz_scene found a use-after-free here).
  const transmittance::LawPtr given_law = transmittance::make_law(desc.law);
  const auto* given = as_exponential(*given_law);
  if (desc.mode == PairMode::explicit_) {
    const auto* q = as_exponential(m.pair.law(Origin::source));
    const auto* s = as_exponential(m.pair.law(Origin::scatterer));
    m.exponential = q != nullptr && s != nullptr && q->mu() == s->mu();
    m.mu = m.exponential ? q->mu() : 0.0;
  } else {
    m.exponential = given != nullptr;
    m.mu = m.exponential ? given->mu() : 0.0;
  }
  m.unit_weights = m.exponential || desc.mode == PairMode::reciprocal;
  if (desc.kind == MediumKind::grid) {
    try {
      m.grid = std::make_shared<const volume::Grid>(volume::Grid::load(desc.file, desc.grid_name));
    } catch (const Error& e) {
      fail("{}: {}", where, e.what());
    }
    if (m.grid->active_voxel_count() == 0) fail("{}: grid '{}' in '{}' is empty", where, m.grid->name(), desc.file);
    m.scale = desc.concentration ? desc.sigma : 1.0;
    m.grid_exponential_mu = m.exponential ? m.mu : 0.0;
    m.exponential = false;  // τ varies along the ray: no closed-form flight
    m.mu = 0.0;
    m.tracking = desc.tracking;
    if (m.tracking == Tracking::delta && m.grid_exponential_mu == 0.0)
      fail("{}: delta tracking needs an exponential law; use \"tracking\": \"optical-depth\"", where);
    m.majorant = m.grid_exponential_mu * m.scale * max_value(*m.grid);
    if (m.tracking == Tracking::delta) m.majorants = build_majorants(*m.grid, m.grid_exponential_mu * m.scale);
  }
  const double ell_s = m.pair.law(Origin::scatterer).mean_free_path();
  m.c = std::isfinite(ell_s) && ell_s > 0.0 ? ell_s : 1.0;
  if (m.exponential && m.mu > 0.0) m.c = 1.0 / m.mu;
  return m;
}

double Medium::entry_weight(double t) const {
  if (unit_weights) return 1.0;
  const auto& law_q = pair.law(Origin::source);
  const auto& law_s = pair.law(Origin::scatterer);
  // T_S/(c p_Q) = exp(log T_S − log T_Q − log Σ_Q − log c): stays finite where T's underflow.
  const double log_w =
      law_s.log_transmittance(t) - law_q.log_transmittance(t) - std::log(law_q.hazard(t)) - std::log(c);
  return std::exp(log_w);
}

double Medium::exit_weight(double t) const {
  if (unit_weights) return 1.0;
  const auto& law_q = pair.law(Origin::source);
  const auto& law_s = pair.law(Origin::scatterer);
  const double log_t_s = law_s.log_transmittance(t);
  if (log_t_s == -std::numeric_limits<double>::infinity()) return 0.0;  // the flight cannot pass here
  const double log_w = std::log(c) + std::log(law_q.hazard(t)) + law_q.log_transmittance(t) - log_t_s;
  return std::exp(log_w);
}

double Medium::shadow_factor(Origin origin, double t) const {
  if (exponential) return mu == 0.0 ? 1.0 : std::exp(-mu * t);
  if (origin == Origin::source) return pair.transmittance(Origin::source, t);
  if (unit_weights) return pair.transmittance(Origin::scatterer, t);
  const auto& law_q = pair.law(Origin::source);
  const double log_t_q = law_q.log_transmittance(t);
  if (log_t_q == -std::numeric_limits<double>::infinity()) return 0.0;
  return std::exp(std::log(c) + std::log(law_q.hazard(t)) + log_t_q);
}

}  // namespace weft::render
