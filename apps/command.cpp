#include "command.h"

#include <fmt/core.h>

namespace weft::app {

std::vector<Command>& registry() {
  static std::vector<Command> commands;
  return commands;
}

void Context::say(const std::string& line) const {
  if (!globals.quiet) fmt::print("{}\n", line);
}

}  // namespace weft::app
