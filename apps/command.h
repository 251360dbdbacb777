#pragma once
/// @file
/// @brief Subcommand registry of the `weft` app: each commands/*.cpp registers itself.

#include <functional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "usage.h"
#include "weft/core/progress.h"

namespace weft::app {

/// Options every subcommand understands.
struct GlobalOptions {
  bool quiet = false;
  unsigned threads = 0;  ///< 0 = all hardware threads
};

/// What a subcommand needs at run time besides its own options.
struct Context {
  const GlobalOptions& globals;
  ProgressSink& progress;
  /// Prints a line to stdout unless --quiet.
  void say(const std::string& line) const;
};

using Action = std::function<int(const Context&)>;

/// A subcommand: `setup` declares its options on `sub` and returns the action to run.
struct Command {
  std::string name;
  std::string summary;
  int order = 100;  ///< position in `weft --help`
  std::function<Action(CLI::App& sub)> setup;
};

std::vector<Command>& registry();

struct Registrar {
  explicit Registrar(Command command) { registry().push_back(std::move(command)); }
};

}  // namespace weft::app
