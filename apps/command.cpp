#include "command.h"

#include <cstdio>

#include <fmt/core.h>

#include "weft/core/parallel.h"
#include "weft/dist/distributed.h"

namespace weft::app {

std::vector<Command>& registry() {
  static std::vector<Command> commands;
  return commands;
}

void Context::say(const std::string& line) const {
  if (!globals.quiet) fmt::print("{}\n", line);
}

void Context::warn(const std::string& line) const {
  if (dist::is_root()) fmt::print(stderr, "weft: warning: {}\n", line);
}

unsigned Context::threads() const { return globals.threads > 0 ? globals.threads : default_thread_count(); }

int Context::ranks() const { return dist::size(); }

}  // namespace weft::app
