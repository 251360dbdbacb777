// Laws ↔ JSON (transmittance/law_json.h): every registered law survives the round trip through
// its own parameters, +∞ travels as "inf", and what JSON cannot hold is refused by name.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include <nlohmann/json.hpp>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/transmittance/law_json.h"
#include "weft/transmittance/registry.h"

namespace weft::transmittance {
namespace {

using json = nlohmann::json;
constexpr double inf = std::numeric_limits<double>::infinity();

TEST(LawJson, RoundTripRebuildsTheSameLaw) {
  const LawSpec specs[] = {
      {"exponential", {{"mu", 2.5}}, "", ""},         {"gamma", {{"mean_extinction", 3.0}, {"alpha", 0.7}}, "", ""},
      {"linear", {{"mean_extinction", 1.5}}, "", ""}, {"gamma-path", {{"k", 2.5}, {"theta", 0.4}}, "", ""},
      {"erlang", {{"k", 3}, {"rate", 2.0}}, "", ""},
  };
  for (const LawSpec& spec : specs) {
    const LawPtr law = make_law(spec);
    const json j = law_to_json(spec_of(*law));
    const LawPtr back = make_law(law_from_json(json::parse(j.dump()), "test"));
    EXPECT_EQ(back->name(), law->name());
    for (const double t : {0.0, 0.1, 1.0, 7.0}) EXPECT_EQ(back->transmittance(t), law->transmittance(t)) << spec.name;
  }
}

TEST(LawJson, TheSamplerChoiceSurvivesTheRoundTrip) {
  // spec_of records a non-default sampler (what `weft model --json` prints), not the default one.
  const LawPtr inversion = make_law({"gamma-path", {{"k", 2.5}, {"theta", 0.4}}, "", "inversion"});
  EXPECT_EQ(law_to_json(spec_of(*inversion)).value("sampler", ""), "inversion");
  const LawPtr back = make_law(law_from_json(law_to_json(spec_of(*inversion)), "test"));
  EXPECT_EQ(back->sampling_method(), inversion->sampling_method());
  const LawPtr fallback = make_law({"gamma-path", {{"k", 2.5}, {"theta", 0.4}}, "", ""});
  EXPECT_FALSE(law_to_json(spec_of(*fallback)).contains("sampler"));
  EXPECT_NE(fallback->sampling_method(), inversion->sampling_method());
}

TEST(LawJson, InfinityIsTheStringInf) {
  EXPECT_EQ(parameter_to_json(inf, "w", "alpha"), json("inf"));
  LawSpec spec{"gamma", {{"mean_extinction", 2.0}, {"alpha", inf}}, "", ""};
  const json j = law_to_json(spec);
  EXPECT_EQ(j.at("alpha"), json("inf"));
  const LawSpec back = law_from_json(json::parse(j.dump()), "test");
  EXPECT_EQ(back.params.at("alpha"), inf);
}

TEST(LawJson, RefusesWhatJsonCannotHold) {
  EXPECT_THROW((void)parameter_to_json(std::nan(""), "w", "alpha"), Error);
  EXPECT_THROW((void)parameter_to_json(-inf, "w", "alpha"), Error);
  EXPECT_THROW((void)law_from_json(json::parse(R"({"name": "gamma", "alpha": "infinite"})"), "w"), Error);
  EXPECT_THROW((void)law_from_json(json::parse(R"({"alpha": 2})"), "w"), Error);
  EXPECT_THROW((void)law_from_json(json(3), "w"), Error);
  EXPECT_THAT([] { (void)law_from_json(json::parse(R"({"name": "gamma", "alpha": [1]})"), "scene.media.cloth.law"); },
              weft::test::throws_one_line_error_with({"scene.media.cloth.law", "'alpha'"}))
      << "an array parameter must be refused";
}

TEST(LawJson, NameAloneIsALaw) { EXPECT_EQ(law_from_json(json("exponential"), "w").name, "exponential"); }

}  // namespace
}  // namespace weft::transmittance
