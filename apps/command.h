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
  /// Prints a line to stdout unless --quiet (always quiet on MPI ranks other than 0).
  void say(const std::string& line) const;
  /// Prints `weft: warning: <line>` to stderr, --quiet or not (on MPI rank 0 only): something the
  /// run did that the user would want to know, such as a medium that cannot affect the image.
  void warn(const std::string& line) const;
  /// Worker threads per process (--threads, 0 resolved to the hardware's count) and processes
  /// (MPI ranks, 1 without mpirun): summaries and reports record both as "threads" and "ranks".
  [[nodiscard]] unsigned threads() const;
  [[nodiscard]] int ranks() const;
};

using Action = std::function<int(const Context&)>;

/// A subcommand: `setup` declares its options on `sub` and returns the action to run.
struct Command {
  std::string name;
  std::string summary;
  int order = 100;  ///< position in `weft --help`
  std::function<Action(CLI::App& sub)> setup;
  /// Spreads work units over MPI ranks (dist::run_units); other commands run on rank 0 only.
  bool distributed = false;
};

std::vector<Command>& registry();

struct Registrar {
  explicit Registrar(Command command) { registry().push_back(std::move(command)); }
};

}  // namespace weft::app
