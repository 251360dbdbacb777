// weft: how light gets through cloth. One binary, one subcommand per stage (design §1).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <memory>
#include <string>

#include <fmt/core.h>

#include "command.h"
#include "terminal_progress.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/dist/distributed.h"

int main(int argc, char** argv) {
  using namespace weft::app;
  // Under mpirun every rank runs this same main; rank 0 alone prints and writes (docs/scale-out.md).
  weft::dist::Session mpi(argc, argv);
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
  app.add_option("--threads", globals.threads, "Worker threads (0 = all cores); results do not depend on it")
      ->check(CLI::Range(0U, 1024U));

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

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every usage error exits 2 (the POSIX convention), whatever
    // CLI11's internal code, so scripts can tell a usage error from a failed run (exit 1).
    const int code = weft::dist::is_root() ? app.exit(e) : e.get_exit_code();
    return code == 0 ? 0 : 2;
  } catch (const weft::Error& e) {
    if (weft::dist::is_root()) fmt::print(stderr, "weft: error: {}\n", e.what());
    return 1;
  }

  if (!weft::dist::is_root()) globals.quiet = true;
  int code = 0;
  std::string error;
  try {
    const weft::ThreadLimit limit(globals.threads);
    TerminalProgress progress(!globals.quiet);
    const Context context{globals, progress};
    bool ran = false;
    for (auto& [sub, action, distributed] : actions) {
      if (sub->parsed()) {
        // A command without work units runs once, on rank 0.
        if (distributed || weft::dist::is_root()) code = action(context);
        ran = true;
        break;
      }
    }
    if (!ran && weft::dist::is_root()) fmt::print("{}", app.help());
  } catch (const weft::dist::UnitFailure& e) {
    // Every rank has it; rank 0 prints it once.
    code = e.internal() ? 3 : 1;
    if (weft::dist::is_root())
      error = fmt::format("weft: error: {}{}", e.internal() ? "internal error: " : "", e.what());
  } catch (const weft::Error& e) {
    code = 1;
    error = fmt::format("weft: error: {}", e.what());
  } catch (const std::exception& e) {
    code = 3;
    error = fmt::format("weft: error: internal error: {}", e.what());
  }
  return mpi.finish(code, error);
}
