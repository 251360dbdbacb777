// Which models a validation computes (fit/model_selection.h).
#include "weft/fit/model_selection.h"

#include <array>
#include <sstream>

#include "weft/core/error.h"
#include "weft/fit/models.h"

namespace weft::fit {
namespace {

/// Report order; the bit of a model is its place here.
constexpr std::array<std::string_view, 10> kNames{"gamma",
                                                  "empirical",
                                                  "gap-gamma",
                                                  "across-beam",
                                                  "local-exponential",
                                                  "local-gamma",
                                                  "local-gamma-renewal",
                                                  "local-gamma-two-scale",
                                                  "isotropic",
                                                  "least-squares"};
constexpr std::uint32_t kAll = (1U << kNames.size()) - 1U;

constexpr std::uint32_t bit(std::string_view name) {
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    if (kNames[i] == name) return 1U << i;
  }
  return 0U;
}

constexpr std::uint32_t kWindows =
    bit("gamma") | bit("empirical") | bit("gap-gamma") | bit("across-beam") | bit("isotropic") | bit("least-squares");
constexpr std::uint32_t kBlocks =
    bit("local-exponential") | bit("local-gamma") | bit("local-gamma-renewal") | bit("local-gamma-two-scale");
constexpr std::uint32_t kAxisModels = kAll & ~(bit("isotropic") | bit("least-squares"));
static_assert(bit("local-gamma-two-scale") != 0U);

std::string known_names() {
  std::string out = "all, predicted";
  for (const auto name : kNames) out += fmt::format(", {}", name);
  return out + ", exponential";
}

}  // namespace

ModelSelection ModelSelection::all() {
  ModelSelection s;
  s.bits_ = kAll;
  return s;
}

ModelSelection ModelSelection::parse(const std::string& text) {
  if (text == "all") return all();
  // std::getline drops a trailing empty entry ("gamma,"): refused here like any other.
  if (!text.empty() && text.back() == ',') fail("models '{}': empty entry (names: {})", text, known_names());
  ModelSelection s;
  std::istringstream in(text);
  std::string part;
  std::uint32_t named_exponential = 0;
  while (std::getline(in, part, ',')) {
    if (part.empty()) fail("models '{}': empty entry (names: {})", text, known_names());
    std::uint32_t b = 0;
    if (part == "predicted") {
      b = bit(kPredictedModel);
    } else if (part == "exponential") {
      if (named_exponential != 0U) fail("models '{}': 'exponential' given twice", text);
      named_exponential = 1U;
      continue;  // the baseline: always computed
    } else if (part == "all") {
      fail("models '{}': 'all' goes alone", text);
    } else {
      b = bit(part);
      if (b == 0U) fail("models '{}': '{}' is not a model (names: {})", text, part, known_names());
    }
    if ((s.bits_ & b) != 0U) fail("models '{}': '{}' given twice", text, part);
    s.bits_ |= b;
  }
  if ((s.bits_ & ~bit("least-squares")) == 0U)
    fail("models '{}': no model to compare beside the exponential baseline and the least-squares reference", text);
  return s;
}

bool ModelSelection::wants(std::string_view name) const { return (bits_ & bit(name)) != 0U; }

ModelSelection ModelSelection::without(std::string_view name) const {
  ModelSelection s = *this;
  s.bits_ &= ~bit(name);
  return s;
}

bool ModelSelection::needs_windows() const { return (bits_ & kWindows) != 0U; }
bool ModelSelection::needs_blocks() const { return (bits_ & kBlocks) != 0U; }
bool ModelSelection::any_axis_model() const { return (bits_ & kAxisModels) != 0U; }

std::string ModelSelection::text() const {
  if (bits_ == kAll) return "all";
  std::string out;
  for (std::size_t i = 0; i < kNames.size(); ++i) {
    if ((bits_ & (1U << i)) != 0U) out += fmt::format("{}{}", out.empty() ? "" : ",", kNames[i]);
  }
  return out;
}

}  // namespace weft::fit
