// weft: how light gets through cloth. One binary, one subcommand per stage (design §1).
#include <algorithm>
#include <cstdio>
#include <exception>
#include <memory>

#include <fmt/core.h>

#include "command.h"
#include "terminal_progress.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"

int main(int argc, char** argv) {
  using namespace weft::app;
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
  std::vector<std::pair<CLI::App*, Action>> actions;
  for (const auto& command : commands) {
    CLI::App* sub = app.add_subcommand(command.name, command.summary);
    actions.emplace_back(sub, command.setup(*sub));
  }

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version exit 0; every usage error exits 2 (the POSIX convention), whatever
    // CLI11's internal code, so scripts can tell a usage error from a failed run (exit 1).
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  } catch (const weft::Error& e) {
    fmt::print(stderr, "weft: error: {}\n", e.what());
    return 1;
  }

  try {
    const weft::ThreadLimit limit(globals.threads);
    TerminalProgress progress(!globals.quiet);
    const Context context{globals, progress};
    for (auto& [sub, action] : actions) {
      if (sub->parsed()) return action(context);
    }
    fmt::print("{}", app.help());
    return 0;
  } catch (const weft::Error& e) {
    fmt::print(stderr, "weft: error: {}\n", e.what());
    return 1;
  } catch (const std::exception& e) {
    fmt::print(stderr, "weft: error: internal error: {}\n", e.what());
    return 3;
  }
}
