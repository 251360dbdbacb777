#include "weft/transmittance/pair.h"

#include <cmath>

#include "weft/core/error.h"
#include "weft/transmittance/derived.h"

namespace weft::transmittance {

std::string to_string(PairMode mode) {
  switch (mode) {
    case PairMode::reciprocal:
      return "reciprocal";
    case PairMode::same:
      return "same";
    case PairMode::explicit_:
      return "explicit";
  }
  return "?";
}

std::string to_string(Origin origin) { return origin == Origin::source ? "source" : "scatterer"; }

PairMode parse_pair_mode(const std::string& text) {
  if (text == "reciprocal") return PairMode::reciprocal;
  if (text == "same") return PairMode::same;
  if (text == "explicit") return PairMode::explicit_;
  fail("unknown pair mode '{}' (known: reciprocal, same, explicit)", text);
}

Origin parse_origin(const std::string& text) {
  if (text == "Q" || text == "source") return Origin::source;
  if (text == "S" || text == "scatterer") return Origin::scatterer;
  fail("unknown segment origin '{}' (known: Q or source, S or scatterer)", text);
}

TransmittancePair TransmittancePair::reciprocal(LawPtr given, Origin given_origin) {
  if (!given) fail("reciprocal pair: no law given");
  if (given_origin == Origin::source) {
    // T_S = p_Q/p_Q(0) needs 0 < p_Q(0) < ∞.
    const double p0 = given->pdf(0.0);
    if (!std::isfinite(p0)) {
      fail("reciprocal pair: {} as the source law has p_Q(0) = +inf, so T_S = p_Q/p_Q(0) does not exist",
           given->name());
    }
    if (!(p0 > 0.0)) {
      fail("reciprocal pair: {} as the source law has p_Q(0) = 0, so T_S = p_Q/p_Q(0) does not exist", given->name());
    }
    LawPtr partner = given->closed_form_scatterer_partner();
    if (!partner) partner = std::make_shared<ScattererFromSource>(given);
    return {PairMode::reciprocal, std::move(given), std::move(partner)};
  }
  const double ell = given->mean_free_path();
  if (!std::isfinite(ell)) {
    fail(
        "reciprocal pair: {} as the scatterer law has an infinite mean free path l_S, so p_Q = T_S/l_S "
        "does not exist",
        given->name());
  }
  LawPtr partner = given->closed_form_source_partner();
  if (!partner) partner = std::make_shared<SourceFromScatterer>(given);
  return {PairMode::reciprocal, std::move(partner), std::move(given)};
}

TransmittancePair TransmittancePair::same(LawPtr law) {
  if (!law) fail("same pair: no law given");
  LawPtr scatterer = law;
  return {PairMode::same, std::move(law), std::move(scatterer)};
}

TransmittancePair TransmittancePair::explicit_pair(LawPtr source, LawPtr scatterer) {
  if (!source || !scatterer) fail("explicit pair: both the source and the scatterer law are needed");
  return {PairMode::explicit_, std::move(source), std::move(scatterer)};
}

}  // namespace weft::transmittance
