#include "weft/render/mesh.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>
#include <string>

#include <vtkCallbackCommand.h>
#include <vtkCellArray.h>
#include <vtkCommand.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkPLYReader.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkTriangleFilter.h>

#include "weft/core/error.h"
#include "weft/core/obj_text.h"
#include "weft/core/paths.h"

namespace weft::render {

TriangleMesh load_obj(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("mesh file '{}' cannot be opened (missing or unreadable)", path.string());
  std::ostringstream text;
  text << in.rdbuf();
  const std::string all = text.str();
  TriangleMesh mesh;
  ObjStatements statements(all);
  ObjStatement s;
  auto bad = [&](const std::string& why) { fail("mesh file '{}', line {}: {}", path.string(), s.line, why); };
  while (statements.next(s)) {
    if (s.tag == "v") {
      if (s.args.size() < 3) bad("a vertex needs 3 coordinates");
      Vec3 v;
      for (int k = 0; k < 3; ++k) {
        const std::string& w = s.args[static_cast<std::size_t>(k)];
        const auto x = obj_number(w);
        if (!x) bad("bad coordinate '" + w + "'");
        v[k] = *x;
      }
      mesh.vertices.push_back(v);
    } else if (s.tag == "f") {
      std::vector<std::uint32_t> face;
      for (const std::string& w : s.args) {
        long long spelled = 0;
        const auto index = obj_vertex(w, mesh.vertices.size(), &spelled);
        if (!index && spelled == 0) bad("bad face index '" + w + "'");
        if (!index) bad("face index " + w + " out of range");
        face.push_back(static_cast<std::uint32_t>(*index));
      }
      if (face.size() < 3) bad("a face needs at least 3 vertices");
      for (std::size_t k = 1; k + 1 < face.size(); ++k) mesh.triangles.push_back({face[0], face[k], face[k + 1]});
    }
  }
  if (mesh.triangles.empty()) fail("mesh file '{}' has no faces", path.string());
  return mesh;
}

namespace {

// ---- PLY: structural check against the header before VTK's parser sees the file ----

struct PlyProperty {
  std::string name;
  int size = 0;        ///< bytes of the (item) type
  int count_size = 0;  ///< > 0: a list whose length has this many bytes
  bool count_signed = false;
};

struct PlyElement {
  std::string name;
  std::uint64_t count = 0;
  std::vector<PlyProperty> props;
};

int ply_type_size(const std::string& t) {
  if (t == "char" || t == "uchar" || t == "int8" || t == "uint8") return 1;
  if (t == "short" || t == "ushort" || t == "int16" || t == "uint16") return 2;
  if (t == "int" || t == "uint" || t == "int32" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

/// Reads the header and walks the body: every element and list must fit the file. Returns the
/// number of vertices.
std::uint64_t check_ply_structure(const std::filesystem::path& path) {
  const std::string where = path.string();
  std::ifstream in(path, std::ios::binary);
  if (!in) fail("mesh file '{}' cannot be opened (missing or unreadable)", where);
  const std::string data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto bad = [&](const std::string& why) { fail("mesh file '{}': malformed PLY: {}", where, why); };
  if (data.compare(0, 4, "ply\n") != 0 && data.compare(0, 5, "ply\r\n") != 0) bad("it does not start with 'ply'");
  const std::size_t end_header = data.find("end_header");
  if (end_header == std::string::npos) bad("no 'end_header' line");
  std::size_t body = data.find('\n', end_header);
  if (body == std::string::npos) bad("nothing after 'end_header'");
  ++body;
  std::istringstream header(data.substr(0, end_header));
  std::string line;
  std::string format;
  std::vector<PlyElement> elements;
  std::getline(header, line);  // "ply"
  while (std::getline(header, line)) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    std::istringstream words(line);
    std::string tag;
    if (!(words >> tag) || tag == "comment" || tag == "obj_info") continue;
    if (tag == "format") {
      std::string version;
      words >> format >> version;
      if (format != "ascii" && format != "binary_little_endian" && format != "binary_big_endian")
        bad("unknown format '" + format + "'");
    } else if (tag == "element") {
      PlyElement e;
      std::string count;
      if (!(words >> e.name >> count)) bad("an element line needs a name and a count");
      const auto [end, ec] = std::from_chars(count.data(), count.data() + count.size(), e.count);
      if (ec != std::errc() || end != count.data() + count.size()) bad("element count '" + count + "'");
      // Every element takes at least one byte: a count beyond the body is a lie.
      if (e.count > data.size() - body)
        bad(fmt::format("element '{}' declares {} entries, more than the file holds", e.name, e.count));
      elements.push_back(std::move(e));
    } else if (tag == "property") {
      if (elements.empty()) bad("a property before any element");
      PlyProperty prop;
      std::string type;
      words >> type;
      if (type == "list") {
        std::string count_type;
        std::string item_type;
        words >> count_type >> item_type;
        prop.count_size = ply_type_size(count_type);
        prop.count_signed = count_type == "char" || count_type == "short" || count_type == "int" ||
                            count_type == "int8" || count_type == "int16" || count_type == "int32";
        prop.size = ply_type_size(item_type);
        if (prop.count_size == 0 || prop.size == 0 || count_type == "float" || count_type == "double" ||
            count_type == "float32" || count_type == "float64")
          bad(fmt::format("unsupported list types '{} {}'", count_type, item_type));
      } else {
        prop.size = ply_type_size(type);
        if (prop.size == 0) bad("unknown property type '" + type + "'");
      }
      if (!(words >> prop.name)) bad("a property needs a name");
      elements.back().props.push_back(prop);
    } else {
      bad("unknown header line '" + line + "'");
    }
  }
  if (format.empty()) bad("no 'format' line");
  const PlyElement* vertex = nullptr;
  const PlyElement* face = nullptr;
  for (const auto& e : elements) {
    if (e.name == "vertex") vertex = &e;
    if (e.name == "face") face = &e;
  }
  if (vertex == nullptr || face == nullptr) bad("it needs a 'vertex' and a 'face' element");
  for (const char* axis : {"x", "y", "z"}) {
    if (std::none_of(vertex->props.begin(), vertex->props.end(),
                     [&](const PlyProperty& p) { return p.name == axis && p.count_size == 0; }))
      bad(std::string("vertices have no '") + axis + "' coordinate");
  }
  if (std::none_of(face->props.begin(), face->props.end(),
                   [](const PlyProperty& p) { return p.name == "vertex_indices" && p.count_size > 0; }))
    bad("faces have no 'vertex_indices' list");

  if (format == "ascii") {
    // vtkPLY reads one element per line: each line must hold exactly its element's tokens.
    std::size_t pos = body;
    std::size_t line_no = static_cast<std::size_t>(std::count(data.begin(), data.begin() + body, '\n'));
    for (const auto& e : elements) {
      for (std::uint64_t n = 0; n < e.count; ++n) {
        std::vector<std::string> tokens;
        while (tokens.empty()) {
          if (pos >= data.size()) bad(fmt::format("the file ends inside element '{}' ({} of {})", e.name, n, e.count));
          std::size_t nl = data.find('\n', pos);
          if (nl == std::string::npos) nl = data.size();
          std::istringstream words(data.substr(pos, nl - pos));
          ++line_no;
          for (std::string w; words >> w;) tokens.push_back(w);
          pos = nl + 1;
        }
        std::size_t k = 0;
        auto next_number = [&]() {
          if (k >= tokens.size()) bad(fmt::format("line {}: too few values for element '{}'", line_no, e.name));
          const std::string& w = tokens[k++];
          double v = 0.0;
          const auto [end, ec] = std::from_chars(w.data(), w.data() + w.size(), v);
          if (ec != std::errc() || end != w.data() + w.size() || !std::isfinite(v))
            bad(fmt::format("line {}: '{}' is not a finite number", line_no, w));
          return v;
        };
        for (const auto& p : e.props) {
          if (p.count_size == 0) {
            (void)next_number();
            continue;
          }
          const double len = next_number();
          if (len < 0 || len != std::floor(len) || len > 1e6)
            bad(fmt::format("line {}: list length '{}'", line_no, len));
          for (int i = 0; i < static_cast<int>(len); ++i) (void)next_number();
        }
        if (k != tokens.size()) bad(fmt::format("line {}: too many values for element '{}'", line_no, e.name));
      }
    }
  } else {
    const bool little = format == "binary_little_endian";
    std::uint64_t pos = body;
    auto read_count = [&](const PlyProperty& p) -> std::int64_t {
      if (data.size() - pos < static_cast<std::uint64_t>(p.count_size)) bad("the file ends inside a list length");
      std::uint64_t v = 0;
      for (int i = 0; i < p.count_size; ++i) {
        const int byte = little ? p.count_size - 1 - i : i;
        v = (v << 8U) | static_cast<unsigned char>(data[pos + static_cast<std::uint64_t>(byte)]);
      }
      pos += static_cast<std::uint64_t>(p.count_size);
      if (p.count_signed && (v >> (8U * static_cast<unsigned>(p.count_size) - 1U)) != 0U) bad("negative list length");
      return static_cast<std::int64_t>(v);
    };
    for (const auto& e : elements) {
      for (std::uint64_t n = 0; n < e.count; ++n) {
        for (const auto& p : e.props) {
          const std::uint64_t items = p.count_size == 0 ? 1 : static_cast<std::uint64_t>(read_count(p));
          const std::uint64_t bytes = items * static_cast<std::uint64_t>(p.size);
          if (data.size() - pos < bytes)
            bad(fmt::format("the file ends inside element '{}' ({} of {})", e.name, n, e.count));
          pos += bytes;
        }
      }
    }
  }
  return vertex->count;
}

/// VTK reports through one process-wide output window; this one keeps the last message instead
/// of printing it (library code never prints).
class QuietOutputWindow : public vtkOutputWindow {
 public:
  static QuietOutputWindow* New();
  // clang-format off
  vtkTypeMacro(QuietOutputWindow, vtkOutputWindow)
      // clang-format on
      void DisplayText(const char* text) override {
    if (text == nullptr) return;
    const std::lock_guard<std::mutex> lock(mutex_);
    last_ = text;
  }

 private:
  std::mutex mutex_;
  std::string last_;
};
vtkStandardNewMacro(QuietOutputWindow);

void quiet_vtk() {
  static std::once_flag once;
  std::call_once(once, [] {
    vtkNew<QuietOutputWindow> window;
    vtkOutputWindow::SetInstance(window);
  });
}

}  // namespace

TriangleMesh load_ply(const std::filesystem::path& path) {
  const std::string where = path.string();
  if (!std::filesystem::is_regular_file(path)) fail("mesh file '{}' cannot be opened (missing or unreadable)", where);
  const std::uint64_t vertex_count = check_ply_structure(path);
  quiet_vtk();
  vtkNew<vtkPLYReader> reader;
  // Errors and warnings of this reader go to the observer (and so never to the output window).
  std::string vtk_message;
  vtkNew<vtkCallbackCommand> on_message;
  on_message->SetClientData(&vtk_message);
  on_message->SetCallback([](vtkObject*, unsigned long, void* client, void* call) {
    if (call != nullptr) *static_cast<std::string*>(client) = static_cast<const char*>(call);
  });
  reader->AddObserver(vtkCommand::ErrorEvent, on_message);
  reader->AddObserver(vtkCommand::WarningEvent, on_message);
  reader->SetFileName(where.c_str());
  reader->Update();
  vtkPolyData* raw = reader->GetOutput();
  if (!vtk_message.empty() || raw == nullptr || raw->GetPoints() == nullptr) {
    std::replace(vtk_message.begin(), vtk_message.end(), '\n', ' ');
    fail("mesh file '{}': VTK cannot read it{}", where, vtk_message.empty() ? "" : ": " + vtk_message);
  }
  const vtkIdType points = raw->GetNumberOfPoints();
  if (points < static_cast<vtkIdType>(vertex_count))
    fail("mesh file '{}': VTK read only {} of {} vertices", where, points, vertex_count);
  // Indices are checked before the triangle filter walks the polygons.
  vtkCellArray* polys = raw->GetPolys();
  vtkNew<vtkIdList> ids;
  for (vtkIdType c = 0; polys != nullptr && c < polys->GetNumberOfCells(); ++c) {
    polys->GetCellAtId(c, ids);
    if (ids->GetNumberOfIds() < 3) fail("mesh file '{}': face {} has fewer than 3 vertices", where, c);
    for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k) {
      if (ids->GetId(k) < 0 || ids->GetId(k) >= points)
        fail("mesh file '{}': face {} uses vertex {} (the file has {})", where, c, ids->GetId(k), points);
    }
  }
  vtkNew<vtkTriangleFilter> triangulate;
  triangulate->SetInputData(raw);
  triangulate->PassVertsOff();
  triangulate->PassLinesOff();
  triangulate->Update();
  vtkPolyData* tri = triangulate->GetOutput();
  TriangleMesh mesh;
  mesh.vertices.reserve(static_cast<std::size_t>(tri->GetNumberOfPoints()));
  for (vtkIdType i = 0; i < tri->GetNumberOfPoints(); ++i) {
    double x[3];
    tri->GetPoint(i, x);
    if (!std::isfinite(x[0]) || !std::isfinite(x[1]) || !std::isfinite(x[2]))
      fail("mesh file '{}': vertex {} is not finite", where, i);
    mesh.vertices.emplace_back(x[0], x[1], x[2]);
  }
  vtkCellArray* out = tri->GetPolys();
  for (vtkIdType c = 0; out != nullptr && c < out->GetNumberOfCells(); ++c) {
    out->GetCellAtId(c, ids);
    if (ids->GetNumberOfIds() != 3) continue;
    mesh.triangles.push_back({static_cast<std::uint32_t>(ids->GetId(0)), static_cast<std::uint32_t>(ids->GetId(1)),
                              static_cast<std::uint32_t>(ids->GetId(2))});
  }
  if (mesh.triangles.empty()) fail("mesh file '{}' has no faces", where);
  return mesh;
}

TriangleMesh load_mesh(const std::filesystem::path& path) {
  // A folder opens as an empty stream on Linux: said as what it is, as the grid readers say it.
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) fail("mesh file '{}': not a regular file (a folder)", path.string());
  const std::string ext = lower_extension(path);
  return ext == ".ply" ? load_ply(path) : load_obj(path);
}

Closure closure(const TriangleMesh& mesh) {
  // Vertices by exact position: the first index of each position stands for all of them.
  std::map<std::array<double, 3>, std::uint32_t> first;
  std::vector<std::uint32_t> id(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    const Vec3& v = mesh.vertices[i];
    id[i] = first.try_emplace({v.x(), v.y(), v.z()}, static_cast<std::uint32_t>(i)).first->second;
  }
  // Per undirected edge (a < b): how often it is walked a → b, and b → a.
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::array<int, 2>> edges;
  for (const auto& t : mesh.triangles) {
    for (std::size_t k = 0; k < 3; ++k) {
      const std::uint32_t a = id[t[k]];
      const std::uint32_t b = id[t[(k + 1) % 3]];
      ++edges[{std::min(a, b), std::max(a, b)}][a < b ? 0 : 1];
    }
  }
  if (edges.empty()) return Closure::open;
  bool balanced = true;
  for (const auto& [edge, n] : edges) {
    if ((n[0] + n[1]) % 2 != 0) return Closure::open;
    balanced = balanced && n[0] == n[1];
  }
  return balanced ? Closure::closed : Closure::misoriented;
}

TriangleMesh box_mesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i)
    m.vertices.emplace_back((i & 1) ? hi.x() : lo.x(), (i & 2) ? hi.y() : lo.y(), (i & 4) ? hi.z() : lo.z());
  // Quads listed counter-clockwise seen from outside.
  const int quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& q : quads) {
    m.triangles.push_back({std::uint32_t(q[0]), std::uint32_t(q[1]), std::uint32_t(q[2])});
    m.triangles.push_back({std::uint32_t(q[0]), std::uint32_t(q[2]), std::uint32_t(q[3])});
  }
  return m;
}

TriangleMesh rectangle_mesh(const Vec3& corner, const Vec3& u, const Vec3& v) {
  TriangleMesh m;
  m.vertices = {corner, corner + u, corner + u + v, corner + v};
  m.triangles = {{0, 1, 2}, {0, 2, 3}};
  return m;
}

}  // namespace weft::render
