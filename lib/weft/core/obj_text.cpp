#include "weft/core/obj_text.h"

#include <charconv>
#include <cmath>
#include <system_error>

#include "weft/core/parse_number.h"

namespace weft {

bool ObjStatements::next(ObjStatement& s) {
  while (pos_ < text_.size()) {
    // One logical line: physical lines joined where one ends in a backslash.
    std::string joined;
    s.line = line_ + 1;
    for (bool more = true; more && pos_ < text_.size();) {
      const std::size_t end = std::min(text_.find('\n', pos_), text_.size());
      std::string_view physical = text_.substr(pos_, end - pos_);
      pos_ = end + 1;
      ++line_;
      if (physical.ends_with('\r')) physical.remove_suffix(1);
      more = physical.ends_with('\\');
      if (more) physical.remove_suffix(1);
      joined.append(physical);
      if (more) joined.push_back(' ');
    }
    if (const auto hash = joined.find('#'); hash != std::string::npos) joined.resize(hash);
    s.tag.clear();
    s.args.clear();
    constexpr std::string_view space = " \t\v\f";
    for (std::size_t at = joined.find_first_not_of(space); at != std::string::npos;) {
      const std::size_t stop = std::min(joined.find_first_of(space, at), joined.size());
      std::string word = joined.substr(at, stop - at);
      if (s.tag.empty()) {
        s.tag = std::move(word);
      } else {
        s.args.push_back(std::move(word));
      }
      at = joined.find_first_not_of(space, stop);
    }
    if (!s.tag.empty()) return true;
  }
  return false;
}

std::optional<double> obj_number(std::string_view token) {
  const auto v = parse_number(token);
  if (!v || !std::isfinite(*v)) return std::nullopt;
  return v;
}

std::optional<std::size_t> obj_vertex(std::string_view token, std::size_t defined, long long* index) {
  const std::string_view head = token.substr(0, token.find('/'));
  long long v = 0;
  const auto [end, ec] = std::from_chars(head.data(), head.data() + head.size(), v);
  if (ec != std::errc() || end != head.data() + head.size() || v == 0) return std::nullopt;
  if (index != nullptr) *index = v;
  const auto count = static_cast<long long>(defined);
  const long long i = v > 0 ? v - 1 : count + v;  // negative: counting back from the last vertex
  if (i < 0 || i >= count) return std::nullopt;
  return static_cast<std::size_t>(i);
}

}  // namespace weft
