#pragma once
/// @file
/// @brief Usage errors of the `weft` app: an option that is unknown, out of range or in conflict
/// with another exits 2 (README "Exit codes"); a run that fails on its input exits 1.
///
/// One mechanism for every command: a check on an option's value either
///   - is declared on the option with a validator below (`->check(positive)`), which CLI11 runs
///     while parsing, or
///   - runs in the action and throws UsageError (`usage_fail`, `usage_positive`, or
///     `as_usage(...)` around a library parser whose weft::Error is about an option value).
/// main.cpp maps CLI::ParseError and UsageError to exit 2; any other weft::Error to 1.

#include <cmath>
#include <initializer_list>
#include <string>
#include <string_view>
#include <utility>

#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include "weft/core/error.h"

namespace weft::app {

/// @brief A bad option value or a conflict of options (exit 2), not a failed run.
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& message) : Error(message) {}
};

/// @brief Throws UsageError with a fmt-formatted message naming the option.
template <typename... Args>
[[noreturn]] void usage_fail(fmt::format_string<Args...> format, Args&&... args) {
  throw UsageError(fmt::format(format, std::forward<Args>(args)...));
}

/// @brief Runs `f` (a library parser or validator fed only option values) and turns its
/// weft::Error into a UsageError with the same message.
template <typename F>
decltype(auto) as_usage(F&& f) {
  try {
    return std::forward<F>(f)();
  } catch (const UsageError&) {
    throw;
  } catch (const Error& e) {
    throw UsageError(e.what());
  }
}

/// @brief `value` finite and > 0, else UsageError naming `option`.
double usage_positive(const char* option, double value);
/// @brief `value` finite and >= 0, else UsageError naming `option`.
double usage_non_negative(const char* option, double value);

/// @brief Refuses the options `names` of `sub` that the command line gave, unless `condition`:
/// UsageError "--a and --b need <what>", naming only those given. The one check of every command
/// for an option that acts only with another (--fibre-rays with --fibres, --resume with the
/// study matrix): refused, never silently ignored.
void usage_needs(const CLI::App& sub, std::initializer_list<const char*> names, bool condition, std::string_view what);

/// CLI11 validators (parse time, exit 2). Unlike CLI::PositiveNumber they refuse NaN and ±inf.
/// Finite and > 0.
extern const CLI::Validator positive;
/// Finite and >= 0.
extern const CLI::Validator non_negative;
/// A file name: not empty (an empty value would otherwise read as the option left out, and a
/// command would run on its default input).
extern const CLI::Validator file_name;
/// An integer count >= `min` (the message says "must be >= min").
CLI::Validator at_least(long long min);
/// A finite number in [lo, hi], or in [lo, hi) when `hi_included` is false (CLI::Range lets NaN
/// through: every comparison with it is false).
CLI::Validator in_range(double lo, double hi, bool hi_included = true);

/// @brief Refuses an option value that is empty after CLI11 splits it: `--input=` or a list of
/// delimiters only (`--cases ,`). CLI11 2.1 counts no value for it and takes the next argument as
/// the value instead (`--cases , --no-plot` looked for cases named "--no-plot"). main() calls it
/// once on the command line, before parsing, so every option of every command is covered.
void check_empty_values(const CLI::App& app, int argc, const char* const* argv);

/// @brief Gives every numeric option of `app` and its subcommands one checked parse, run before
/// its other checks (a CLI11 transform). Integers (CLI11 type name UINT or INT): CLI11 2.1 reads
/// "-1" into an unsigned option as 2^64 − 1, a number past the 64-bit range as the largest value,
/// and converts in base 0 (010 is 8, 0x10 is 16), silently. Instead every integer is read in
/// decimal digits (blanks around them and leading zeros dropped, -0 as 0), and refused with the
/// option named otherwise: another spelling (1e3, 2.0, 0x10: said with its digits), a negative
/// value of an unsigned option, any value outside the 64-bit range. (Narrower types CLI11 itself
/// refuses when the value does not fit.) Reals (FLOAT): weft::parse_option_number's spelling, the
/// one every list of numbers and every file header uses too (decimal, blanks around it dropped;
/// a hexadecimal number or one past double's range refused as such, weft::number_problem).
/// main() calls it once, after every command has declared its options, so no command can forget
/// it.
void check_number_options(CLI::App& app);

/// @brief The message for an integer CLI11 could not store: check_number_options lets through
/// what fits in 64 bits, so a whole number refused here is past a narrower option's range (every
/// narrower integer option of weft is 32 bits), said with that range instead of CLI11's "Could not
/// convert". Empty for any other conversion error (CLI11's own message stands).
[[nodiscard]] std::string narrow_integer_message(const CLI::App& app, const CLI::ConversionError& e);

/// @brief Refuses, before the command runs, outputs it could not write (docs/robustness.md):
/// the folder of every given or defaulted `--out` option of the parsed subcommand `sub`, and the
/// folder of its `--output` file (weft::check_writable_folder). A given empty or blank value is
/// refused (weft::output_name_problem: UsageError "--out: must name a folder, got an empty value"),
/// not read as the option left out nor made into a folder named " ".
/// main() calls it once for the command that will run, so no command finds an unwritable folder
/// only after its work.
void check_output_options(const CLI::App& sub);

}  // namespace weft::app
