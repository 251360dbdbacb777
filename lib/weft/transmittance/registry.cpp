#include "weft/transmittance/registry.h"

#include <algorithm>
#include <cstddef>
#include <functional>
#include <iterator>
#include <set>
#include <string>

#include <fmt/format.h>
#include <fmt/ranges.h>

#include "weft/core/error.h"
#include "weft/core/names.h"
#include "weft/transmittance/erlang.h"
#include "weft/transmittance/exponential.h"
#include "weft/transmittance/gamma_concentration.h"
#include "weft/transmittance/gamma_mixture.h"
#include "weft/transmittance/gamma_path.h"
#include "weft/transmittance/gap_gamma.h"
#include "weft/transmittance/linear.h"
#include "weft/transmittance/tabulated.h"

namespace weft::transmittance {

namespace {

using Params = std::map<std::string, double>;

/// One accepted parametrisation: its parameter names and how it builds the law.
struct Form {
  std::vector<std::string> keys;
  std::function<LawPtr(const Params&, const LawSpec&)> build;
};

struct Entry {
  std::string name;
  std::string summary;
  std::vector<Form> forms;
  std::vector<std::string> docs;  ///< one line per parameter
};

const std::vector<Entry>& entries() {
  static const std::vector<Entry> table = {
      {"exponential",
       "Beer-Lambert T = exp(-mu t)",
       {{{"mu"}, [](const Params& p, const LawSpec&) { return std::make_shared<Exponential>(p.at("mu")); }},
        {{"mean_extinction"},
         [](const Params& p, const LawSpec&) { return std::make_shared<Exponential>(p.at("mean_extinction")); }}},
       {"mu               extinction coefficient [1/length], >= 0 (alias: mean_extinction)"}},
      {"gamma",
       "gamma-concentration law (Eq. 20) T = (1 + mean_extinction t/alpha)^-alpha",
       {{{"mean_extinction", "alpha"},
         [](const Params& p, const LawSpec&) {
           return std::make_shared<GammaConcentration>(p.at("mean_extinction"), p.at("alpha"));
         }},
        {{"sigma", "alpha", "beta"},
         [](const Params& p, const LawSpec&) {
           return std::make_shared<GammaConcentration>(
               GammaConcentration::from_sigma_alpha_beta(p.at("sigma"), p.at("alpha"), p.at("beta")));
         }},
        {{"sigma", "mean_concentration", "var_concentration"},
         [](const Params& p, const LawSpec&) {
           return std::make_shared<GammaConcentration>(GammaConcentration::from_concentration(
               p.at("sigma"), p.at("mean_concentration"), p.at("var_concentration")));
         }}},
       {"mean_extinction  mean extinction mu_bar = sigma*alpha/beta [1/length], >= 0",
        "alpha            shape of the concentration distribution, C_bar^2/Var C [1], > 0 (inf = exponential)",
        "sigma            extinction cross-section per unit concentration [1/length], >= 0",
        "beta             rate of the concentration distribution, C_bar/Var C [1/concentration], > 0",
        "mean_concentration  mean concentration C_bar [concentration, e.g. volume fraction], >= 0",
        "var_concentration   variance of the concentration Var C [concentration^2], >= 0 (0 = exponential)",
        std::string("accepted sets: {mean_extinction, alpha} | {sigma, alpha, beta} | ") +
            "{sigma, mean_concentration, var_concentration}"}},
      {"gap-gamma",
       "gap-aware gamma law T = gap + (1 - gap)(1 + mean_extinction t/alpha)^-alpha",
       {{{"gap", "mean_extinction", "alpha"},
         [](const Params& p, const LawSpec&) {
           return std::make_shared<GapGamma>(p.at("gap"), p.at("mean_extinction"), p.at("alpha"));
         }},
        {{"gap", "sigma", "alpha", "beta"},
         [](const Params& p, const LawSpec&) {
           return std::make_shared<GapGamma>(
               GapGamma::from_sigma_alpha_beta(p.at("gap"), p.at("sigma"), p.at("alpha"), p.at("beta")));
         }},
        {{"gap", "sigma", "mean_concentration", "var_concentration"},
         [](const Params& p, const LawSpec&) {
           return std::make_shared<GapGamma>(GapGamma::from_concentration(
               p.at("gap"), p.at("sigma"), p.at("mean_concentration"), p.at("var_concentration")));
         }}},
       {"gap              fraction of rays that see no fibre (open area, 1 - cover factor) [1], in [0, 1)",
        "mean_extinction  mean extinction of the non-gap rays mu_c = sigma*alpha/beta [1/length], >= 0",
        "alpha            gamma shape of the non-gap concentration [1], > 0 (inf = gap + exponential)",
        "sigma, beta, mean_concentration, var_concentration  as for gamma, statistics of the non-gap rays",
        "T(inf) = gap, so the mean free path is infinite for gap > 0; a draw is inf with probability gap",
        std::string("accepted sets: {gap, mean_extinction, alpha} | {gap, sigma, alpha, beta} | ") +
            "{gap, sigma, mean_concentration, var_concentration}"}},
      {"gamma-mixture",
       "mixture of gamma laws T = sum_i weight_i (1 + mean_extinction_i t/alpha_i)^-alpha_i",
       {},
       {"weight_N            share of the rays in component N = 1, 2, ... [1], >= 0, summing to 1",
        "alpha_N             gamma shape of component N [1], > 0 (inf = exponential component)",
        "mean_extinction_N   mean extinction of component N [1/length], >= 0 (0 = gap: never collides)",
        "every component N = 1..n needs all three; weft model takes lists: --weights 0.2,0.8 --alpha 1,inf "
        "--mean-extinction 0,5"}},
      {"linear",
       "perfect negative correlation (S.58) T = max(0, 1 - mean_extinction t)",
       {{{"mean_extinction"},
         [](const Params& p, const LawSpec&) { return std::make_shared<Linear>(p.at("mean_extinction")); }}},
       {"mean_extinction  mean extinction mu_bar [1/length], >= 0; T reaches 0 at t = 1/mu_bar"}},
      {"gamma-path",
       "gamma-distributed free paths (S.62) T = Q(k, t/theta)",
       {{{"k", "theta"},
         [](const Params& p, const LawSpec& spec) {
           return std::make_shared<GammaPath>(p.at("k"), p.at("theta"), parse_gamma_sampler(spec.sampler));
         }}},
       {"k                shape of the free-path distribution [1], > 0",
        "theta            scale of the free-path distribution [length], > 0; mean free path = k*theta",
        "sampler          marsaglia-tsang (default) | inversion"}},
      {"erlang",
       "Erlang free paths T = exp(-rate t) sum_{n<k} (rate t)^n/n! (d'Eon's Gamma-2 for k = 2)",
       {{{"k", "rate"},
         [](const Params& p, const LawSpec&) { return std::make_shared<Erlang>(p.at("k"), p.at("rate")); }}},
       {"k                integer shape [1], >= 1", "rate             rate of each exponential stage [1/length], > 0"}},
      {"erlang-source",
       "reciprocal source law of erlang: T = (1/k) sum_{j=1..k} Q(j, rate t)",
       {{{"k", "rate"},
         [](const Params& p, const LawSpec&) { return std::make_shared<ErlangMixture>(p.at("k"), p.at("rate")); }}},
       {"k                integer shape of the scatterer law [1], >= 1",
        "rate             rate of each exponential stage [1/length], > 0"}},
      {"tabulated",
       "T(t) samples from a CSV file 't,T' (t in length units), log-linear between samples",
       {{{},
         [](const Params&, const LawSpec& spec) {
           if (spec.table.empty()) fail("tabulated law: a table file is needed (--table FILE)");
           return std::make_shared<Tabulated>(Tabulated::from_csv(spec.table));
         }}},
       {"table            CSV file with columns t [length], T [1]; T(0) = 1, non-increasing"}},
  };
  return table;
}

std::string suggestion(const std::string& word, const std::vector<std::string>& candidates) {
  // Only suggest when the word is plausibly a misspelling.
  const std::string best = closest_name(word, candidates, std::max<std::size_t>(2, word.size() / 2));
  return best.empty() ? std::string{} : fmt::format(" (did you mean '{}'?)", best);
}

const Entry& find_entry(const std::string& name) {
  for (const auto& entry : entries()) {
    if (entry.name == name) return entry;
  }
  fail("unknown transmittance law '{}'{}; known: {}", name, suggestion(name, law_names()),
       fmt::join(law_names(), ", "));
}

/// The gamma-mixture's parameters weight_N, alpha_N, mean_extinction_N (N = 1..n, every one).
constexpr const char* kMixtureBases[] = {"weight", "alpha", "mean_extinction"};

LawPtr make_mixture(const LawSpec& spec) {
  const std::vector<std::string> bases(std::begin(kMixtureBases), std::end(kMixtureBases));
  // component index (0-based) → base → value
  std::map<std::size_t, std::map<std::string, double>> by_index;
  for (const auto& [key, value] : spec.params) {
    const auto underscore = key.rfind('_');
    const std::string base = underscore == std::string::npos ? key : key.substr(0, underscore);
    const std::string digits = underscore == std::string::npos ? std::string() : key.substr(underscore + 1);
    const bool numbered = !digits.empty() && digits.size() <= 7 && digits[0] != '0' &&
                          std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; });
    if (!numbered || std::find(bases.begin(), bases.end(), base) == bases.end()) {
      fail(
          "gamma-mixture law: unknown parameter '{}'{}; accepted: weight_N, alpha_N, mean_extinction_N (N = 1, 2, ...)",
          key, suggestion(numbered ? base : key, bases));
    }
    by_index[std::stoul(digits) - 1][base] = value;
  }
  if (by_index.empty()) {
    fail(
        "gamma-mixture law: no components; give weight_N, alpha_N, mean_extinction_N for N = 1..n "
        "(weft model: --weights, --alpha, --mean-extinction as comma-separated lists)");
  }
  const std::size_t n = by_index.rbegin()->first + 1;
  std::vector<GammaComponent> components;
  for (std::size_t i = 0; i < n; ++i) {
    const auto it = by_index.find(i);
    for (const auto& base : bases) {
      if (it == by_index.end() || it->second.count(base) == 0) {
        fail(
            "gamma-mixture law: missing parameter {}_{} (there are {} components; the lists of weights, alpha "
            "and mean_extinction must have the same length)",
            base, i + 1, n);
      }
    }
    components.push_back({it->second.at("weight"), it->second.at("mean_extinction"), it->second.at("alpha")});
  }
  return std::make_shared<GammaMixture>(std::move(components));
}

}  // namespace

bool takes_parameter_lists(const std::string& name) { return name == "gamma-mixture"; }

std::string list_parameter_key(const std::string& key, std::size_t index) {
  return fmt::format("{}_{}", key, index + 1);
}

std::vector<std::string> law_names() {
  std::vector<std::string> names;
  for (const auto& entry : entries()) names.push_back(entry.name);
  return names;
}

std::string describe_law(const std::string& name) {
  const Entry& entry = find_entry(name);
  std::string text = fmt::format("{}: {}\n", entry.name, entry.summary);
  for (const auto& line : entry.docs) text += fmt::format("  {}\n", line);
  return text;
}

LawPtr make_law(const LawSpec& spec) {
  const Entry& entry = find_entry(spec.name);
  if (takes_parameter_lists(entry.name)) {
    if (!spec.table.empty()) fail("{} law: a table file is only used by the tabulated law", entry.name);
    if (!spec.sampler.empty()) fail("{} law: no choice of sampler (only gamma-path has one)", entry.name);
    return make_mixture(spec);
  }
  std::set<std::string> known;
  for (const auto& form : entry.forms) known.insert(form.keys.begin(), form.keys.end());
  const std::vector<std::string> known_list(known.begin(), known.end());
  for (const auto& [key, value] : spec.params) {
    if (known.count(key) == 0) {
      fail("{} law: unknown parameter '{}'{}; accepted: {}", entry.name, key,
           suggestion(key, known_list.empty() ? std::vector<std::string>{"table"} : known_list),
           known_list.empty() ? std::string("a table file only") : fmt::format("{}", fmt::join(known_list, ", ")));
    }
  }
  if (!spec.table.empty() && entry.name != "tabulated") {
    fail("{} law: a table file is only used by the tabulated law", entry.name);
  }
  if (!spec.sampler.empty() && entry.name != "gamma-path") {
    fail("{} law: no choice of sampler (only gamma-path has one)", entry.name);
  }
  std::set<std::string> given;
  for (const auto& [key, value] : spec.params) given.insert(key);
  for (const auto& form : entry.forms) {
    if (std::set<std::string>(form.keys.begin(), form.keys.end()) == given) return form.build(spec.params, spec);
  }
  // Say what is missing from the closest accepted set.
  std::vector<std::string> sets;
  for (const auto& form : entry.forms) {
    std::vector<std::string> missing;
    bool superset = true;
    for (const auto& key : form.keys) {
      if (given.count(key) == 0) missing.push_back(key);
    }
    for (const auto& key : given)
      superset = superset && std::find(form.keys.begin(), form.keys.end(), key) != form.keys.end();
    if (superset && entry.forms.size() == 1) {
      fail("{} law: missing parameter {}", entry.name, fmt::join(missing, ", "));
    }
    sets.push_back(fmt::format("{{{}}}", fmt::join(form.keys, ", ")));
  }
  fail("{} law: parameters {{{}}} do not form an accepted set; give exactly one of {}", entry.name,
       fmt::join(given, ", "), fmt::join(sets, " | "));
}

}  // namespace weft::transmittance
