#include "weft/volume/renderer_export.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <string_view>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <nanovdb/util/IO.h>
#include <nanovdb/util/OpenToNanoVDB.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/memory.h"
#include "weft/volume/dense.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace fs = std::filesystem;

void validate(const ExportMedium& medium, const ExportView& view) {
  require_positive("export: sigma", medium.sigma);
  // Mitsuba 3's and pbrt-v4's scale is a float: a larger σ would be written as a number their
  // parsers overflow to inf (or refuse), not as the medium asked for.
  if (medium.sigma > static_cast<double>(std::numeric_limits<float>::max()))
    fail("export: sigma {} is beyond a float ({:g}), which Mitsuba 3 and pbrt-v4 read the medium's scale as",
         medium.sigma, static_cast<double>(std::numeric_limits<float>::max()));
  // Below the smallest normal float the scale loses its digits, and below 1.4e-45 it reads as 0: a
  // vacuum written as a medium.
  if (medium.sigma < static_cast<double>(std::numeric_limits<float>::min()))
    fail(
        "export: sigma {} is below the smallest normal float ({:g}), which Mitsuba 3 and pbrt-v4 read the medium's "
        "scale as (it would lose its digits or read as 0)",
        medium.sigma, static_cast<double>(std::numeric_limits<float>::min()));
  for (const double a : medium.albedo) {
    if (!(a >= 0.0 && a <= 1.0)) fail("export: albedo must be in [0, 1], got {}", a);
  }
  if (!(std::abs(medium.g) < 1.0)) fail("export: g must be in (-1, 1), got {}", medium.g);
  if (view.width < 1 || view.height < 1 || view.width > 1 << 15 || view.height > 1 << 15)
    fail("export: image size must be 1..32768 pixels per side, got {}x{}", view.width, view.height);
  if (view.spp < 1) fail("export: spp must be >= 1, got {}", view.spp);
  if (view.max_depth < 1) fail("export: max_depth must be >= 1, got {}", view.max_depth);
  if (!(view.fov_deg > 0.0 && view.fov_deg < 180.0))
    fail("export: fov must be in (0, 180) degrees, got {}", view.fov_deg);
}

WorldBox world_box(const Grid& grid, const IndexBox& box) {
  if (box.empty()) fail("export: grid '{}' has no active voxels", grid.name());
  const auto o = grid.origin();
  const double h = grid.voxel_size();
  WorldBox w;
  for (int a = 0; a < 3; ++a) {
    w.min[a] = o[a] + h * box.min[a];
    w.max[a] = o[a] + h * (static_cast<double>(box.max[a]) + 1.0);
  }
  return w;
}

namespace {

// Shortest text that reads back as the same double.
std::string num(double x) { return fmt::format("{}", x); }

struct Camera {
  std::array<double, 3> eye{};
  std::array<double, 3> target{};
};

// Looks at the box centre along (0, −1, 1)/√2 (from the front, 45° above the cloth plane) from
// the distance at which the bounding sphere fills the vertical field of view.
Camera camera_for(const WorldBox& box, const ExportView& view) {
  Camera c;
  double radius = 0.0;
  for (int a = 0; a < 3; ++a) {
    c.target[a] = 0.5 * (box.min[a] + box.max[a]);
    radius += 0.25 * (box.max[a] - box.min[a]) * (box.max[a] - box.min[a]);
  }
  radius = std::sqrt(radius);
  const double distance = 1.1 * radius / std::sin(0.5 * view.fov_deg * std::numbers::pi / 180.0);
  c.eye = {c.target[0], c.target[1] - distance / std::sqrt(2.0), c.target[2] + distance / std::sqrt(2.0)};
  return c;
}

std::string triple(const std::array<double, 3>& v, const char* sep) {
  return num(v[0]) + sep + num(v[1]) + sep + num(v[2]);
}

// Length of the valid UTF-8 sequence at the start of `s` (RFC 3629: no overlong forms, no
// surrogates, nothing above U+10FFFF) and its code point; 0 when the first byte starts none.
std::pair<std::size_t, char32_t> utf8_sequence(std::string_view s) {
  const auto byte = [&](std::size_t i) { return static_cast<unsigned char>(s[i]); };
  const unsigned char b0 = byte(0);
  const std::size_t n = b0 < 0x80 ? 1 : (b0 >> 5) == 0x6 ? 2 : (b0 >> 4) == 0xE ? 3 : (b0 >> 3) == 0x1E ? 4 : 0;
  if (n == 0 || n > s.size()) return {0, 0};
  char32_t c = n == 1 ? b0 : b0 & (0x7Fu >> n);
  for (std::size_t i = 1; i < n; ++i) {
    if ((byte(i) & 0xC0) != 0x80) return {0, 0};
    c = (c << 6) | (byte(i) & 0x3Fu);
  }
  constexpr std::array<char32_t, 5> kLeast{0, 0, 0x80, 0x800, 0x10000};  // shortest form of each length
  if (c < kLeast.at(n) || (c >= 0xD800 && c <= 0xDFFF) || c > 0x10FFFF) return {0, 0};
  return {n, c};
}

// A unit from the grid's metadata inside a comment of either scene (both are UTF-8 text): valid
// UTF-8 is kept as it is ("µm"); written as '?' is what could end or break a comment: control
// characters (a newline ends a pbrt comment; NUL, C0, DEL, C1), a second '-' in a row ("--" is
// not allowed in an XML comment, so neither is "-->"), '&', '<', '>', the non-characters
// U+FFFE/U+FFFF that XML refuses, and each byte that starts no valid UTF-8 sequence.
std::string comment_text(std::string_view s) {
  std::string out;
  while (!s.empty()) {
    const auto [n, c] = utf8_sequence(s);
    const bool control = c < 0x20 || (c >= 0x7F && c <= 0x9F);
    const bool breaks = control || c == 0xFFFE || c == 0xFFFF ||
                        std::u32string_view(U"&<>").find(c) != std::u32string_view::npos ||
                        (c == '-' && !out.empty() && out.back() == '-');
    if (n == 0 || breaks)
      out += '?';
    else
      out.append(s.substr(0, n));
    s.remove_prefix(std::max<std::size_t>(n, 1));
  }
  return out;
}

// The recorded unit without surrounding blanks: a blank one is no unit ("" → "no units recorded").
std::string_view trimmed_unit(std::string_view u) {
  const auto blank = [](char ch) { return std::string_view(" \t\n\r\v\f").find(ch) != std::string_view::npos; };
  while (!u.empty() && blank(u.front())) u.remove_prefix(1);
  while (!u.empty() && blank(u.back())) u.remove_suffix(1);
  return u;
}

// XML attribute text: the file names are the only free text in the scenes.
std::string xml_escape(const std::string& s) {
  std::string out;
  for (const char ch : s) {
    switch (ch) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += ch;
    }
  }
  return out;
}

void append_bytes(std::vector<char>& out, const void* p, std::size_t n) {
  const auto* c = static_cast<const char*>(p);
  out.insert(out.end(), c, c + n);
}

}  // namespace

namespace {

// Distance from |x| to the next float above it: 2^(e − 23) for 2^e <= |x| < 2^(e + 1).
double float_spacing(double x) {
  const double a = std::abs(x);
  if (a < static_cast<double>(std::numeric_limits<float>::min()))
    return static_cast<double>(std::numeric_limits<float>::denorm_min());
  return std::ldexp(1.0, std::ilogb(a) - (std::numeric_limits<float>::digits - 1));
}

}  // namespace

void check_float_resolution(const Grid& grid, const IndexBox& box, ExportFormat format, const std::string& grid_label) {
  const WorldBox w = world_box(grid, box);
  const bool pbrt = format == ExportFormat::pbrt;
  // The largest magnitude of each kind of coordinate decides: the spacing grows with it.
  double world = 0.0;
  double index = 0.0;
  for (int a = 0; a < 3; ++a) {
    world = std::max({world, std::abs(w.min[a]), std::abs(w.max[a])});
    // pbrt-v4: the grid's own indices, voxel faces at ±0.5 around its centres (worldToIndexF);
    // Mitsuba 3: the box-relative index, 0 .. extent (the gridvolume's unit cube × resolution).
    index = pbrt ? std::max({index, std::abs(box.min[a] - 0.5), std::abs(box.max[a] + 0.5)})
                 : std::max(index, static_cast<double>(box.extent()[a]));
  }
  const auto refuse_beyond = [&](double x, double voxel, const char* what, const char* remedy) {
    const double spacing = float_spacing(x);
    if (spacing <= kFloatVoxelShare * voxel) return;
    fail(
        "{}: {} holds {} in single precision, whose spacing at {:g} is {:.3g} voxels (at most 1/{:g} keeps each "
        "voxel's width within {:.1f} %), so its index box ({}, {}, {})..({}, {}, {}) cannot be exported; {}",
        grid_label, pbrt ? "pbrt-v4" : "Mitsuba 3", what, x, spacing / voxel, 1.0 / kFloatVoxelShare,
        100.0 * kFloatVoxelShare, box.min[0], box.min[1], box.min[2], box.max[0], box.max[1], box.max[2], remedy);
  };
  refuse_beyond(world, grid.voxel_size(), "world coordinates",
                "place the grid nearer the world origin (its transform's translation)");
  refuse_beyond(
      index, 1.0, pbrt ? "the grid's index coordinates" : "voxel coordinates across the box",
      pbrt ? "shift its indices nearer 0 (and its origin by as much, for the same world)" : "export a smaller box");
}

void check_mitsuba_vol(const IndexBox& box, const fs::path& path, std::uint64_t max_bytes) {
  const std::uint64_t bytes = dense_bytes(box);
  if (bytes > max_bytes) {
    const auto [need, limit] = format_bytes_apart(bytes, max_bytes);
    fail("{}: the dense volume of {} voxels would take {}, over the limit of {}", path.string(), bytes / sizeof(float),
         need, limit);
  }
  for (const auto n : box.extent()) {
    if (n > std::numeric_limits<std::int32_t>::max())
      fail("{}: {} voxels along an axis exceed the format's int32 resolution", path.string(), n);
  }
}

MitsubaVolume mitsuba_volume(const Grid& grid, const IndexBox& box, const fs::path& path, std::uint64_t max_bytes,
                             ProgressSink& progress) {
  const WorldBox w = world_box(grid, box);
  check_mitsuba_vol(box, path, max_bytes);
  const auto e = box.extent();
  static_assert(std::endian::native == std::endian::little, "the .vol format is little endian");
  // Header (Mitsuba 3 gridvolume docs): "VOL", version 3, encoding 1 (float32), resolution
  // x, y, z, channel count, bounding box (float32 xmin, ymin, zmin, xmax, ymax, zmax).
  MitsubaVolume vol;
  append_bytes(vol.header, "VOL", 3);
  vol.header.push_back(3);
  const std::int32_t ints[5] = {1, static_cast<std::int32_t>(e[0]), static_cast<std::int32_t>(e[1]),
                                static_cast<std::int32_t>(e[2]), 1};
  append_bytes(vol.header, ints, sizeof ints);
  const float bbox[6] = {static_cast<float>(w.min[0]), static_cast<float>(w.min[1]), static_cast<float>(w.min[2]),
                         static_cast<float>(w.max[0]), static_cast<float>(w.max[1]), static_cast<float>(w.max[2])};
  append_bytes(vol.header, bbox, sizeof bbox);
  vol.values.resize(dense_bytes(box) / sizeof(float));
  // data[((z·yres + y)·xres + x)]: x fastest.
  copy_to_dense(grid, box, vol.values.data(), DenseLayout::z_major, progress);
  return vol;
}

void write_mitsuba_vol(const MitsubaVolume& volume, const fs::path& path) {
  // The checked stream of every writer: a short write says why ("File too large").
  write_stream_atomically(path, [&](std::ostream& f) {
    f.write(volume.header.data(), static_cast<std::streamsize>(volume.header.size()));
    f.write(reinterpret_cast<const char*>(volume.values.data()),
            static_cast<std::streamsize>(volume.values.size() * sizeof(float)));
  });
}

void write_mitsuba_vol(const Grid& grid, const IndexBox& box, const fs::path& path, std::uint64_t max_bytes) {
  write_mitsuba_vol(mitsuba_volume(grid, box, path, max_bytes), path);
}

std::string medium_description(const ExportMedium& medium) {
  const std::string_view recorded = trimmed_unit(medium.units);
  const std::string unit = recorded.empty() ? "length" : comment_text(recorded);
  const std::string lengths = recorded.empty() ? "lengths in the grid's own units (no units recorded)"
                                               : fmt::format("lengths in {} (the grid's units)", unit);
  if (medium.extinction)
    return fmt::format("sigma_t = scale x grid value, the values are extinction in 1/{}, scale = {}; {}", unit,
                       num(medium.sigma), lengths);
  return fmt::format(
      "sigma_t = scale x grid value, the values are concentration (fibre volume fraction), scale = sigma = {} "
      "per unit concentration in 1/{}; {}",
      num(medium.sigma), unit, lengths);
}

std::string pbrt_interpolation_note() {
  return "pbrt-v4 interpolates the density trilinearly, where weft and the Mitsuba export hold each voxel "
         "constant: fibres under 2 voxels wide are smeared (docs/export.md)";
}

std::string mitsuba_scene_xml(const WorldBox& box, const std::string& vol_file, const ExportMedium& medium,
                              const ExportView& view) {
  validate(medium, view);
  const Camera cam = camera_for(box, view);
  std::array<double, 3> size{};
  std::array<double, 3> centre{};
  for (int a = 0; a < 3; ++a) {
    size[a] = box.max[a] - box.min[a];
    centre[a] = 0.5 * (box.min[a] + box.max[a]);
  }
  const std::array<double, 3> half{0.5 * size[0], 0.5 * size[1], 0.5 * size[2]};
  // Mitsuba composes <transform> children in order (each applied after the previous): the
  // gridvolume maps its unit cube [0,1]^3 onto the box, the cube shape [-1,1]^3 likewise.
  std::string x;
  x += "<?xml version=\"1.0\" encoding=\"utf-8\"?>\n";
  x += fmt::format(
      "<!-- weft export: cloth grid as a heterogeneous medium, gridvolume with nearest filtering (piecewise "
      "constant voxels, as weft renders them); {} -->\n",
      medium_description(medium));
  x += "<scene version=\"3.0.0\">\n";
  x += fmt::format(
      "    <integrator type=\"volpath\">\n        <integer name=\"max_depth\" value=\"{}\"/>\n"
      "    </integrator>\n",
      view.max_depth);
  x += "    <sensor type=\"perspective\">\n";
  x += fmt::format("        <float name=\"fov\" value=\"{}\"/>\n        <string name=\"fov_axis\" value=\"y\"/>\n",
                   num(view.fov_deg));
  x += fmt::format(
      "        <transform name=\"to_world\">\n            <lookat origin=\"{}\" target=\"{}\" "
      "up=\"0, 0, 1\"/>\n        </transform>\n",
      triple(cam.eye, ", "), triple(cam.target, ", "));
  x += fmt::format(
      "        <sampler type=\"independent\">\n            <integer name=\"sample_count\" value=\"{}\"/>\n"
      "        </sampler>\n",
      view.spp);
  x += fmt::format(
      "        <film type=\"hdrfilm\">\n            <integer name=\"width\" value=\"{}\"/>\n"
      "            <integer name=\"height\" value=\"{}\"/>\n        </film>\n",
      view.width, view.height);
  x += "    </sensor>\n";
  x += "    <emitter type=\"constant\">\n        <rgb name=\"radiance\" value=\"1, 1, 1\"/>\n    </emitter>\n";
  x += "    <medium type=\"heterogeneous\" id=\"cloth\">\n";
  x += "        <volume type=\"gridvolume\" name=\"sigma_t\">\n";
  x += fmt::format("            <string name=\"filename\" value=\"{}\"/>\n", xml_escape(vol_file));
  x += "            <string name=\"filter_type\" value=\"nearest\"/>\n";
  x += fmt::format(
      "            <transform name=\"to_world\">\n                <scale x=\"{}\" y=\"{}\" z=\"{}\"/>\n"
      "                <translate x=\"{}\" y=\"{}\" z=\"{}\"/>\n            </transform>\n",
      num(size[0]), num(size[1]), num(size[2]), num(box.min[0]), num(box.min[1]), num(box.min[2]));
  x += "        </volume>\n";
  x += fmt::format("        <rgb name=\"albedo\" value=\"{}\"/>\n", triple(medium.albedo, ", "));
  x += fmt::format("        <float name=\"scale\" value=\"{}\"/>\n", num(medium.sigma));
  x += fmt::format("        <phase type=\"hg\">\n            <float name=\"g\" value=\"{}\"/>\n        </phase>\n",
                   num(medium.g));
  x += "    </medium>\n";
  x += "    <shape type=\"cube\">\n";
  x += fmt::format(
      "        <transform name=\"to_world\">\n            <scale x=\"{}\" y=\"{}\" z=\"{}\"/>\n"
      "            <translate x=\"{}\" y=\"{}\" z=\"{}\"/>\n        </transform>\n",
      num(half[0]), num(half[1]), num(half[2]), num(centre[0]), num(centre[1]), num(centre[2]));
  x += "        <bsdf type=\"null\"/>\n        <ref name=\"interior\" id=\"cloth\"/>\n";
  x += "    </shape>\n";
  x += "</scene>\n";
  return x;
}

struct NanoVdbGrid::Impl {
  fs::path path;
  nanovdb::GridHandle<> handle;
};

NanoVdbGrid::NanoVdbGrid(const Grid& grid, const fs::path& path, ProgressSink& progress)
    : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  ProgressTask task(progress, "NanoVDB conversion", 2);
  openvdb::FloatGrid::Ptr copy = deep_copy(grid);
  copy->setName("density");  // the grid pbrt-v4's nanovdb medium looks up
  task.step();
  impl_->handle = nanovdb::openToNanoVDB(*copy);
  if (!impl_->handle || impl_->handle.grid<float>() == nullptr) fail("{}: NanoVDB conversion failed", path.string());
  task.step();
}

NanoVdbGrid::~NanoVdbGrid() = default;
NanoVdbGrid::NanoVdbGrid(NanoVdbGrid&&) noexcept = default;
NanoVdbGrid& NanoVdbGrid::operator=(NanoVdbGrid&&) noexcept = default;

void NanoVdbGrid::write() const {
  write_atomically(impl_->path, [&](const fs::path& tmp) {
    try {
      nanovdb::io::writeGrid(tmp.string(), impl_->handle, nanovdb::io::Codec::NONE);
    } catch (const std::exception& e) {
      fail("{}: {}", impl_->path.string(), e.what());
    }
  });
}

void write_nanovdb(const Grid& grid, const fs::path& path) { NanoVdbGrid(grid, path).write(); }

std::string pbrt_scene(const WorldBox& box, const std::string& nvdb_file, const ExportMedium& medium,
                       const ExportView& view) {
  validate(medium, view);
  const Camera cam = camera_for(box, view);
  std::array<double, 3> sigma_a{};
  std::array<double, 3> sigma_s{};
  for (int c = 0; c < 3; ++c) {
    sigma_s[c] = medium.albedo[c];
    sigma_a[c] = 1.0 - medium.albedo[c];
  }
  std::string quoted;
  for (const char ch : nvdb_file) {
    if (ch == '"' || ch == '\n') fail("export: file name '{}' cannot be quoted in a pbrt scene", nvdb_file);
    quoted += ch;
  }
  const auto& lo = box.min;
  const auto& hi = box.max;
  std::string s;
  s += fmt::format("# weft export: cloth grid as a pbrt-v4 nanovdb medium; {}.\n", medium_description(medium));
  s += fmt::format("# Not weft's medium: {}.\n", pbrt_interpolation_note());
  s += fmt::format("LookAt {}  {}  0 0 1\n", triple(cam.eye, " "), triple(cam.target, " "));
  s += fmt::format("Camera \"perspective\" \"float fov\" [ {} ]\n", num(view.fov_deg));
  s += fmt::format(
      "Film \"rgb\" \"integer xresolution\" [ {} ] \"integer yresolution\" [ {} ] "
      "\"string filename\" [ \"cloth.exr\" ]\n",
      view.width, view.height);
  s += fmt::format("Sampler \"zsobol\" \"integer pixelsamples\" [ {} ]\n", view.spp);
  s += fmt::format("Integrator \"volpath\" \"integer maxdepth\" [ {} ]\n", view.max_depth);
  s += "WorldBegin\n";
  s += "LightSource \"infinite\" \"rgb L\" [ 1 1 1 ]\n";
  // Declared under the identity transform: the grid's own index-to-world map places it.
  s += fmt::format(
      "MakeNamedMedium \"cloth\" \"string type\" [ \"nanovdb\" ] \"string filename\" [ \"{}\" ]\n"
      "    \"rgb sigma_a\" [ {} ] \"rgb sigma_s\" [ {} ] \"float scale\" [ {} ] \"float g\" [ {} ]\n",
      quoted, triple(sigma_a, " "), triple(sigma_s, " "), num(medium.sigma), num(medium.g));
  s += "AttributeBegin\n";
  s += "    MediumInterface \"cloth\" \"\"\n";
  s += "    Material \"interface\"\n";
  // The box as 12 outward-facing triangles.
  s += fmt::format(
      "    Shape \"trianglemesh\"\n        \"point3 P\" [ {0} {1} {2}  {3} {1} {2}  {3} {4} {2}  {0} {4} {2}  "
      "{0} {1} {5}  {3} {1} {5}  {3} {4} {5}  {0} {4} {5} ]\n",
      num(lo[0]), num(lo[1]), num(lo[2]), num(hi[0]), num(hi[1]), num(hi[2]));
  s += "        \"integer indices\" [ 0 2 1  0 3 2  4 5 6  4 6 7  0 1 5  0 5 4  1 2 6  1 6 5  2 3 7  2 7 6  "
       "3 0 4  3 4 7 ]\n";
  s += "AttributeEnd\n";
  return s;
}

}  // namespace weft::volume
