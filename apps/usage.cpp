#include "usage.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <limits>
#include <string_view>
#include <vector>

#include "weft/core/atomic_file.h"
#include "weft/core/parse_number.h"

namespace weft::app {

double usage_positive(const char* option, double value) {
  if (!(std::isfinite(value) && value > 0.0)) usage_fail("{} must be finite and > 0, got {}", option, value);
  return value;
}

double usage_non_negative(const char* option, double value) {
  if (!(std::isfinite(value) && value >= 0.0)) usage_fail("{} must be finite and >= 0, got {}", option, value);
  return value;
}

void usage_needs(const CLI::App& sub, std::initializer_list<const char*> names, bool condition, std::string_view what) {
  if (condition) return;
  std::vector<std::string> given;
  for (const char* name : names) {
    if (sub.count(name) > 0) given.emplace_back(name);
  }
  if (given.empty()) return;
  std::string list = given.front();
  for (std::size_t i = 1; i < given.size(); ++i) list += (i + 1 == given.size() ? " and " : ", ") + given[i];
  usage_fail("{} {} {}", list, given.size() == 1 ? "needs" : "need", what);
}

namespace {

/// The option's text as a double, or NaN (CLI11 has already refused non-numbers for numeric
/// options; "nan" and "inf" parse and are refused by the callers).
double number_of(const std::string& text) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  return end == text.c_str() || *end != '\0' ? std::nan("") : v;
}

}  // namespace

const CLI::Validator positive(
    [](std::string& text) -> std::string {
      const double v = number_of(text);
      return std::isfinite(v) && v > 0.0 ? std::string() : fmt::format("must be finite and > 0, got {}", text);
    },
    "> 0", "positive");

const CLI::Validator non_negative(
    [](std::string& text) -> std::string {
      const double v = number_of(text);
      return std::isfinite(v) && v >= 0.0 ? std::string() : fmt::format("must be finite and >= 0, got {}", text);
    },
    ">= 0", "non_negative");

const CLI::Validator file_name(
    [](std::string& text) -> std::string { return text.empty() ? "must name a file, got an empty value" : ""; }, "FILE",
    "file_name");

CLI::Validator at_least(long long min) {
  return CLI::Validator(
      [min](std::string& text) -> std::string {
        const double v = number_of(text);
        return std::isfinite(v) && v >= static_cast<double>(min) ? std::string()
                                                                 : fmt::format("must be >= {}, got {}", min, text);
      },
      fmt::format(">= {}", min), "at_least");
}

CLI::Validator in_range(double lo, double hi, bool hi_included) {
  const std::string range = fmt::format("[{}, {}{}", lo, hi, hi_included ? ']' : ')');
  return CLI::Validator(
      [lo, hi, hi_included, range](std::string& text) -> std::string {
        const double v = number_of(text);
        return std::isfinite(v) && v >= lo && (hi_included ? v <= hi : v < hi)
                   ? std::string()
                   : fmt::format("must be a number in {}, got {}", range, text);
      },
      range, "in_range");
}

namespace {

// An integer option's value in decimal digits, checked and written back canonically before any
// other check or CLI11's conversion sees it. CLI11 2.1 converts with strtoll's base 0, which
// reads a leading 0 as octal (--spp 010 was 8, --seed 08 a refusal) and 0x as hex: here every
// integer is decimal, as the docs and the Python calls read it. Blanks around the digits are
// dropped (as parse_option_number drops them for the real-valued options), leading zeros too, and -0 is
// 0. A whole number in another spelling (1e3, 2.0, 0x10) is refused with its digits.
std::string canonical_integer(std::string& text, bool is_unsigned) {
  const std::size_t first = text.find_first_not_of(" \t");
  const std::size_t last = text.find_last_not_of(" \t");
  const std::string given = text;
  std::string body = first == std::string::npos ? std::string() : text.substr(first, last - first + 1);
  const bool negative = !body.empty() && body[0] == '-';
  const std::string_view digits = std::string_view(body).substr(!body.empty() && (body[0] == '-' || body[0] == '+'));
  if (digits.empty() || digits.find_first_not_of("0123456789") != std::string_view::npos) {
    // Not decimal digits: said as a whole number when it is one in another spelling.
    char* number_end = nullptr;
    const double v = body.empty() ? 0.0 : std::strtod(body.c_str(), &number_end);
    if (!body.empty() && number_end == body.c_str() + body.size() && std::isfinite(v)) {
      if (v == std::floor(v) && std::abs(v) < 1e18 && (v >= 0.0 || !is_unsigned))
        return fmt::format("must be a whole number written in decimal digits ({:.0f}), got {}", v, given);
      return fmt::format("must be a whole number, got {}", given);
    }
    return fmt::format("must be a whole number written in decimal digits, got {}", given);
  }
  const std::size_t nonzero = digits.find_first_not_of('0');
  const std::string_view magnitude = nonzero == std::string_view::npos ? std::string_view("0") : digits.substr(nonzero);
  if (negative && magnitude != "0" && is_unsigned) return fmt::format("must be >= 0, got {}", given);
  const std::string canonical = (negative && magnitude != "0" ? "-" : "") + std::string(magnitude);
  errno = 0;
  if (is_unsigned) {
    (void)std::strtoull(canonical.c_str(), nullptr, 10);
  } else {
    (void)std::strtoll(canonical.c_str(), nullptr, 10);
  }
  if (errno == ERANGE) {
    return is_unsigned ? fmt::format("must be <= {}, got {}", std::numeric_limits<std::uint64_t>::max(), given)
                       : fmt::format("must be in [{}, {}], got {}", std::numeric_limits<std::int64_t>::min(),
                                     std::numeric_limits<std::int64_t>::max(), given);
  }
  text = canonical;
  return {};
}

// A real-valued option's value: parse_option_number's spelling (decimal, blanks around it
// dropped), written back without the blanks; CLI11 2.1 took hex floats and leading blanks through
// strtod, refused trailing ones with "Could not convert" and read 1e309 as inf.
std::string canonical_real(std::string& text) {
  const std::string_view t = trim_blanks(text);
  if (parse_number(t)) {
    text = std::string(t);
    return {};
  }
  return fmt::format("'{}' is {}", text, number_problem(text));
}

}  // namespace

void check_number_options(CLI::App& app) {
  for (CLI::Option* option : app.get_options()) {
    const std::string type = option->get_type_name();
    if (type.rfind("FLOAT", 0) == 0) {
      option->transform(CLI::Validator(canonical_real, "", "real"));
      continue;
    }
    const bool is_unsigned = type.rfind("UINT", 0) == 0;
    if (!is_unsigned && type.rfind("INT", 0) != 0) continue;
    // A transform: it runs first (CLI11 puts transforms before the checks), so the range checks
    // and the conversion see the canonical digits.
    option->transform(CLI::Validator([is_unsigned](std::string& text) { return canonical_integer(text, is_unsigned); },
                                     "", "integer"));
  }
  for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) check_number_options(*sub);
}

std::string narrow_integer_message(const CLI::App& app, const CLI::ConversionError& e) {
  // CLI11 2.x: "Could not convert: <name> = <values>".
  static constexpr std::string_view kPrefix = "Could not convert: ";
  const std::string_view what = e.what();
  const std::size_t eq = what.find(" = ");
  if (!what.starts_with(kPrefix) || eq == std::string_view::npos) return {};
  const std::string name(what.substr(kPrefix.size(), eq - kPrefix.size()));
  const std::string value(what.substr(eq + 3));
  const CLI::Option* option = nullptr;
  const std::function<void(const CLI::App&)> search = [&](const CLI::App& a) {
    if (option == nullptr && a.parsed()) option = a.get_option_no_throw(name);
    for (const CLI::App* sub : a.get_subcommands()) search(*sub);
  };
  search(app);
  if (option == nullptr) return {};
  const std::string type = option->get_type_name();
  const bool is_unsigned = type.rfind("UINT", 0) == 0;
  if (!is_unsigned && type.rfind("INT", 0) != 0) return {};
  errno = 0;
  char* end = nullptr;
  const long long v = std::strtoll(value.c_str(), &end, 10);  // canonical_integer's digits
  if (end == value.c_str() || *end != '\0' || errno == ERANGE) return {};
  if (v < 0 && !is_unsigned)
    return fmt::format("{}: must be >= {}, got {}", name, std::numeric_limits<std::int32_t>::min(), value);
  return fmt::format("{}: must be <= {}, got {}", name,
                     is_unsigned ? std::numeric_limits<std::uint32_t>::max()
                                 : static_cast<std::uint32_t>(std::numeric_limits<std::int32_t>::max()),
                     value);
}

void check_output_options(const CLI::App& sub) {
  for (const CLI::Option* option : sub.get_options()) {
    const bool folder = option->check_lname("out");
    if (!folder && !option->check_lname("output")) continue;
    std::string value = option->count() > 0 ? option->as<std::string>() : option->get_default_str();
    // Given empty, it would read as the option left out and the command would write to its
    // default path; given blank, it would make a folder named " " (docs/robustness.md, the
    // empty-argument cases): refused, like file_name, by the rule the Python calls use too.
    if (const std::string problem = option->count() > 0 ? output_name_problem(value, folder) : std::string();
        !problem.empty()) {
      std::string name = option->get_name(false, true);  // "-o,--output": as the help lists it
      std::replace(name.begin(), name.end(), ',', '/');
      usage_fail("{}: {}", name, problem);
    }
    if (value.empty()) continue;  // an output the command does not write unless asked for
    const std::filesystem::path path(value);
    if (!folder) {
      if (const std::string problem = output_file_problem(path); !problem.empty())
        fail("output file '{}' {}", path.string(), problem);
    }
    check_writable_folder(folder ? path : (path.has_parent_path() ? path.parent_path() : std::filesystem::path(".")));
  }
}

namespace {

/// The option `name` ("--cases", "-o") of `app` or, as CLI11 falls through, of its parents.
const CLI::Option* find_option(const CLI::App* app, const std::string& name) {
  for (; app != nullptr; app = app->get_parent()) {
    if (const CLI::Option* option = app->get_option_no_throw(name)) return option;
  }
  return nullptr;
}

}  // namespace

void check_empty_values(const CLI::App& app, int argc, const char* const* argv) {
  const CLI::App* current = &app;
  for (int i = 1; i < argc; ++i) {
    const std::string_view token = argv[i];
    if (token == "--") return;  // positionals only from here
    if (token.size() < 2 || token[0] != '-') {
      // A subcommand's name: its options follow (the others are positionals or values).
      for (const CLI::App* sub : current->get_subcommands([](const CLI::App*) { return true; })) {
        if (sub->get_name() == token) current = sub;
      }
      continue;
    }
    const auto eq = token.starts_with("--") ? token.find('=') : std::string_view::npos;
    const std::string name(token.substr(0, eq));
    const CLI::Option* option = find_option(current, name);
    if (option == nullptr || option->get_items_expected_max() == 0) continue;  // unknown (CLI11 says), or a flag
    const bool attached = eq != std::string_view::npos;
    if (!attached && i + 1 >= argc) continue;  // CLI11 says the value is missing
    const std::string_view value = attached ? token.substr(eq + 1) : std::string_view(argv[++i]);
    const char delimiter = option->get_delimiter();
    if (delimiter != '\0' && value.find_first_not_of(delimiter) == std::string_view::npos)
      usage_fail("{}: an empty list, got '{}' (give at least one item)", name, value);
    if (attached && value.empty()) usage_fail("{}: an empty value ('{}')", name, token);
    // Given as a separate argument (`--seed ""`), CLI11 reads an empty value as 0 or as the option
    // left out. Files, folders and lists have checks of their own that name what they expect.
    const std::string type = option->get_type_name();
    const bool own_check = type.find("FILE") != std::string::npos || type.find("LIST") != std::string::npos ||
                           option->check_lname("out") || option->check_lname("output");
    if (value.empty() && !own_check) usage_fail("{}: an empty value ('')", name);
  }
}

}  // namespace weft::app
