#include "weft/viz/chart_items.h"

#include <algorithm>
#include <cmath>
#include <utility>

#include <vtkAxis.h>
#include <vtkChartXY.h>
#include <vtkContext2D.h>
#include <vtkContextItem.h>
#include <vtkContextScene.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkPen.h>
#include <vtkPlotLine.h>
#include <vtkPlotPoints.h>
#include <vtkPoints2D.h>
#include <vtkRect.h>
#include <vtkTextProperty.h>
#include <vtkTransform2D.h>

#include "weft/viz/vtk_support.h"

namespace weft::viz::detail {
namespace {

// Liang-Barsky: clips the segment a-b to the box; false when nothing is left.
bool clip(std::array<float, 2>& a, std::array<float, 2>& b, const std::array<float, 4>& box) {
  const float dx = b[0] - a[0];
  const float dy = b[1] - a[1];
  float t0 = 0.0f;
  float t1 = 1.0f;
  const std::array<std::pair<float, float>, 4> pq{
      {{-dx, a[0] - box[0]}, {dx, box[1] - a[0]}, {-dy, a[1] - box[2]}, {dy, box[3] - a[1]}}};
  for (const auto& [p, q] : pq) {
    if (p == 0.0f) {
      if (q < 0.0f) return false;
      continue;
    }
    const float r = q / p;
    if (p < 0.0f) {
      if (r > t1) return false;
      t0 = std::max(t0, r);
    } else {
      if (r < t0) return false;
      t1 = std::min(t1, r);
    }
  }
  const std::array<float, 2> start{a[0] + t0 * dx, a[1] + t0 * dy};
  b = {a[0] + t1 * dx, a[1] + t1 * dy};
  a = start;
  return true;
}

// The plot area of a plot's axes in scene pixels (x_lo, x_hi, y_lo, y_hi), a little enlarged so
// a line along the frame is not cut in half.
std::array<float, 4> plot_box(vtkPlot& plot) {
  vtkAxis* x = plot.GetXAxis();
  vtkAxis* y = plot.GetYAxis();
  if (x == nullptr || y == nullptr) return {-1e6f, 1e6f, -1e6f, 1e6f};
  const vtkVector2f x1 = x->GetPosition1();
  const vtkVector2f x2 = x->GetPosition2();
  const vtkVector2f y1 = y->GetPosition1();
  const vtkVector2f y2 = y->GetPosition2();
  constexpr float kSlack = 4.0f;
  return {std::min(x1.GetX(), x2.GetX()) - kSlack, std::max(x1.GetX(), x2.GetX()) + kSlack,
          std::min(y1.GetY(), y2.GetY()) - kSlack, std::max(y1.GetY(), y2.GetY()) + kSlack};
}

// VTK's own line stipple is a fixed 16-bit pattern (its dotted line: 1 px on, 7 off), which reads
// as faint ticks. This line cuts its polyline into pieces in screen pixels instead.
class PatternLine : public vtkPlotLine {
 public:
  static PatternLine* New();
  vtkTypeMacro(PatternLine, vtkPlotLine)

      public :

      DashPattern pattern;

  bool Paint(vtkContext2D* painter) override {
    if (pattern.empty()) return vtkPlotLine::Paint(painter);
    if (!this->Visible || this->Points == nullptr || this->Points->GetNumberOfPoints() < 2) return false;
    const auto n = static_cast<int>(this->Points->GetNumberOfPoints());
    const auto* data = static_cast<const float*>(this->Points->GetVoidPointer(0));
    vtkTransform2D* to_scene = painter->GetTransform();
    std::vector<float> xy(2 * static_cast<std::size_t>(n));
    to_scene->TransformPoints(data, xy.data(), n);
    const std::vector<float> pieces = dash_polyline(xy, pattern, plot_box(*this));
    if (!pieces.empty()) {
      std::vector<float> back(pieces.size());
      to_scene->InverseTransformPoints(pieces.data(), back.data(), static_cast<int>(pieces.size() / 2));
      painter->ApplyPen(this->Pen);
      painter->DrawLines(back.data(), static_cast<int>(back.size() / 2));
    }
    return this->vtkPlotPoints::Paint(painter);  // the markers, if any
  }

  bool PaintLegend(vtkContext2D* painter, const vtkRectf& rect, int index) override {
    if (pattern.empty()) return vtkPlotLine::PaintLegend(painter, rect, index);
    const float y = rect.GetY() + 0.5f * rect.GetHeight();
    const std::vector<float> sample{rect.GetX(), y, rect.GetX() + rect.GetWidth(), y};
    const std::vector<float> pieces = dash_polyline(sample, pattern, {-1e9f, 1e9f, -1e9f, 1e9f});
    painter->ApplyPen(this->Pen);
    if (!pieces.empty()) painter->DrawLines(const_cast<float*>(pieces.data()), static_cast<int>(pieces.size() / 2));
    if (this->MarkerStyle != vtkPlotPoints::NONE) this->vtkPlotPoints::PaintLegend(painter, rect, index);
    return true;
  }
};
vtkStandardNewMacro(PatternLine);

// Labels at data points: the chart maps the table's points to the plot (log axes included);
// the text is then drawn in scene pixels so it keeps its size and stays upright.
class AnnotationPlot : public vtkPlotPoints {
 public:
  static AnnotationPlot* New();
  vtkTypeMacro(AnnotationPlot, vtkPlotPoints)

      public :

      std::vector<std::string> texts;
  std::vector<std::array<unsigned char, 3>> colors;
  int size = 12;

  bool Paint(vtkContext2D* painter) override {
    if (!this->Visible || this->Points == nullptr) return false;
    const auto n = static_cast<int>(this->Points->GetNumberOfPoints());
    if (n != static_cast<int>(texts.size())) return false;
    const auto* data = static_cast<const float*>(this->Points->GetVoidPointer(0));
    std::vector<float> xy(2 * static_cast<std::size_t>(n));
    painter->GetTransform()->TransformPoints(data, xy.data(), n);
    const std::array<float, 4> box = plot_box(*this);
    painter->PushMatrix();
    vtkNew<vtkTransform2D> identity;
    painter->SetTransform(identity);
    vtkNew<vtkTextProperty> prop;
    set_font(*prop, size, false);
    const auto gap = static_cast<float>(std::max(3, size / 3));
    for (int i = 0; i < n; ++i) {
      const auto& c = colors[static_cast<std::size_t>(i)];
      prop->SetColor(c[0] / 255.0, c[1] / 255.0, c[2] / 255.0);
      prop->SetVerticalJustificationToBottom();
      prop->SetJustificationToLeft();
      painter->ApplyTextProp(prop);
      float bounds[4];
      painter->ComputeStringBounds(texts[static_cast<std::size_t>(i)].c_str(), bounds);
      float x = xy[2 * i] + gap;
      float y = xy[2 * i + 1] + gap;
      if (x + bounds[2] > box[1]) x = xy[2 * i] - gap - bounds[2];      // no room on the right
      if (y + bounds[3] > box[3]) y = xy[2 * i + 1] - gap - bounds[3];  // nor above
      painter->DrawString(x, y, texts[static_cast<std::size_t>(i)].c_str());
    }
    painter->PopMatrix();
    return true;
  }

  bool PaintLegend(vtkContext2D*, const vtkRectf&, int) override { return false; }
};
vtkStandardNewMacro(AnnotationPlot);

class SceneText : public vtkContextItem {
 public:
  static SceneText* New();
  vtkTypeMacro(SceneText, vtkContextItem)

      public :

      float x = 0.0f;
  float y = 0.0f;
  std::string text;
  vtkNew<vtkTextProperty> prop;

  bool Paint(vtkContext2D* painter) override {
    painter->ApplyTextProp(prop);
    painter->DrawString(x, y, text.c_str());
    return true;
  }
};
vtkStandardNewMacro(SceneText);

}  // namespace

std::vector<float> dash_polyline(const std::vector<float>& xy, const DashPattern& pattern,
                                 const std::array<float, 4>& box) {
  std::vector<float> out;
  if (pattern.empty() || xy.size() < 4) return out;
  std::size_t k = 0;        // current pattern entry; even entries are "on"
  float left = pattern[0];  // pixels left in it
  for (std::size_t i = 0; i + 3 < xy.size(); i += 2) {
    std::array<float, 2> a{xy[i], xy[i + 1]};
    std::array<float, 2> b{xy[i + 2], xy[i + 3]};
    if (!clip(a, b, box)) continue;  // far outside the plot: the pattern's phase does not matter
    const float len = std::hypot(b[0] - a[0], b[1] - a[1]);
    if (!(len > 0.0f) || !std::isfinite(len)) continue;
    float pos = 0.0f;
    while (pos < len) {
      const float step = std::min(left, len - pos);
      if (k % 2 == 0) {
        const float f0 = pos / len;
        const float f1 = (pos + step) / len;
        out.insert(out.end(), {a[0] + f0 * (b[0] - a[0]), a[1] + f0 * (b[1] - a[1]), a[0] + f1 * (b[0] - a[0]),
                               a[1] + f1 * (b[1] - a[1])});
      }
      pos += step;
      left -= step;
      if (left <= 1e-4f) {
        k = (k + 1) % pattern.size();
        left = pattern[k];
      }
    }
  }
  return out;
}

vtkPlot* add_pattern_line(vtkChartXY& chart, const DashPattern& pattern) {
  vtkNew<PatternLine> line;
  line->pattern = pattern;
  chart.AddPlot(line);
  return line;
}

vtkPlot* add_annotations(vtkChartXY& chart, std::vector<std::string> texts,
                         std::vector<std::array<unsigned char, 3>> colors, int size) {
  vtkNew<AnnotationPlot> plot;
  plot->texts = std::move(texts);
  plot->colors = std::move(colors);
  plot->size = size;
  plot->SetMarkerStyle(vtkPlotPoints::NONE);
  plot->SetLegendVisibility(false);
  chart.AddPlot(plot);
  return plot;
}

void add_scene_title(vtkContextScene& scene, float x, float y, const std::string& text, int size) {
  vtkNew<SceneText> item;
  item->x = x;
  item->y = y;
  item->text = text;
  set_font(*item->prop, size, true);
  item->prop->SetColor(0.0, 0.0, 0.0);
  item->prop->SetJustificationToCentered();
  item->prop->SetVerticalJustificationToTop();
  scene.AddItem(item);
}

}  // namespace weft::viz::detail
