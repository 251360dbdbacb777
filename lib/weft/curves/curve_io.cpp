#include "weft/curves/curve_io.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <sstream>

#include <fmt/format.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/file_kind.h"
#include "weft/core/obj_text.h"
#include "weft/core/paths.h"

namespace weft::curves {
namespace fs = std::filesystem;

namespace {

constexpr std::size_t kBccHeaderBytes = 64;

std::uint64_t read_u64(const unsigned char* p) {
  std::uint64_t v = 0;
  for (int i = 7; i >= 0; --i) v = (v << 8U) | p[i];
  return v;
}
std::int32_t read_i32(const unsigned char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8U) | p[i];
  return std::bit_cast<std::int32_t>(v);
}
float read_f32(const unsigned char* p) {
  std::uint32_t v = 0;
  for (int i = 3; i >= 0; --i) v = (v << 8U) | p[i];
  return std::bit_cast<float>(v);
}
void put_u64(std::string& out, std::uint64_t v) {
  for (int i = 0; i < 8; ++i) out.push_back(static_cast<char>((v >> (8U * static_cast<unsigned>(i))) & 0xFFU));
}
void put_u32(std::string& out, std::uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<char>((v >> (8U * static_cast<unsigned>(i))) & 0xFFU));
}

std::string read_whole(const fs::path& path, std::uintmax_t expected) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("{}: cannot open", path.string());
  std::string bytes(static_cast<std::size_t>(expected), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(expected));
  if (static_cast<std::uintmax_t>(in.gcount()) != expected) fail("{}: short read", path.string());
  return bytes;
}

std::uintmax_t existing_file_size(const fs::path& path) {
  std::error_code ec;
  if (!fs::exists(path, ec)) fail("{}: no such file", path.string());
  if (!fs::is_regular_file(path, ec)) fail("{}: not a regular file", path.string());
  const auto size = fs::file_size(path, ec);
  if (ec) fail("{}: cannot read size: {}", path.string(), ec.message());
  return size;
}

// Uniform Catmull–Rom between P1 and P2 at t ∈ [0, 1].
Point3 catmull_rom(const Point3& p0, const Point3& p1, const Point3& p2, const Point3& p3, double t) {
  Point3 r{};
  const double t2 = t * t;
  const double t3 = t2 * t;
  for (int a = 0; a < 3; ++a) {
    r[a] = 0.5 * (2.0 * p1[a] + (-p0[a] + p2[a]) * t + (2.0 * p0[a] - 5.0 * p1[a] + 4.0 * p2[a] - p3[a]) * t2 +
                  (-p0[a] + 3.0 * p1[a] - 3.0 * p2[a] + p3[a]) * t3);
  }
  return r;
}

Curve catmull_rom_polyline(const Curve& control, int subdivisions) {
  const auto& c = control.points;
  const auto n = static_cast<long>(c.size());
  if (n < 2) return control;
  const auto at = [&](long i) -> Point3 {
    if (control.closed) return c[static_cast<std::size_t>(((i % n) + n) % n)];
    if (i < 0) return {2 * c[0][0] - c[1][0], 2 * c[0][1] - c[1][1], 2 * c[0][2] - c[1][2]};
    if (i >= n) {
      const auto& a = c[static_cast<std::size_t>(n - 1)];
      const auto& b = c[static_cast<std::size_t>(n - 2)];
      return {2 * a[0] - b[0], 2 * a[1] - b[1], 2 * a[2] - b[2]};
    }
    return c[static_cast<std::size_t>(i)];
  };
  Curve out;
  out.closed = control.closed;
  const long spans = control.closed ? n : n - 1;
  for (long s = 0; s < spans; ++s) {
    for (int k = 0; k < subdivisions; ++k) {
      out.points.push_back(catmull_rom(at(s - 1), at(s), at(s + 1), at(s + 2), static_cast<double>(k) / subdivisions));
    }
  }
  if (!control.closed) out.points.push_back(c.back());
  return out;
}

}  // namespace

std::vector<Curve> parse_bcc(std::string_view data, const std::string& where, int catmull_rom_subdivisions) {
  const std::uintmax_t size = data.size();
  if (size < kBccHeaderBytes) fail("{}: truncated BCC file ({} bytes, the header alone is 64)", where, size);
  const auto* h = reinterpret_cast<const unsigned char*>(data.data());
  if (std::memcmp(h, "BCC", 3) != 0)
    fail("{}: not a BCC file (signature is not 'BCC'; looks like {})", where, file_kind(data.substr(0, 512)));
  if (h[3] != 0x44)
    fail("{}: unsupported BCC element sizes 0x{:02x} (only 0x44: 4-byte integers and floats)", where, h[3]);
  const std::string type(reinterpret_cast<const char*>(h + 4), 2);
  if (type != "PL" && type != "C0") {
    fail("{}: unsupported BCC curve type '{}' (supported: 'PL' polyline, 'C0' Catmull-Rom)", where, type);
  }
  if (h[6] != 3) fail("{}: BCC curves have {} dimensions, weft needs 3", where, static_cast<int>(h[6]));
  const std::uint64_t curve_count = read_u64(h + 8);
  const std::uint64_t point_count = read_u64(h + 16);
  const std::uintmax_t body = size - kBccHeaderBytes;
  // The declared counts must account for every byte before anything is reserved, so a hostile
  // header cannot ask for a huge allocation.
  if (curve_count > body / 4 || point_count > body / 12 || curve_count * 4 + point_count * 12 != body) {
    // The bytes they take: a 4-byte count per curve and 12 bytes per point, in 64 bits or more.
    std::uint64_t counts = 0;
    std::uint64_t points = 0;
    std::uint64_t implied = 0;
    const bool overflow = __builtin_mul_overflow(curve_count, std::uint64_t{4}, &counts) ||
                          __builtin_mul_overflow(point_count, std::uint64_t{12}, &points) ||
                          __builtin_add_overflow(counts, points, &implied);
    fail(
        "{}: BCC header declares {} curves and {} points, which take {} bytes after the 64-byte header, but the file "
        "has {}",
        where, curve_count, point_count, overflow ? "more than 18446744073709551615" : std::to_string(implied), body);
  }
  const auto* p = h + kBccHeaderBytes;
  const auto* end = h + size;
  std::vector<Curve> curves;
  curves.reserve(static_cast<std::size_t>(curve_count));
  std::uint64_t points_seen = 0;
  for (std::uint64_t c = 0; c < curve_count; ++c) {
    if (end - p < 4) fail("{}: truncated at curve {}", where, c);
    const std::int32_t signed_n = read_i32(p);
    p += 4;
    if (signed_n == std::numeric_limits<std::int32_t>::min()) fail("{}: curve {} has an invalid point count", where, c);
    const auto n = static_cast<std::uint64_t>(signed_n < 0 ? -signed_n : signed_n);
    if (points_seen + n > point_count || static_cast<std::uint64_t>(end - p) < n * 12) {
      fail("{}: curve {} declares {} points, more than the header's total {} allows", where, c, n, point_count);
    }
    Curve curve;
    curve.closed = signed_n < 0;
    curve.points.reserve(static_cast<std::size_t>(n));
    for (std::uint64_t i = 0; i < n; ++i, p += 12) {
      Point3 q{read_f32(p), read_f32(p + 4), read_f32(p + 8)};
      if (!std::isfinite(q[0]) || !std::isfinite(q[1]) || !std::isfinite(q[2])) {
        fail("{}: curve {} point {} is not finite", where, c, i);
      }
      curve.points.push_back(q);
    }
    points_seen += n;
    curves.push_back(type == "C0" ? catmull_rom_polyline(curve, std::max(1, catmull_rom_subdivisions))
                                  : std::move(curve));
  }
  if (points_seen != point_count)
    fail("{}: curves hold {} points but the header says {}", where, points_seen, point_count);
  return curves;
}

std::vector<Curve> read_bcc(const fs::path& path, int catmull_rom_subdivisions) {
  const std::uintmax_t size = existing_file_size(path);
  return parse_bcc(read_whole(path, size), path.string(), catmull_rom_subdivisions);
}

std::string bcc_bytes(const std::vector<Curve>& curves, const std::string& info) {
  std::uint64_t points = 0;
  for (const auto& c : curves) {
    if (c.points.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max())) {
      fail("BCC output: a curve of {} points does not fit a BCC int32 count", c.points.size());
    }
    points += c.points.size();
  }
  std::string out;
  out.reserve(kBccHeaderBytes + curves.size() * 4 + points * 12);
  out += "BCC";
  out.push_back(static_cast<char>(0x44));
  out += "PL";
  out.push_back(3);  // dimensions
  out.push_back(2);  // up dimension: z
  put_u64(out, curves.size());
  put_u64(out, points);
  std::string text = info.substr(0, 39);
  text.resize(40, '\0');
  out += text;
  for (const auto& c : curves) {
    const auto n = static_cast<std::int32_t>(c.points.size());
    put_u32(out, std::bit_cast<std::uint32_t>(c.closed ? -n : n));
    for (const auto& q : c.points) {
      for (double v : q) put_u32(out, std::bit_cast<std::uint32_t>(static_cast<float>(v)));
    }
  }
  return out;
}

void write_bcc(const fs::path& path, const std::vector<Curve>& curves, const std::string& info) {
  write_text_atomically(path, bcc_bytes(curves, info));
}

std::vector<Curve> read_obj_curves(const fs::path& path) {
  const std::string where = path.string();
  const std::uintmax_t size = existing_file_size(path);
  const std::string text = read_whole(path, size);
  const std::string_view head = std::string_view(text).substr(0, 512);
  if (!head.empty() && !looks_like_text(head)) fail("{}: not an OBJ text (looks like {})", where, file_kind(head));
  std::vector<Point3> vertices;
  std::vector<Curve> curves;
  long last_end = -1;  // vertex index where the previous polyline ended, for chaining
  ObjStatements statements(text);
  ObjStatement s;
  const auto parse_double = [&](const std::string& token) {
    const auto v = obj_number(token);
    if (!v) fail("{}:{}: '{}' is not a finite number", where, s.line, token);
    return *v;
  };
  while (statements.next(s)) {
    const auto& tokens = s.args;
    const std::size_t number = s.line;
    if (s.tag == "v") {
      if (tokens.size() < 3) fail("{}:{}: a vertex needs 3 coordinates, got {}", where, number, tokens.size());
      vertices.push_back({parse_double(tokens[0]), parse_double(tokens[1]), parse_double(tokens[2])});
    } else if (s.tag == "l") {
      if (tokens.size() < 2) fail("{}:{}: a polyline needs at least 2 vertices", where, number);
      std::vector<long> idx;
      for (const auto& t : tokens) {
        long long spelled = 0;
        const auto i = obj_vertex(t, vertices.size(), &spelled);
        if (!i && spelled == 0) fail("{}:{}: '{}' is not a vertex index", where, number, t);
        if (!i) {
          fail("{}:{}: vertex index {} out of range (1..{} defined so far)", where, number, spelled, vertices.size());
        }
        idx.push_back(static_cast<long>(*i));
      }
      std::size_t first = 0;
      if (idx.size() == 2 && idx[0] == last_end && !curves.empty()) {
        first = 1;  // continues the previous polyline
      } else {
        curves.emplace_back();
      }
      for (std::size_t k = first; k < idx.size(); ++k)
        curves.back().points.push_back(vertices[static_cast<std::size_t>(idx[k])]);
      last_end = idx.back();
    }
  }
  if (curves.empty()) fail("{}: no polylines ('l' elements) in the OBJ file", where);
  for (auto& c : curves) {
    if (c.points.size() > 2 && c.points.front() == c.points.back()) {
      c.points.pop_back();
      c.closed = true;
    }
  }
  return curves;
}

void write_obj_curves(const fs::path& path, const std::vector<Curve>& curves) {
  std::string out = "# yarn curves written by weft (units: mm)\n";
  for (const auto& c : curves) {
    for (const auto& q : c.points) out += fmt::format("v {} {} {}\n", q[0], q[1], q[2]);
  }
  std::uint64_t base = 1;
  for (const auto& c : curves) {
    if (c.points.size() < 2) {
      base += c.points.size();
      continue;
    }
    out += "l";
    for (std::size_t i = 0; i < c.points.size(); ++i) out += fmt::format(" {}", base + i);
    if (c.closed) out += fmt::format(" {}", base);
    out += "\n";
    base += c.points.size();
  }
  write_text_atomically(path, out);
}

std::vector<Curve> read_curves(const fs::path& path) {
  const std::string ext = lower_extension(path);
  if (ext == ".bcc") return read_bcc(path);
  if (ext == ".obj") return read_obj_curves(path);
  fail("{}: unknown curve file type '{}' (expected .bcc or .obj)", path.string(), ext);
}

}  // namespace weft::curves
