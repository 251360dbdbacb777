#include "weft/core/file_kind.h"

#include <algorithm>
#include <fstream>

namespace weft {

namespace {

bool starts_with(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

std::string_view trim_left(std::string_view s) {
  const auto p = s.find_first_not_of(" \t\r\n");
  return p == std::string_view::npos ? std::string_view() : s.substr(p);
}

/// Text: no NUL and at most 1 in 20 bytes a control character other than tab/CR/LF (UTF-8
/// multi-byte characters have the high bit set and count as text).
bool is_text(std::string_view s) {
  std::size_t control = 0;
  for (const char ch : s) {
    const auto c = static_cast<unsigned char>(ch);
    if (c == 0) return false;
    if (c < 0x20 && c != '\t' && c != '\r' && c != '\n') ++control;
  }
  return control * 20 <= s.size();
}

}  // namespace

bool looks_like_text(std::string_view head) {
  const std::string kind = file_kind(head);
  return kind != "an empty file" && head.find('\0') == std::string_view::npos && is_text(head) &&
         kind.find("text") != std::string::npos;
}

std::string_view skip_utf8_bom(std::string_view text) {
  constexpr std::string_view bom = "\xEF\xBB\xBF";
  return text.starts_with(bom) ? text.substr(bom.size()) : text;
}

bool looks_like_json(std::string_view head) {
  const std::string_view t = trim_left(skip_utf8_bom(head));
  return !t.empty() && (t.front() == '{' || t.front() == '[');
}

std::string file_kind(std::string_view head) {
  if (head.empty()) return "an empty file";
  // Binary signatures (OpenVDB: int64 magic 0x56444220 little-endian, i.e. " BDV").
  if (starts_with(head, std::string_view(" BDV", 4))) return "an OpenVDB grid file";
  if (starts_with(head, "BCC")) return "a BCC curve file";
  if (starts_with(head, "\x89PNG")) return "a PNG image";
  if (starts_with(head, std::string_view("\x76\x2f\x31\x01", 4))) return "an OpenEXR image";
  if (starts_with(head, "\x1f\x8b")) return "a gzip archive";
  if (starts_with(head, std::string_view("PK\x03\x04", 4))) return "a zip archive";
  if (starts_with(head, "%PDF")) return "a PDF document";
  if (starts_with(head, "\xff\xd8\xff")) return "a JPEG image";
  if (starts_with(head, "ply\n") || starts_with(head, "ply\r")) return "a PLY mesh";
  if (!is_text(head)) return "a binary file";
  const std::string_view t = trim_left(head);
  if (t.empty()) return "a blank text file";
  if (t.front() == '{') return "a JSON text (an object)";
  if (t.front() == '[') return "a JSON text (an array)";
  if (starts_with(t, "<VTKFile") || (starts_with(t, "<?xml") && t.find("<VTKFile") != std::string_view::npos))
    return "a VTK XML file";
  if (t.front() == '<') return "an XML/HTML text";
  // Line-based texts: OBJ has "v x y z" lines; CSV a first line with commas.
  std::size_t pos = 0;
  while (pos < t.size()) {
    const std::size_t end = std::min(t.find('\n', pos), t.size());
    const std::string_view line = t.substr(pos, end - pos);
    if (starts_with(line, "v ") || starts_with(line, "l ") || starts_with(line, "f ")) return "a Wavefront OBJ text";
    if (!line.empty() && line.front() != '#') break;
    pos = end + 1;
  }
  const std::string_view first = t.substr(0, std::min(t.find('\n'), t.size()));
  if (first.find(',') != std::string_view::npos) return "a CSV text";
  return "a text file";
}

std::string file_kind_at(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "an unreadable file";
  char buffer[512];
  in.read(buffer, sizeof buffer);
  return file_kind(std::string_view(buffer, static_cast<std::size_t>(in.gcount())));
}

}  // namespace weft
