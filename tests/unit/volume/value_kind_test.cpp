// The one rule for a value kind given against the grid's metadata (volume::require_value_kind,
// docs/robustness.md "Value kind"): each recorded kind refuses the other one, in words that say
// what to pass, and a grid without a recorded kind is read as the caller says.
#include <gtest/gtest.h>

#include <string>

#include <fmt/format.h>

#include "weft/core/error.h"
#include "weft/volume/provenance.h"

namespace weft::volume {
namespace {

std::string refusal(const std::string& recorded, bool read_as_extinction, ValuesAsker asker = ValuesAsker::cli) {
  Provenance p;
  p.value_kind = recorded;
  try {
    require_value_kind(p, read_as_extinction, "g.vdb", asker);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(ValueKind, EachRecordedKindRefusesTheOther) {
  for (const std::string kind : {"concentration", "extinction"}) {
    const bool extinction = kind == "extinction";
    EXPECT_EQ(refusal(kind, extinction), "") << kind;
    const std::string says = fmt::format("g.vdb: the grid's metadata says its values are {}; ", kind);
    EXPECT_EQ(refusal(kind, !extinction), fmt::format("{}pass --values {}", says, kind));
    EXPECT_EQ(refusal(kind, !extinction, ValuesAsker::scene), fmt::format("{}set \"values\": \"{}\"", says, kind));
  }
}

TEST(ValueKind, AGridWithoutARecordedKindAcceptsEither) {
  for (const std::string kind : {"", "density"}) {
    EXPECT_EQ(refusal(kind, false), "") << kind;
    EXPECT_EQ(refusal(kind, true), "") << kind;
  }
}

}  // namespace
}  // namespace weft::volume
