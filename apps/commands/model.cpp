// `weft model`: evaluate and sample a transmittance law and its source/scatterer partner
// (lib/weft/transmittance; docs/architecture.md §6). Thin: parses options, calls the library, prints.
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iterator>
#include <memory>
#include <optional>
#include <span>
#include <sstream>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command.h"
#include "weft/core/error.h"
#include "weft/core/parse_number.h"
#include "weft/core/rng.h"
#include "weft/transmittance/draws.h"
#include "weft/transmittance/law_json.h"
#include "weft/transmittance/pair.h"
#include "weft/transmittance/registry.h"

namespace weft::app {
namespace {

namespace tr = weft::transmittance;
using json = nlohmann::json;

/// A law parameter as typed: CLI flag, registry key, unit for --help.
struct ParamFlag {
  const char* flag;
  const char* key;
  const char* help;
};

constexpr ParamFlag kParamFlags[] = {
    {"--sigma", "sigma", "gamma: extinction cross-section per unit concentration [1/length]"},
    {"--alpha", "alpha",
     "gamma, gap-gamma: shape alpha = C_bar^2/Var C [1], > 0 ('inf' = exponential); gamma-mixture: a list"},
    {"--beta", "beta", "gamma: rate beta = C_bar/Var C [1/concentration], > 0"},
    {"--mean-extinction", "mean_extinction",
     "gamma, gap-gamma (of the non-gap rays), linear (or exponential): mean extinction mu_bar = sigma*alpha/beta "
     "[1/length]; gamma-mixture: a list"},
    {"--gap", "gap", "gap-gamma: fraction of rays that see no fibre [1], in [0, 1)"},
    {"--weights", "weight", "gamma-mixture: comma-separated component weights [1], >= 0, summing to 1"},
    {"--mean-concentration", "mean_concentration", "gamma: mean concentration C_bar [concentration]"},
    {"--var-concentration", "var_concentration",
     "gamma: concentration variance Var C [concentration^2]; 0 = exponential"},
    {"--mu", "mu", "exponential: extinction coefficient [1/length]"},
    {"--k", "k", "gamma-path: shape k [1] (> 0); erlang: integer shape (>= 1)"},
    {"--theta", "theta", "gamma-path: scale theta [length]; mean free path = k*theta"},
    {"--rate", "rate", "erlang: rate of each exponential stage [1/length]"},
};
constexpr std::size_t kParamCount = sizeof(kParamFlags) / sizeof(kParamFlags[0]);

struct ModelOptions {
  std::string law = "gamma";
  std::string values[kParamCount];
  std::string table;
  std::string sampler;
  std::string t = "0,0.5,1,2,5,10";
  bool json = false;
  std::string given = "Q";
  std::string pair = "reciprocal";
  long long sample = 0;
  std::string from = "source";
  std::uint64_t seed = 1;
};

/// An option's number (weft::parse_number: subnormals are numbers, a value past double's range is not).
double number_option(const std::string& what, const std::string& text) {
  const std::optional<double> value = parse_option_number(text);
  if (!value) usage_fail("{}: '{}' is {}", what, text, number_problem(text));
  return *value;
}

std::vector<double> parse_distances(const std::string& list) {
  std::vector<double> out;
  std::stringstream in(list);
  for (std::string item; std::getline(in, item, ',');) {
    const double t = number_option("--t", item);
    if (std::isnan(t) || t < 0.0) usage_fail("--t: distances must be >= 0, got '{}'", item);
    out.push_back(t);
  }
  if (out.empty()) usage_fail("--t: no distances given");
  return out;
}

/// Finite numbers as numbers; ±∞ as "infinite"/"-infinite"; NaN as null.
json number(double x) {
  if (std::isnan(x)) return nullptr;
  if (std::isinf(x)) return x > 0 ? "infinite" : "-infinite";
  return x;
}

std::string text(double x) { return fmt::format("{:.10g}", x); }

/// The law's parameters in the scene format's convention (+∞ as "inf"; transmittance/law_json.h).
json parameters_json(const tr::Law& law) {
  json out = tr::law_to_json(tr::spec_of(law));
  out.erase("name");
  return out;
}

std::string parameters_text(const tr::Law& law) {
  std::string out;
  for (const auto& p : law.parameters())
    out += fmt::format("{}{} = {}", out.empty() ? "" : ", ", p.name, text(p.value));
  return out;
}

std::string help_footer() {
  std::string out = "Laws and their parameters (lengths in the scene's unit):\n";
  for (const auto& name : tr::law_names()) out += tr::describe_law(name);
  out +=
      "Pairs: the given law is T_Q (segments from a source/surface, --given Q) or T_S (from a scatterer,\n"
      "--given S); --pair reciprocal derives the partner (T_S = p_Q/p_Q(0), T_Q = int_t^inf T_S/l_S),\n"
      "--pair same uses the given law for both. Output columns: t [length], T [1], p [1/length],\n"
      "Sigma [1/length] for Q and S.";
  return out;
}

int run(const ModelOptions& o, const std::vector<bool>& given_flags, const CLI::App& sub, const Context& ctx) {
  // --sample N prints N draws (none for 0, as Python's Law.sample(0)); the options of the draws
  // do nothing without it.
  const bool sampling = sub.count("--sample") > 0;
  usage_needs(sub, {"--sampler", "--from", "--seed"}, sampling, "--sample");
  // --sample prints draws instead of the table at --t: a --t beside it would be read by nothing.
  if (sampling && sub.count("--t") > 0)
    usage_fail("--t does not go with --sample (it prints free-flight distances instead of T at --t)");
  // p ∝ T (S.55-S.57) is not a sampler of the law (it draws another density): it is the source law
  // of the reciprocal pair given as T_S, p_Q = T_S/l_S (docs/transmittance.md), the same draws.
  if (o.sampler == "proportional")
    usage_fail(
        "--sampler proportional: p proportional to T is the source law of the pair given as T_S "
        "(p_Q = T_S/l_S): draw it with --given S --from source");
  tr::LawSpec spec;
  spec.name = o.law;
  spec.table = o.table;
  spec.sampler = o.sampler;  // the registry's rule: which laws offer a choice (weft.law's sampler= too)
  bool any_parameter = !o.table.empty();
  // A law with list parameters (gamma-mixture) reads each flag as a comma-separated list,
  // element j under the registry key "<key>_<j+1>".
  const bool lists = tr::takes_parameter_lists(o.law);
  for (std::size_t i = 0; i < kParamCount; ++i) {
    if (!given_flags[i]) continue;
    if (lists) {
      std::stringstream in(o.values[i]);
      std::size_t j = 0;
      for (std::string item; std::getline(in, item, ',');)
        spec.params[tr::list_parameter_key(kParamFlags[i].key, j++)] = number_option(kParamFlags[i].flag, item);
      if (j == 0 || o.values[i].back() == ',')
        usage_fail("{}: expected a comma-separated list of numbers, got '{}'", kParamFlags[i].flag, o.values[i]);
    } else {
      spec.params[kParamFlags[i].key] = number_option(kParamFlags[i].flag, o.values[i]);
    }
    any_parameter = true;
  }
  const bool default_law = !given_flags[kParamCount] && !any_parameter;
  if (default_law) spec.params = {{"mean_extinction", 1.0}, {"alpha", 2.0}};
  const std::string note =
      "no law given: using the default gamma law (mean_extinction = 1 [1/length], alpha = 2); see weft model --help";

  // Every law but the tabulated one is made from option values only: its errors are usage errors
  // (exit 2); a table's errors are about its file (exit 1).
  const tr::LawPtr law = o.law == "tabulated" ? tr::make_law(spec) : as_usage([&] { return tr::make_law(spec); });
  const tr::PairMode mode = as_usage([&] { return tr::parse_pair_mode(o.pair); });
  const tr::Origin given = as_usage([&] { return tr::parse_origin(o.given); });
  const tr::Origin from = sampling ? as_usage([&] { return tr::parse_origin(o.from); }) : given;
  // Draws from the given side need only the given law, as Python's Law.sample: its reciprocal
  // partner, which may not exist (p_Q(0) = 0 for gamma-path with k > 1), is built only when it is
  // drawn from or tabulated. The pair is still reported as the mode asked for.
  const bool given_law_only = sampling && mode == tr::PairMode::reciprocal && from == given;
  const tr::TransmittancePair pair = given_law_only ? tr::TransmittancePair::same(law) : [&] {
    switch (mode) {
      case tr::PairMode::same:
        return tr::TransmittancePair::same(law);
      case tr::PairMode::explicit_:
        usage_fail("--pair explicit needs two laws; weft model takes one (use reciprocal or same)");
      case tr::PairMode::reciprocal:
        break;
    }
    try {
      return tr::TransmittancePair::reciprocal(law, given);
    } catch (const Error& e) {
      usage_fail("{} (try --pair same, or --given {})", e.what(), given == tr::Origin::source ? "S" : "Q");
    }
  }();

  if (o.sample < 0) usage_fail("--sample: expected a count >= 0, got {}", o.sample);
  if (static_cast<std::uint64_t>(o.sample) > tr::kMaxDraws)
    usage_fail("--sample: at most 1e9 samples per run, got {} (run several seeds)", o.sample);
  if (sampling) {
    // Streamed chunk by chunk (N may be far larger than memory); each chunk is a progress report,
    // where Ctrl-C or SIGTERM stops the run (what was printed before stays printed). With --json,
    // the same numbers in one object whose "samples" array is streamed after its other fields (+∞
    // as "infinite").
    std::string out;
    if (o.json) {
      const tr::Law& drawn = pair.law(from);
      json head = {{"law", law->name()},
                   {"parameters", parameters_json(*law)},
                   {"given", given == tr::Origin::source ? "Q" : "S"},
                   {"pair", tr::to_string(mode)},
                   {"from", tr::to_string(from)},
                   {"sampled_law", {{"law", drawn.name()}, {"parameters", parameters_json(drawn)}}},
                   {"sampling", drawn.sampling_method()},
                   {"seed", o.seed},
                   {"count", o.sample},
                   {"units", {{"t", "length"}}}};
      if (default_law) head["note"] = note;
      out = head.dump(2);
      out.resize(out.size() - 2);  // reopen the object: dump(2) ends with "\n}"
      out += ",\n  \"samples\": [";
    } else if (default_law && !ctx.globals.quiet) {
      fmt::print(stderr, "weft: note: {}\n", note);
    }
    const auto flush = [&out] {
      if (std::fwrite(out.data(), 1, out.size(), stdout) != out.size())
        fail("cannot write samples to stdout: {}", std::strerror(errno));
      out.clear();
    };
    std::uint64_t taken = 0;
    tr::draw_in_chunks(
        static_cast<std::uint64_t>(o.sample), o.seed, ctx.progress, [&](Pcg32& rng) { return pair.sample(from, rng); },
        [&](std::span<const double> chunk) {
          for (const double t : chunk) {
            if (o.json) {
              out += taken++ == 0 ? "\n    " : ",\n    ";
              out += std::isfinite(t) ? fmt::format("{:.17g}", t) : number(t).dump();
            } else {
              fmt::format_to(std::back_inserter(out), "{:.17g}\n", t);
            }
          }
          flush();
        });
    if (o.json) out += taken == 0 ? "]\n}\n" : "\n  ]\n}\n";
    flush();
    if (std::fflush(stdout) != 0) fail("cannot write samples to stdout: {}", std::strerror(errno));
    return 0;
  }

  const std::vector<double> ts = parse_distances(o.t);
  const tr::Law& q = pair.law(tr::Origin::source);
  const tr::Law& s = pair.law(tr::Origin::scatterer);
  if (o.json) {
    const auto side = [](const tr::Law& l) {
      return json{{"law", l.name()},
                  {"parameters", parameters_json(l)},
                  {"sampling", l.sampling_method()},
                  {"mean_free_path", number(l.mean_free_path())}};
    };
    json points = json::array();
    for (double t : ts) {
      points.push_back({{"t", number(t)},
                        {"T_Q", number(q.transmittance(t))},
                        {"p_Q", number(q.pdf(t))},
                        {"Sigma_Q", number(q.hazard(t))},
                        {"T_S", number(s.transmittance(t))},
                        {"p_S", number(s.pdf(t))},
                        {"Sigma_S", number(s.hazard(t))}});
    }
    json out = {{"law", law->name()},
                {"parameters", parameters_json(*law)},
                {"given", given == tr::Origin::source ? "Q" : "S"},
                {"pair", tr::to_string(pair.mode())},
                {"source", side(q)},
                {"scatterer", side(s)},
                {"mean_free_path", {{"source", number(q.mean_free_path())}, {"scatterer", number(s.mean_free_path())}}},
                {"units", {{"t", "length"}, {"T", "1"}, {"p", "1/length"}, {"Sigma", "1/length"}}},
                {"points", points}};
    if (default_law) out["note"] = note;
    fmt::print("{}\n", out.dump(2));
    return 0;
  }

  std::string out;
  if (default_law) out += fmt::format("# {}\n", note);
  out += fmt::format("# law: {} ({}), given as T_{}; pair: {}\n", law->name(), parameters_text(*law),
                     given == tr::Origin::source ? "Q" : "S", tr::to_string(pair.mode()));
  out += fmt::format("# source law T_Q: {} ({}); mean free path l_Q = {}\n", q.name(), parameters_text(q),
                     text(q.mean_free_path()));
  out += fmt::format("# scatterer law T_S: {} ({}); mean free path l_S = {}\n", s.name(), parameters_text(s),
                     text(s.mean_free_path()));
  out += fmt::format("{:>16} {:>16} {:>16} {:>16} {:>16} {:>16} {:>16}\n", "t", "T_Q", "p_Q", "Sigma_Q", "T_S", "p_S",
                     "Sigma_S");
  for (double t : ts) {
    out += fmt::format("{:>16} {:>16} {:>16} {:>16} {:>16} {:>16} {:>16}\n", text(t), text(q.transmittance(t)),
                       text(q.pdf(t)), text(q.hazard(t)), text(s.transmittance(t)), text(s.pdf(t)), text(s.hazard(t)));
  }
  fmt::print("{}", out);
  return 0;
}

const Registrar kModel{Command{
    "model", "Evaluate and sample transmittance laws (T, p, Sigma; source/scatterer pairs)", 40,
    [](CLI::App& sub) -> Action {
      auto o = std::make_shared<ModelOptions>();
      std::string names;
      for (const auto& n : tr::law_names()) names += (names.empty() ? "" : ", ") + n;
      auto* law_option = sub.add_option("--law", o->law, "Law name: " + names)->capture_default_str();
      std::vector<CLI::Option*> flags;
      for (std::size_t i = 0; i < kParamCount; ++i) {
        flags.push_back(sub.add_option(kParamFlags[i].flag, o->values[i], kParamFlags[i].help)->type_name("NUMBER"));
      }
      flags.push_back(law_option);
      sub.add_option("--table", o->table, "tabulated: CSV file with columns t [length], T [1]")->check(file_name);
      sub.add_option("--sampler", o->sampler,
                     "With --sample, where the law offers several: gamma-path marsaglia-tsang (default) or "
                     "inversion (p proportional to T, S.55-S.57: --given S --from source)");
      sub.add_option("--t", o->t, "Comma-separated distances t [length] to evaluate")->capture_default_str();
      sub.add_flag("--json", o->json,
                   "Print one JSON object (law, parameters, mean free paths, points; with --sample: the samples)");
      sub.add_option("--given", o->given, "The law given is T_Q (Q, source) or T_S (S, scatterer)")
          ->capture_default_str();
      sub.add_option("--pair", o->pair, "reciprocal (derive the partner) or same (T_S = T_Q)")->capture_default_str();
      sub.add_option("--sample", o->sample,
                     "Print N sampled free-flight distances [length], one per line (0: none), instead of T at --t");
      sub.add_option("--from", o->from, "With --sample: segments starting at a source or a scatterer")
          ->capture_default_str();
      sub.add_option("--seed", o->seed, "With --sample: the random seed")->capture_default_str();
      sub.footer(help_footer());
      return [o, flags, &sub](const Context& ctx) -> int {
        std::vector<bool> given;
        given.reserve(flags.size());
        for (auto* f : flags) given.push_back(f->count() > 0);
        return run(*o, given, sub, ctx);
      };
    }}};

}  // namespace
}  // namespace weft::app
