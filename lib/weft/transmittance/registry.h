#pragma once
/// @file
/// @brief Names → laws (Tungsten-style factory), shared by `weft model`, scenes and fits.

#include <map>
#include <string>
#include <vector>

#include "weft/transmittance/law.h"

namespace weft::transmittance {

/// A law by name with named parameters, as typed on the command line or found in a scene file.
/// Each law accepts the parametrisations its docs list (e.g. gamma: sigma+alpha+beta,
/// mean_extinction+alpha, or sigma+mean_concentration+var_concentration); `table` is the CSV
/// path of a tabulated law.
struct LawSpec {
  std::string name;
  std::map<std::string, double> params;
  std::string table;
  /// Sampler of laws that offer several ("marsaglia-tsang" | "inversion" for gamma-path);
  /// empty for the default.
  std::string sampler = {};
};

/// Builds the law; throws weft::Error naming the law and the offending or missing parameter
/// (and the closest known name for a misspelt law or parameter).
[[nodiscard]] LawPtr make_law(const LawSpec& spec);

/// @brief Laws whose parameters are lists, one value per component (gamma-mixture): the registry
/// reads them as numbered keys `<key>_1`, `<key>_2`, … (e.g. weight_1, alpha_1,
/// mean_extinction_1), which is also how parameters() names them and how a scene file writes them.
[[nodiscard]] bool takes_parameter_lists(const std::string& name);
/// The registry key of element `index` (0-based) of list parameter `key`: "<key>_<index + 1>".
[[nodiscard]] std::string list_parameter_key(const std::string& key, std::size_t index);

/// The registered law names, in a stable order.
[[nodiscard]] std::vector<std::string> law_names();

/// One line per accepted parameter of `name`, with units, for --help and docs.
[[nodiscard]] std::string describe_law(const std::string& name);

}  // namespace weft::transmittance
