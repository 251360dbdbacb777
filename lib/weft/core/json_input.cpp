#include "weft/core/json_input.h"

#include <algorithm>
#include <set>
#include <vector>

#include "weft/core/error.h"
#include "weft/core/file_kind.h"

namespace weft {

TextPosition position_of(std::string_view text, std::size_t offset) {
  TextPosition pos;
  offset = std::min(offset, text.size());
  for (std::size_t i = 0; i < offset; ++i) {
    if (text[i] == '\n') {
      ++pos.line;
      pos.column = 1;
    } else {
      ++pos.column;
    }
  }
  return pos;
}

nlohmann::json parse_json_input(std::string_view text, const std::string& source) {
  using nlohmann::json;
  text = skip_utf8_bom(text);
  // The open containers: an object's keys so far and where it is ("camera", "media.m",
  // "shapes[]": array elements are not numbered, the parser does not count them).
  struct Open {
    bool object = false;
    std::string path;
    std::set<std::string> keys;
  };
  std::vector<Open> open;
  std::string last_key;
  const auto child_path = [&] {
    if (open.empty()) return std::string();
    const Open& parent = open.back();
    if (!parent.object) return parent.path + "[]";
    return parent.path.empty() ? last_key : parent.path + "." + last_key;
  };
  const json::parser_callback_t check = [&](int /*depth*/, json::parse_event_t event, json& parsed) {
    switch (event) {
      case json::parse_event_t::object_start:
        open.push_back({true, child_path(), {}});
        break;
      case json::parse_event_t::array_start:
        open.push_back({false, child_path(), {}});
        break;
      case json::parse_event_t::object_end:
      case json::parse_event_t::array_end:
        if (!open.empty()) open.pop_back();
        break;
      case json::parse_event_t::key:
        last_key = parsed.get<std::string>();
        if (!open.empty() && !open.back().keys.insert(last_key).second)
          fail("{}: key '{}' appears twice in {}", source, last_key,
               open.back().path.empty() ? std::string("the top-level object") : "'" + open.back().path + "'");
        break;
      case json::parse_event_t::value:
        break;
    }
    return true;
  };
  try {
    return json::parse(text.begin(), text.end(), check);
  } catch (const json::parse_error& e) {
    // nlohmann reports the byte just past the offending token; users want line and column.
    const std::size_t offset = e.byte == 0 ? 0 : e.byte - 1;
    const TextPosition pos = position_of(text, offset);
    std::string what = e.what();
    const auto colon = what.rfind(": ");
    if (colon != std::string::npos) what = what.substr(colon + 2);
    // Python's json.dump writes NaN and Infinity, which JSON (RFC 8259 §6) has no literal for:
    // said as such, not as nlohmann's "last read: 'N'".
    const std::string_view rest = text.substr(std::min(offset, text.size()));
    for (const std::string_view word : {"NaN", "Infinity", "nan", "inf", "Inf"}) {
      if (rest.starts_with(word)) {
        fail("{}:{}:{}: invalid JSON: {}{} is not a JSON number (JSON has no NaN or Infinity): give a finite number",
             source, pos.line, pos.column, offset > 0 && text[offset - 1] == '-' ? "-" : "", word);
      }
    }
    fail("{}:{}:{}: invalid JSON: {}", source, pos.line, pos.column, what);
  } catch (const json::out_of_range& e) {
    // A number beyond double range (1e999): nlohmann throws out_of_range, not parse_error.
    fail("{}: invalid JSON: {}", source, e.what());
  }
}

}  // namespace weft
