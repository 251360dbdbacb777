#include "weft/viz/volume_view.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <vtkActor.h>
#include <vtkActor2D.h>
#include <vtkArrowSource.h>
#include <vtkCamera.h>
#include <vtkCoordinate.h>
#include <vtkFloatArray.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkMatrix4x4.h>
#include <vtkNew.h>
#include <vtkOutlineSource.h>
#include <vtkPointData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPropCollection.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTransform.h>
#include <vtkTransformPolyDataFilter.h>

#include "weft/core/error.h"
#include "weft/core/fp_hold.h"
#include "weft/viz/display.h"
#include "weft/viz/vtk_support.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::viz {
namespace {

// Larger grids are averaged down to this budget for display: finer than the picture's pixels
// along the cloth, and few enough triangles for llvmpipe to draw in a fraction of a second.
constexpr std::int64_t kMaxSamplesPerAxis = 160;
constexpr std::int64_t kMaxSamples = 100LL * 100LL * 100LL;
// Share of the picture's width given to the oblique view when the top view is drawn beside it.
constexpr double kObliqueShare = 0.58;
constexpr double kIsoFraction = 0.35;

struct Sampled {
  vtkSmartPointer<vtkImageData> image = vtkSmartPointer<vtkImageData>::New();
  std::array<double, 6> bounds{};  ///< world bounds of the voxels shown (not of the samples)
};

// Box-filters the active box by an integer factor, so a displayed sample is the mean of the
// voxels it covers (the mean concentration is what the eye should judge), and pads one empty
// layer around it so the volume fades out at its faces and a one-voxel-thick grid still renders.
Sampled sample_grid(const volume::Grid& grid) {
  const volume::IndexBox box = grid.active_bbox();
  const auto ext = box.extent();
  std::int64_t f = 1;
  auto cells = [&](std::int64_t n) { return (n + f - 1) / f; };
  while (std::max({cells(ext[0]), cells(ext[1]), cells(ext[2])}) > kMaxSamplesPerAxis ||
         cells(ext[0]) * cells(ext[1]) * cells(ext[2]) > kMaxSamples) {
    ++f;
  }
  const std::array<std::int64_t, 3> n{cells(ext[0]), cells(ext[1]), cells(ext[2])};
  const std::array<std::int64_t, 3> dims{n[0] + 2, n[1] + 2, n[2] + 2};
  std::vector<double> sum(static_cast<std::size_t>(n[0] * n[1] * n[2]), 0.0);
  auto index = [&](std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<std::size_t>(((i - box.min[0]) / f) +
                                    n[0] * (((j - box.min[1]) / f) + n[1] * ((k - box.min[2]) / f)));
  };
  const openvdb::FloatGrid& vdb = *grid.impl().grid;
  for (auto it = vdb.cbeginValueOn(); it; ++it) {
    const openvdb::CoordBBox b = it.getBoundingBox();
    for (int k = b.min().z(); k <= b.max().z(); ++k) {
      for (int j = b.min().y(); j <= b.max().y(); ++j) {
        for (int i = b.min().x(); i <= b.max().x(); ++i) sum[index(i, j, k)] += *it;
      }
    }
  }

  Sampled s;
  const double h = grid.voxel_size();
  const auto o = grid.origin();
  const double step = h * static_cast<double>(f);
  s.image->SetDimensions(static_cast<int>(dims[0]), static_cast<int>(dims[1]), static_cast<int>(dims[2]));
  s.image->SetSpacing(step, step, step);
  // Sample (a) sits at the centre of its block; the padding layer sits one step outside.
  s.image->SetOrigin(o[0] + h * box.min[0] - 0.5 * step, o[1] + h * box.min[1] - 0.5 * step,
                     o[2] + h * box.min[2] - 0.5 * step);
  vtkNew<vtkFloatArray> values;
  values->SetName("value");
  values->SetNumberOfValues(dims[0] * dims[1] * dims[2]);
  values->FillValue(0.0f);
  for (std::int64_t k = 0; k < n[2]; ++k) {
    for (std::int64_t j = 0; j < n[1]; ++j) {
      for (std::int64_t i = 0; i < n[0]; ++i) {
        // Blocks at the far faces may be cut short by the box.
        const std::int64_t bx = std::min(f, ext[0] - i * f);
        const std::int64_t by = std::min(f, ext[1] - j * f);
        const std::int64_t bz = std::min(f, ext[2] - k * f);
        const double mean =
            sum[static_cast<std::size_t>(i + n[0] * (j + n[1] * k))] / static_cast<double>(bx * by * bz);
        const auto v = static_cast<float>(mean);
        values->SetValue((i + 1) + dims[0] * ((j + 1) + dims[1] * (k + 1)), v);
      }
    }
  }
  s.image->GetPointData()->SetScalars(values);
  for (std::size_t a = 0; a < 3; ++a) {
    s.bounds[2 * a] = o[a] + h * box.min[a];
    s.bounds[2 * a + 1] = o[a] + h * (box.max[a] + 1.0);
  }
  return s;
}

void check(const volume::Grid& grid, const VolumeView& view, const std::filesystem::path& path) {
  const std::string where = path.string();
  if (view.width < 16 || view.height < 16 || view.width > 16384 || view.height > 16384) {
    fail("{}: view size {}x{} is out of range (16..16384 pixels)", where, view.width, view.height);
  }
  if (grid.active_bbox().empty()) fail("{}: grid '{}' has no active voxels; nothing to show", where, grid.name());
  for (const Arrow& a : view.arrows) {
    const double len2 =
        a.direction[0] * a.direction[0] + a.direction[1] * a.direction[1] + a.direction[2] * a.direction[2];
    if (!std::isfinite(len2) || !(len2 > 0.0)) {
      fail("{}: arrow '{}' has direction ({}, {}, {}); it needs a finite non-zero vector", where, a.label,
           a.direction[0], a.direction[1], a.direction[2]);
    }
  }
}

// An arrow of `length` whose tip is at `tip`, pointing along unit `d`: vtkArrowSource points
// along +x from 0 to 1, so map x to d and complete an orthonormal frame.
vtkSmartPointer<vtkActor> make_arrow(const std::array<double, 3>& d, const std::array<double, 3>& tip, double length,
                                     const std::array<unsigned char, 3>& colour) {
  std::array<double, 3> helper = std::abs(d[0]) < 0.9 ? std::array<double, 3>{1, 0, 0} : std::array<double, 3>{0, 1, 0};
  std::array<double, 3> u{d[1] * helper[2] - d[2] * helper[1], d[2] * helper[0] - d[0] * helper[2],
                          d[0] * helper[1] - d[1] * helper[0]};
  const double un = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
  for (double& c : u) c /= un;
  const std::array<double, 3> w{d[1] * u[2] - d[2] * u[1], d[2] * u[0] - d[0] * u[2], d[0] * u[1] - d[1] * u[0]};
  vtkNew<vtkMatrix4x4> m;
  for (int r = 0; r < 3; ++r) {
    const auto ri = static_cast<std::size_t>(r);
    m->SetElement(r, 0, d[ri] * length);
    m->SetElement(r, 1, u[ri] * length);
    m->SetElement(r, 2, w[ri] * length);
    m->SetElement(r, 3, tip[ri] - d[ri] * length);
  }
  vtkNew<vtkTransform> transform;
  transform->SetMatrix(m);
  vtkNew<vtkArrowSource> arrow;
  arrow->SetShaftResolution(24);
  arrow->SetTipResolution(24);
  arrow->SetShaftRadius(0.04);
  arrow->SetTipRadius(0.1);
  arrow->SetTipLength(0.3);
  vtkNew<vtkTransformPolyDataFilter> placed;
  placed->SetTransform(transform);
  placed->SetInputConnection(arrow->GetOutputPort());
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(placed->GetOutputPort());
  auto actor = vtkSmartPointer<vtkActor>::New();
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(colour[0] / 255.0, colour[1] / 255.0, colour[2] / 255.0);
  actor->GetProperty()->SetAmbient(0.3);
  actor->GetProperty()->SetDiffuse(0.7);
  return actor;
}

// ResetCamera fits a bounding sphere, which leaves the picture off-centre and small when the
// arrows stick out on one side; instead, pan and zoom until the projected corners of everything
// shown fill the picture less `top_margin` and `bottom_margin` (fractions of the height kept for
// the title and the key).
void frame(vtkRenderer& renderer, double top_margin, double bottom_margin) {
  // Corners of each prop's own box: the union's box would add empty corners of its own.
  std::vector<std::array<double, 3>> corners;
  vtkPropCollection* props = renderer.GetViewProps();
  props->InitTraversal();
  while (vtkProp* prop = props->GetNextProp()) {
    if (vtkActor2D::SafeDownCast(prop) != nullptr) continue;  // text: placed in pixels
    const double* b = prop->GetVisibility() != 0 ? prop->GetBounds() : nullptr;
    if (b == nullptr || !(b[0] <= b[1])) continue;
    for (int c = 0; c < 8; ++c)
      corners.push_back({b[(c & 1) != 0 ? 1 : 0], b[(c & 2) != 0 ? 3 : 2], b[(c & 4) != 0 ? 5 : 4]});
  }
  if (corners.empty()) return;
  vtkCamera& camera = *renderer.GetActiveCamera();
  camera.OrthogonalizeViewUp();
  // The free area in view coordinates ([-1, 1] over the viewport): y from -1 + 2b to 1 - 2t.
  const double area_centre = bottom_margin - top_margin;
  const double area_half = 1.0 - top_margin - bottom_margin;
  for (int pass = 0; pass < 3; ++pass) {
    double lo[2] = {1e300, 1e300};
    double hi[2] = {-1e300, -1e300};
    for (auto p : corners) {
      renderer.WorldToView(p[0], p[1], p[2]);  // now in [-1, 1] across the viewport
      for (int a = 0; a < 2; ++a) {
        lo[a] = std::min(lo[a], p[static_cast<std::size_t>(a)]);
        hi[a] = std::max(hi[a], p[static_cast<std::size_t>(a)]);
      }
    }
    // Move the camera sideways so the box's projection is centred in the free area.
    const double shift[2] = {0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]) - area_centre};
    double fp[3];
    double pos[3];
    double up[3];
    camera.GetFocalPoint(fp);
    camera.GetPosition(pos);
    camera.GetViewUp(up);
    double dir[3] = {fp[0] - pos[0], fp[1] - pos[1], fp[2] - pos[2]};
    const double dist = std::sqrt(dir[0] * dir[0] + dir[1] * dir[1] + dir[2] * dir[2]);
    double right[3] = {dir[1] * up[2] - dir[2] * up[1], dir[2] * up[0] - dir[0] * up[2],
                       dir[0] * up[1] - dir[1] * up[0]};
    const double rn = std::sqrt(right[0] * right[0] + right[1] * right[1] + right[2] * right[2]);
    const double half_h = camera.GetParallelProjection() != 0
                              ? camera.GetParallelScale()
                              : dist * std::tan(0.5 * camera.GetViewAngle() * M_PI / 180.0);
    double aspect[2];
    renderer.GetAspect(aspect);
    const double half_w = half_h * aspect[0] / aspect[1];
    for (int a = 0; a < 3; ++a) {
      const double move = right[a] / rn * shift[0] * half_w + up[a] * shift[1] * half_h;
      fp[a] += move;
      pos[a] += move;
    }
    camera.SetFocalPoint(fp);
    camera.SetPosition(pos);
    const double need = std::max(0.5 * (hi[0] - lo[0]), 0.5 * (hi[1] - lo[1]) / area_half);
    if (need > 0.0) camera.Zoom(0.9 / need);
    renderer.ResetCameraClippingRange();
  }
}

// The surface level: a fraction of a high percentile of the positive sample values. Fibre
// volume fractions inside a yarn sit near its packing fraction; a third of it outlines the yarn.
double iso_level(const Sampled& s) {
  std::vector<float> positive;
  const vtkIdType n = s.image->GetNumberOfPoints();
  const auto* values = vtkFloatArray::SafeDownCast(s.image->GetPointData()->GetScalars());
  for (vtkIdType i = 0; i < n; ++i) {
    const float v = values->GetValue(i);
    if (v > 0.0f) positive.push_back(v);
  }
  if (positive.empty()) return 0.5;
  const auto k = static_cast<std::ptrdiff_t>(0.95 * static_cast<double>(positive.size() - 1));
  std::nth_element(positive.begin(), positive.begin() + k, positive.end());
  return kIsoFraction * static_cast<double>(positive[static_cast<std::size_t>(k)]);
}

void add_title(vtkRenderer& renderer, const std::string& text, int size) {
  vtkNew<vtkTextActor> title;
  title->SetInput(text.c_str());
  detail::set_font(*title->GetTextProperty(), size, true);
  title->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
  title->GetTextProperty()->SetJustificationToCentered();
  title->GetTextProperty()->SetVerticalJustificationToTop();
  title->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  title->SetPosition(0.5, 0.975);
  renderer.AddActor2D(title);
}

// One row of coloured labels along the bottom of the viewport, centred, each an arrow glyph and
// its text, spaced by their length.
void add_key(vtkRenderer& renderer, const std::vector<std::pair<std::string, std::array<unsigned char, 3>>>& keys,
             int size, double viewport_width) {
  if (keys.empty()) return;
  std::vector<std::string> texts;
  double total = 0.0;
  const double char_w = 0.62 * size;  // DejaVu Sans Bold's mean advance
  const double spacing = 2.0 * size;
  for (const auto& [label, colour] : keys) {
    texts.push_back("\u2192 " + label);
    total += char_w * static_cast<double>(label.size() + 2);
  }
  total += spacing * static_cast<double>(keys.size() - 1);
  double x = std::max(4.0, 0.5 * (viewport_width - total));
  for (std::size_t i = 0; i < keys.size(); ++i) {
    vtkNew<vtkTextActor> text;
    text->SetInput(texts[i].c_str());
    detail::set_font(*text->GetTextProperty(), size, true);
    const auto& c = keys[i].second;
    text->GetTextProperty()->SetColor(c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
    text->GetTextProperty()->SetJustificationToLeft();
    text->GetTextProperty()->SetVerticalJustificationToBottom();
    text->GetPositionCoordinate()->SetCoordinateSystemToViewport();
    text->SetPosition(x, 0.5 * size);
    renderer.AddActor2D(text);
    x += char_w * static_cast<double>(keys[i].first.size() + 2) + spacing;
  }
}

}  // namespace

RenderOutcome save_volume_png(const volume::Grid& grid, const VolumeView& view, const std::filesystem::path& path) {
  check(grid, view, path);
  detail::require_writable_folder(path);
  RenderOutcome outcome;
  if (!ensure_display(&outcome.reason)) return outcome;
  detail::quiet_vtk_messages();

  const Sampled s = sample_grid(grid);
  vtkNew<vtkRenderWindow> window;
  detail::prepare_window(*window, view.width, view.height);

  // The yarns as a surface: an isosurface of the (block-mean) values, lit, which llvmpipe
  // rasterizes in a fraction of the time its ray caster needed for the same grid (docs/benchmarks.md:
  // the volume rendering was most of `weft validate`). The level sits at a fraction of a high
  // percentile of the positive values, not of the maximum, so one saturated voxel does not move it.
  const double level = iso_level(s);
  vtkNew<vtkFlyingEdges3D> surface;
  surface->SetInputData(s.image);
  surface->SetValue(0, level);
  surface->ComputeNormalsOn();
  surface->ComputeScalarsOff();
  surface->ComputeGradientsOff();
  {
    const HeldFpExceptions hold;
    surface->Update();
  }
  vtkNew<vtkPolyDataMapper> surface_mapper;
  surface_mapper->SetInputConnection(surface->GetOutputPort());
  surface_mapper->ScalarVisibilityOff();
  auto cloth_actor = [&] {
    auto actor = vtkSmartPointer<vtkActor>::New();
    actor->SetMapper(surface_mapper);
    vtkProperty& p = *actor->GetProperty();
    p.SetColor(0.80, 0.55, 0.30);
    p.SetAmbient(0.30);
    p.SetDiffuse(0.75);
    p.SetSpecular(0.15);
    p.SetSpecularPower(20.0);
    return actor;
  };
  auto outline_actor = [&] {
    vtkNew<vtkOutlineSource> outline;
    outline->SetBounds(s.bounds[0], s.bounds[1], s.bounds[2], s.bounds[3], s.bounds[4], s.bounds[5]);
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputConnection(outline->GetOutputPort());
    auto actor = vtkSmartPointer<vtkActor>::New();
    actor->SetMapper(mapper);
    actor->GetProperty()->SetColor(0.3, 0.3, 0.3);
    actor->GetProperty()->SetLineWidth(1.5f);
    return actor;
  };

  // Left (or whole) panel: the three-quarter view with the beams; right: straight down z.
  const double split = view.top_view ? kObliqueShare : 1.0;
  const double font_scale = std::min(view.width * split / 800.0, view.height / 700.0);
  const int label_size = std::max(12, static_cast<int>(std::lround(20.0 * font_scale)));
  vtkNew<vtkRenderer> oblique;
  detail::prepare_renderer(*oblique);
  oblique->SetViewport(0.0, 0.0, split, 1.0);
  window->AddRenderer(oblique);
  oblique->AddActor(cloth_actor());
  oblique->AddActor(outline_actor());

  // Arrows come from outside the box and stop short of it, pointing at its centre.
  const std::array<double, 3> centre{0.5 * (s.bounds[0] + s.bounds[1]), 0.5 * (s.bounds[2] + s.bounds[3]),
                                     0.5 * (s.bounds[4] + s.bounds[5])};
  const double radius = 0.5 * std::sqrt((s.bounds[1] - s.bounds[0]) * (s.bounds[1] - s.bounds[0]) +
                                        (s.bounds[3] - s.bounds[2]) * (s.bounds[3] - s.bounds[2]) +
                                        (s.bounds[5] - s.bounds[4]) * (s.bounds[5] - s.bounds[4]));
  std::vector<std::pair<std::string, std::array<unsigned char, 3>>> keys;
  for (const Arrow& a : view.arrows) {
    const double len =
        std::sqrt(a.direction[0] * a.direction[0] + a.direction[1] * a.direction[1] + a.direction[2] * a.direction[2]);
    const std::array<double, 3> d{a.direction[0] / len, a.direction[1] / len, a.direction[2] / len};
    // Distance from the centre to the box's face along -d, so the tip stops just outside it.
    double reach = radius;
    for (int ax = 0; ax < 3; ++ax) {
      const auto i = static_cast<std::size_t>(ax);
      if (std::abs(d[i]) > 1e-12) {
        reach = std::min(reach, 0.5 * (s.bounds[2 * i + 1] - s.bounds[2 * i]) / std::abs(d[i]));
      }
    }
    const double gap = 0.08 * radius;
    const double length = 0.6 * radius;
    const std::array<double, 3> tip{centre[0] - d[0] * (reach + gap), centre[1] - d[1] * (reach + gap),
                                    centre[2] - d[2] * (reach + gap)};
    oblique->AddActor(make_arrow(d, tip, length, a.color));
    if (!a.label.empty()) keys.emplace_back(a.label, a.color);
  }

  // Labels are a key in a strip kept free of geometry (below the view), never placed in the
  // scene: a label beside its arrow was covered by the arrow's own tail from some directions.
  const double title_margin = view.title.empty() ? 0.02 : 0.06 + 0.9 * label_size / view.height;
  // The strip is kept whenever there are arrows, labelled or not, so labels never move the view.
  const double key_margin = view.arrows.empty() ? 0.02 : 0.04 + 1.6 * label_size / view.height;
  add_key(*oblique, keys, label_size, view.width * split);
  if (!view.title.empty()) add_title(*oblique, view.title, label_size + 4);

  vtkCamera* camera = oblique->GetActiveCamera();
  camera->SetFocalPoint(centre[0], centre[1], centre[2]);
  camera->SetPosition(centre[0] + 1.0 * radius, centre[1] - 1.7 * radius, centre[2] + 1.3 * radius);
  camera->SetViewUp(0.0, 0.0, 1.0);
  oblique->ResetCamera();
  frame(*oblique, title_margin, key_margin);

  vtkNew<vtkRenderer> top;
  if (view.top_view) {
    detail::prepare_renderer(*top);
    top->SetViewport(split, 0.0, 1.0, 1.0);
    window->AddRenderer(top);
    top->AddActor(cloth_actor());
    top->AddActor(outline_actor());
    add_title(*top, "seen along -z (gaps show white)", label_size);
    vtkCamera* c = top->GetActiveCamera();
    c->ParallelProjectionOn();
    c->SetFocalPoint(centre[0], centre[1], centre[2]);
    c->SetPosition(centre[0], centre[1], centre[2] + 3.0 * radius);
    c->SetViewUp(0.0, 1.0, 0.0);
    top->ResetCamera();
    frame(*top, title_margin, key_margin);
  }

  detail::capture_png(*window, path);
  outcome.written = true;
  return outcome;
}

}  // namespace weft::viz
