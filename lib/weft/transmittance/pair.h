#pragma once
/// @file
/// @brief Source vs scatterer transmittance (Extended GBE, S.21–S.36; docs/architecture.md §6, docs/render.md §2).
///
/// A free-flight segment starts at a source/surface/camera (uncorrelated with the medium's
/// particles: law Q) or at a scattering event (correlated: law S) and ends at a surface
/// (transmittance T) or in the medium (collision pdf p): the four cases T_Q, p_Q, T_S, p_S,
/// as in Tungsten's Transmittance interface.

#include <string>

#include "weft/transmittance/law.h"

namespace weft::transmittance {

/// Where a free-flight segment starts.
enum class Origin { source, scatterer };

/// How the partner of a given law is obtained.
enum class PairMode {
  reciprocal,  ///< p_Q(t) = T_S(t)/ℓ_S: the partner is derived from the given law
  same,        ///< T_S = T_Q (the non-reciprocal simplification)
  explicit_,   ///< both laws given (e.g. both measured)
};

[[nodiscard]] std::string to_string(PairMode mode);
[[nodiscard]] std::string to_string(Origin origin);
/// Parses "reciprocal" | "same" | "explicit"; throws weft::Error otherwise.
[[nodiscard]] PairMode parse_pair_mode(const std::string& text);
/// Parses "Q" | "source" | "S" | "scatterer"; throws weft::Error otherwise.
[[nodiscard]] Origin parse_origin(const std::string& text);

class TransmittancePair {
 public:
  /// `given` is the law of segments that start at `given_origin`; the partner is derived
  /// (closed form where the law provides one, numerically otherwise). Throws weft::Error when
  /// the derivation does not exist (p_Q(0) infinite or zero, ℓ_S infinite), saying why.
  static TransmittancePair reciprocal(LawPtr given, Origin given_origin);
  static TransmittancePair same(LawPtr law);
  static TransmittancePair explicit_pair(LawPtr source, LawPtr scatterer);

  [[nodiscard]] PairMode mode() const { return mode_; }
  [[nodiscard]] const Law& law(Origin origin) const { return origin == Origin::source ? *source_ : *scatterer_; }
  [[nodiscard]] LawPtr law_ptr(Origin origin) const { return origin == Origin::source ? source_ : scatterer_; }

  /// Segment from `origin` that reaches a surface at distance t: T_Q(t) or T_S(t).
  [[nodiscard]] double transmittance(Origin origin, double t) const { return law(origin).transmittance(t); }
  /// Segment from `origin` that collides in the medium at distance t: p_Q(t) or p_S(t).
  [[nodiscard]] double pdf(Origin origin, double t) const { return law(origin).pdf(t); }
  /// Free-flight distance for a segment from `origin`.
  [[nodiscard]] double sample(Origin origin, Pcg32& rng) const { return law(origin).sample(rng); }

 private:
  TransmittancePair(PairMode mode, LawPtr source, LawPtr scatterer)
      : mode_(mode), source_(std::move(source)), scatterer_(std::move(scatterer)) {}
  PairMode mode_;
  LawPtr source_;
  LawPtr scatterer_;
};

}  // namespace weft::transmittance
