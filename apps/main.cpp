// weft: how light gets through cloth. One binary, one subcommand per stage (docs/architecture.md §1).
#include <algorithm>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <exception>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include <fmt/core.h>

#include "command.h"
#include "interrupt.h"
#include "terminal_progress.h"
#include "usage.h"
#include "weft/core/error.h"
#include "weft/core/names.h"
#include "weft/core/parallel.h"
#include "weft/dist/distributed.h"

namespace {

/// Longest edit distance that still earns a suggestion: a third of the word, at least 2.
std::size_t suggest_distance(const std::string& word) { return std::max<std::size_t>(2, word.size() / 3); }

std::string did_you_mean(const std::string& word, const std::vector<std::string>& candidates) {
  const std::string best = weft::closest_name(word, candidates, suggest_distance(word));
  return best.empty() ? std::string() : fmt::format("; did you mean '{}'?", best);
}

/// `weft valdate`, `weft validate --axis x`: CLI11 says "The following arguments were not
/// expected: x --axis"; this names the first unknown word and the nearest command or option.
std::string extras_message(const CLI::App& app, const CLI::App* sub) {
  const std::vector<std::string> extras = app.remaining(true);
  std::vector<std::string> options;
  for (const CLI::App* a : {sub, &app}) {
    if (a == nullptr) continue;
    for (const CLI::Option* o : a->get_options()) {
      for (const auto& n : o->get_lnames()) options.push_back("--" + n);
    }
  }
  for (const auto& word : extras) {
    if (word.size() < 2 || word[0] != '-') continue;
    const std::string name = word.substr(0, word.find('='));
    return fmt::format("{}unknown option '{}'{} (see weft {}--help)", sub != nullptr ? sub->get_name() + ": " : "",
                       name, did_you_mean(name, options), sub != nullptr ? sub->get_name() + " " : "");
  }
  const std::string word = extras.empty() ? std::string() : extras.front();
  if (sub == nullptr) {
    std::vector<std::string> names;
    for (const CLI::App* s : app.get_subcommands([](const CLI::App*) { return true; })) names.push_back(s->get_name());
    return fmt::format("unknown command '{}'{} (see weft --help)", word, did_you_mean(word, names));
  }
  return fmt::format("{}: unexpected argument '{}' (see weft {} --help)", sub->get_name(), word, sub->get_name());
}

/// "" when everything written to standard output (stdio and iostreams: CLI11 prints its help
/// through std::cout) reached it, else why not.
std::string stdout_problem() {
  // std::cout writes through stdout's buffer: its flush is the first to meet a failure, and its
  // errno the one to report.
  errno = 0;
  std::cout.flush();
  int error = errno;
  const bool flushed = std::fflush(stdout) == 0;
  if (!flushed && errno != 0) error = errno;
  if (flushed && std::ferror(stdout) == 0 && std::cout) return {};
  return fmt::format("cannot write to standard output: {}", error != 0 ? std::strerror(error) : "the write failed");
}

}  // namespace

int main(int argc, char** argv) {
  using namespace weft::app;
  // Under mpirun every rank runs this same main; rank 0 alone prints and writes (docs/scale-out.md).
  weft::dist::Session mpi(argc, argv);
  // A file size limit (ulimit -f) is a short write like a full disk: with SIGXFSZ ignored write(2)
  // fails with EFBIG and the writer names the file and keeps the earlier one (docs/robustness.md
  // "Short writes"); its default action killed weft mid-file and left the temporary file behind.
  std::signal(SIGXFSZ, SIG_IGN);
  CLI::App app{
      "weft: transmittance of spatially-correlated media (cloth) -- ground truth, gamma models, rendering.\n"
      "Lengths are in the scene's unit (millimetres for cloth) unless an option says otherwise."};
  app.set_version_flag("--version", "weft 0.1.0");
  app.require_subcommand(0, 1);
  app.fallthrough();
  // Parse errors are one line like every other weft error; `--help` has the details.
  app.failure_message([](const CLI::App* /*app*/, const CLI::Error& e) {
    return fmt::format("weft: error: {} (see --help)\n", e.what());
  });

  GlobalOptions globals;
  app.add_flag("-q,--quiet", globals.quiet, "No progress bar and no summary on stdout");
  app.add_option("--threads", globals.threads,
                 "Worker threads (0 = all cores; also the EXR writer's pool); results do not depend on it")
      ->check(CLI::Range(0U, weft::kMaxThreads));

  auto& commands = registry();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const Command& a, const Command& b) { return a.order < b.order; });
  struct Entry {
    CLI::App* sub;
    Action action;
    bool distributed;
  };
  std::vector<Entry> actions;
  for (const auto& command : commands) {
    CLI::App* sub = app.add_subcommand(command.name, command.summary);
    actions.push_back({sub, command.setup(*sub), command.distributed});
  }
  check_number_options(app);

  try {
    check_empty_values(app, argc, argv);
    app.parse(argc, argv);
  } catch (const CLI::ExtrasError& e) {
    const CLI::App* sub = nullptr;
    for (const auto& entry : actions) {
      if (entry.sub->parsed()) sub = entry.sub;
    }
    if (weft::dist::is_root()) fmt::print(stderr, "weft: error: {}\n", extras_message(app, sub));
    return 2;
  } catch (const CLI::ConversionError& e) {
    const std::string message = narrow_integer_message(app, e);
    if (weft::dist::is_root())
      fmt::print(stderr, "weft: error: {} (see --help)\n", message.empty() ? std::string(e.what()) : message);
    return 2;
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every usage error exits 2 (the POSIX convention), whatever
    // CLI11's internal code, so scripts can tell a usage error from a failed run (exit 1).
    const int code = weft::dist::is_root() ? app.exit(e) : e.get_exit_code();
    if (code == 0) {
      // --help and --version print to standard output: one that cannot take them is an error.
      if (const std::string problem = stdout_problem(); !problem.empty()) {
        fmt::print(stderr, "weft: error: {}\n", problem);
        return 1;
      }
    }
    return code == 0 ? 0 : 2;
  } catch (const UsageError& e) {
    if (weft::dist::is_root()) fmt::print(stderr, "weft: error: {}\n", e.what());
    return 2;
  } catch (const weft::Error& e) {
    if (weft::dist::is_root()) fmt::print(stderr, "weft: error: {}\n", e.what());
    return 1;
  }

  if (!weft::dist::is_root()) globals.quiet = true;
  int code = 0;
  std::string error;
  try {
    const weft::ThreadLimit limit(globals.threads);
    catch_interrupts();
    TerminalProgress progress(!globals.quiet);
    const Context context{globals, progress};
    bool ran = false;
    for (auto& [sub, action, distributed] : actions) {
      if (sub->parsed()) {
        // A command without work units runs once, on rank 0; outputs that could not be written
        // are refused before it starts.
        if (distributed || weft::dist::is_root()) {
          check_output_options(*sub);
          code = action(context);
        }
        ran = true;
        break;
      }
    }
    if (!ran && weft::dist::is_root()) fmt::print("{}", app.help());
  } catch (const weft::Cancelled&) {
    // Ctrl-C or SIGTERM: the computation unwound at its next report; atomic writes removed their
    // temporaries (apps/interrupt.h).
    const int signal = interrupt_signal() != 0 ? interrupt_signal() : SIGINT;
    code = interrupted_exit_code(signal);
    error = fmt::format("weft: {}", interrupted_word(signal));
  } catch (const weft::dist::UnitFailure& e) {
    // Every rank has it; rank 0 prints it once.
    code = e.internal() ? 3 : 1;
    if (weft::dist::is_root())
      error = fmt::format("weft: error: {}{}", e.internal() ? "internal error: " : "", e.what());
  } catch (const UsageError& e) {
    code = 2;
    error = fmt::format("weft: error: {}", e.what());
  } catch (const weft::Error& e) {
    code = 1;
    error = fmt::format("weft: error: {}", e.what());
  } catch (const std::exception& e) {
    code = 3;
    error = fmt::format("weft: error: internal error: {}", e.what());
  }
  // The summary and `wrote` lines go to standard output, buffered: one that cannot take them (a
  // full disk) is an error, not a success whose report is lost without a word.
  if (code == 0) {
    if (const std::string problem = stdout_problem(); !problem.empty()) {
      code = 1;
      error = "weft: error: " + problem;
    }
  }
  return mpi.finish(code, error);
}
