// Hard cases against high-precision references (scripts/reference/transmittance_reference.py,
// mpmath at 60 digits): every value within 1e−10 relative, finite where the reference is, in
// range, and monotone in t.
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include <fmt/format.h>
#include <gtest/gtest.h>

#include "weft/transmittance/erlang.h"
#include "weft/transmittance/exponential.h"
#include "weft/transmittance/gamma_concentration.h"
#include "weft/transmittance/gamma_path.h"
#include "weft/transmittance/linear.h"
#include "weft/transmittance/registry.h"

namespace weft::transmittance {
namespace {

struct Row {
  int line = 0;
  std::string law;
  double p1 = 0, p2 = 0, t = 0;
  double value = 0, log_value = 0, pdf = 0, hazard = 0;
  std::string more;  ///< further registry parameters "key=value;key=value" (gap-gamma, gamma-mixture)
};

std::vector<Row> load_rows() {
  std::vector<Row> rows;
  std::ifstream in(std::string(WEFT_TEST_DATA_DIR) + "/transmittance/reference.csv");
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#' || line.rfind("law,", 0) == 0) continue;
    std::stringstream fields(line);
    std::vector<std::string> cells;
    for (std::string cell; std::getline(fields, cell, ',');) cells.push_back(cell);
    // The `more` column is empty (and then dropped by getline) for two-parameter laws.
    EXPECT_TRUE(cells.size() == 8 || cells.size() == 9) << "reference.csv line " << number << ": " << line;
    if (cells.size() != 8 && cells.size() != 9) continue;
    Row row;
    row.line = number;
    row.law = cells[0];
    double* targets[] = {&row.p1, &row.p2, &row.t, &row.value, &row.log_value, &row.pdf, &row.hazard};
    for (int i = 0; i < 7; ++i) *targets[i] = std::strtod(cells[static_cast<std::size_t>(i) + 1].c_str(), nullptr);
    if (cells.size() == 9) row.more = cells[8];
    rows.push_back(row);
  }
  return rows;
}

const std::vector<Row>& rows() {
  static const std::vector<Row> all = load_rows();
  return all;
}

/// The new laws through the registry (their parameters by name): gap-gamma from p1 =
/// mean_extinction, p2 = alpha and more = "gap=…"; gamma-mixture from its numbered keys in more.
LawPtr make_from_registry(const Row& row) {
  LawSpec spec;
  spec.name = row.law;
  if (row.law == "gap-gamma") spec.params = {{"mean_extinction", row.p1}, {"alpha", row.p2}};
  std::stringstream items(row.more);
  for (std::string item; std::getline(items, item, ';');) {
    const auto eq = item.find('=');
    spec.params[item.substr(0, eq)] = std::strtod(item.substr(eq + 1).c_str(), nullptr);
  }
  return make_law(spec);
}

LawPtr make(const Row& row) {
  if (row.law == "gap-gamma" || row.law == "gamma-mixture") return make_from_registry(row);
  if (row.law == "gamma") return std::make_shared<GammaConcentration>(row.p1, row.p2);
  if (row.law == "gamma-path") return std::make_shared<GammaPath>(row.p1, row.p2);
  if (row.law == "erlang") return std::make_shared<Erlang>(row.p1, row.p2);
  if (row.law == "erlang-source") return std::make_shared<ErlangMixture>(row.p1, row.p2);
  if (row.law == "linear") return std::make_shared<Linear>(row.p1);
  if (row.law == "exponential") return std::make_shared<Exponential>(row.p1);
  return nullptr;
}

/// Within 1e−10 relative; values below the normal range compare absolutely (they carry no
/// relative precision in double).
::testing::AssertionResult close(const char* what, double got, double want) {
  if (std::isnan(got)) return ::testing::AssertionFailure() << what << " is NaN, want " << want;
  if (std::isinf(want) || std::isinf(got)) {
    if (got == want) return ::testing::AssertionSuccess();
    return ::testing::AssertionFailure() << what << " = " << got << ", want " << want;
  }
  const double tolerance = 1e-10 * std::fabs(want) + 1e-300;
  if (std::fabs(got - want) <= tolerance) return ::testing::AssertionSuccess();
  return ::testing::AssertionFailure() << fmt::format("{} = {:.17g}, want {:.17g} (relative error {:.3g})", what, got,
                                                      want, std::fabs(got - want) / std::fabs(want));
}

class ReferenceTable : public ::testing::TestWithParam<std::size_t> {};

TEST(ReferenceTable, IsPresentAndCoversEveryLaw) {
  std::map<std::string, int> count;
  for (const auto& row : rows()) ++count[row.law];
  EXPECT_GE(count["gamma"], 70);
  EXPECT_GE(count["gamma-path"], 60);
  EXPECT_GT(count["linear"], 0);
  EXPECT_GT(count["exponential"], 0);
  EXPECT_GT(count["erlang"], 0);
  EXPECT_GT(count["erlang-source"], 0);
  EXPECT_GE(count["gap-gamma"], 170);
  EXPECT_GE(count["gamma-mixture"], 45);
}

TEST_P(ReferenceTable, MatchesHighPrecisionReference) {
  const Row& row = rows()[GetParam()];
  SCOPED_TRACE(fmt::format("reference.csv line {}: {}({}, {}{}{}) at t = {}", row.line, row.law, row.p1, row.p2,
                           row.more.empty() ? "" : ", ", row.more, row.t));
  const LawPtr law = make(row);
  ASSERT_TRUE(law);
  const double value = law->transmittance(row.t);
  const double log_value = law->log_transmittance(row.t);
  const double pdf = law->pdf(row.t);
  const double hazard = law->hazard(row.t);
  EXPECT_TRUE(close("T", value, row.value));
  EXPECT_TRUE(close("log T", log_value, row.log_value));
  EXPECT_TRUE(close("p", pdf, row.pdf));
  EXPECT_TRUE(close("Sigma", hazard, row.hazard));
  EXPECT_GE(value, 0.0);
  EXPECT_LE(value, 1.0);
  EXPECT_LE(log_value, 0.0);
  EXPECT_GE(pdf, 0.0);
  EXPECT_GE(hazard, 0.0);
  EXPECT_EQ(std::isfinite(hazard), std::isfinite(row.hazard));
  EXPECT_EQ(std::isfinite(log_value), std::isfinite(row.log_value));
}

INSTANTIATE_TEST_SUITE_P(Rows, ReferenceTable, ::testing::Range<std::size_t>(0, rows().size()),
                         [](const ::testing::TestParamInfo<std::size_t>& info) {
                           std::string name = fmt::format("line{}_{}", rows()[info.param].line, rows()[info.param].law);
                           for (auto& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(ReferenceTable, EachLawIsMonotoneInT) {
  std::map<std::tuple<std::string, double, double, std::string>, std::vector<double>> ts;
  for (const auto& row : rows()) ts[{row.law, row.p1, row.p2, row.more}].push_back(row.t);
  for (auto& [key, list] : ts) {
    std::sort(list.begin(), list.end());
    Row probe;
    probe.law = std::get<0>(key);
    probe.p1 = std::get<1>(key);
    probe.p2 = std::get<2>(key);
    probe.more = std::get<3>(key);
    const LawPtr law = make(probe);
    for (std::size_t i = 1; i < list.size(); ++i) {
      EXPECT_LE(law->transmittance(list[i]), law->transmittance(list[i - 1]))
          << probe.law << "(" << probe.p1 << ", " << probe.p2 << ") between t = " << list[i - 1] << " and " << list[i];
      EXPECT_LE(law->log_transmittance(list[i]), law->log_transmittance(list[i - 1]))
          << probe.law << "(" << probe.p1 << ", " << probe.p2 << ") between t = " << list[i - 1] << " and " << list[i];
    }
  }
}

}  // namespace
}  // namespace weft::transmittance
