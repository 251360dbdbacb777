#pragma once
/// @file
/// @brief Laws ↔ JSON, written once for scene files, `weft model` reports and cloth scenes.
///
/// A law is `{"name": ..., <parameter>: <number>, ..., "table": ..., "sampler": ...}` or just its
/// name. JSON has no infinity, so the one non-finite parameter value a law can hold, +∞ (α = ∞:
/// the exponential limit of a gamma component, docs/transmittance.md), is the string "inf"; every
/// other non-finite value is refused on both sides.

#include <string>

#include <nlohmann/json_fwd.hpp>

#include "weft/transmittance/law.h"
#include "weft/transmittance/registry.h"

namespace weft::transmittance {

/// A parameter value as JSON: the number, or "inf" for +∞; throws weft::Error (naming `where`
/// and the parameter) for NaN and −∞.
[[nodiscard]] nlohmann::json parameter_to_json(double value, const std::string& where, const std::string& name);

/// The spec as JSON (name, parameters, table and sampler when set).
[[nodiscard]] nlohmann::json law_to_json(const LawSpec& spec);

/// The spec that rebuilds `law` through make_law: its name, parameters() and sampler_choice().
[[nodiscard]] LawSpec spec_of(const Law& law);

/// Reads a law (a name, or an object as above); throws weft::Error naming `where` and the key.
[[nodiscard]] LawSpec law_from_json(const nlohmann::json& j, const std::string& where);

}  // namespace weft::transmittance
