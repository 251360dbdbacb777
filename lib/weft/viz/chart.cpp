#include "weft/viz/chart.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include <vtkAxis.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/fp_hold.h"
#include "weft/viz/display.h"
#include "weft/viz/vtk_support.h"

namespace weft::viz {
namespace {

// Sizes in pixels for a ~1000 px wide chart; scaled with the picture so small ones stay legible.
struct FontSizes {
  int title;
  int axis_title;
  int labels;
  int legend;
};

FontSizes font_sizes(int width, int height) {
  const double scale = std::clamp(std::min(width / 1000.0, height / 700.0), 0.6, 3.0);
  auto px = [&](double base) {
    const int size = std::max(9, static_cast<int>(std::lround(base * scale)));
    // With VTK's built-in font (the fallback when DejaVu is missing), 16 px context text showed
    // a ghost of each glyph's top row below it under Mesa llvmpipe; 15 and 17 px were clean.
    return size == 16 ? 17 : size;
  };
  return {px(24), px(20), px(17), px(17)};
}

struct Points {
  std::vector<double> x;
  std::vector<double> y;
};

// Points a log axis cannot show (<= 0) and non-finite points are dropped, not an error:
// a transmittance curve legitimately reaches 0 where it underflows.
Points plottable(const Series& s, const Chart& chart) {
  Points p;
  for (std::size_t i = 0; i < s.x.size(); ++i) {
    const double x = s.x[i];
    const double y = s.y[i];
    if (!std::isfinite(x) || !std::isfinite(y)) continue;
    if (chart.log_x && x <= 0.0) continue;
    if (chart.log_y && y <= 0.0) continue;
    p.x.push_back(x);
    p.y.push_back(y);
  }
  return p;
}

vtkPlot* add_plot(vtkChartXY& chart, const Points& p, const std::string& label, bool markers) {
  vtkNew<vtkTable> table;
  vtkNew<vtkDoubleArray> xs;
  xs->SetName("x");
  vtkNew<vtkDoubleArray> ys;
  // Column names must be unique in a table; the legend text comes from SetLabel below.
  ys->SetName("y");
  table->AddColumn(xs);
  table->AddColumn(ys);
  table->SetNumberOfRows(static_cast<vtkIdType>(p.x.size()));
  for (std::size_t i = 0; i < p.x.size(); ++i) {
    table->SetValue(static_cast<vtkIdType>(i), 0, vtkVariant(p.x[i]));
    table->SetValue(static_cast<vtkIdType>(i), 1, vtkVariant(p.y[i]));
  }
  vtkPlot* plot = chart.AddPlot(markers ? vtkChart::POINTS : vtkChart::LINE);
  plot->SetInputData(table, 0, 1);
  plot->SetLabel(label);
  return plot;
}

struct Corner {
  bool right;
  bool top;
};

// Position of a value along an axis as a fraction of the shown range (log axes in log10).
double fraction(vtkAxis& a, double v) {
  double lo = a.GetUnscaledMinimum();
  double hi = a.GetUnscaledMaximum();
  if (a.GetLogScaleActive()) {
    lo = std::log10(lo);
    hi = std::log10(hi);
    v = std::log10(v);
  }
  return hi > lo ? (v - lo) / (hi - lo) : 0.5;
}

// The legend goes where it hides the least data: the corner box (of the legend's size, in plot
// fractions) crossed by the fewest samples of the drawn curves. Ties keep the usual top right.
Corner emptiest_corner(const std::vector<std::pair<Points, bool>>& drawn, vtkAxis& x_axis, vtkAxis& y_axis,
                       double box_w, double box_h) {
  constexpr std::array<Corner, 4> kOrder{{{true, true}, {false, true}, {true, false}, {false, false}}};
  std::array<long, 4> hits{0, 0, 0, 0};
  auto count = [&](double u, double v) {
    for (std::size_t c = 0; c < kOrder.size(); ++c) {
      const bool in_x = kOrder[c].right ? u >= 1.0 - box_w : u <= box_w;
      const bool in_y = kOrder[c].top ? v >= 1.0 - box_h : v <= box_h;
      if (in_x && in_y && u >= 0.0 && u <= 1.0 && v >= 0.0 && v <= 1.0) ++hits[c];
    }
  };
  constexpr int kSteps = 16;  // samples along each segment, so long straight lines count too
  for (const auto& [p, joined] : drawn) {
    for (std::size_t i = 0; i < p.x.size(); ++i) {
      const double u1 = fraction(x_axis, p.x[i]);
      const double v1 = fraction(y_axis, p.y[i]);
      count(u1, v1);
      if (!joined || i + 1 == p.x.size()) continue;
      const double u2 = fraction(x_axis, p.x[i + 1]);
      const double v2 = fraction(y_axis, p.y[i + 1]);
      for (int k = 1; k < kSteps; ++k) {
        const double f = static_cast<double>(k) / kSteps;
        count(u1 + f * (u2 - u1), v1 + f * (v2 - v1));
      }
    }
  }
  std::size_t best = 0;
  for (std::size_t c = 1; c < hits.size(); ++c) {
    if (hits[c] < hits[best]) best = c;
  }
  return kOrder[best];
}

void style_axis(vtkAxis& axis, const std::string& title, bool log,
                const std::optional<std::pair<double, double>>& range, const FontSizes& fonts) {
  axis.SetTitle(title);
  detail::set_font(*axis.GetTitleProperties(), fonts.axis_title, false);
  detail::set_font(*axis.GetLabelProperties(), fonts.labels, false);
  axis.SetLogScale(log);
  if (range) {
    axis.SetBehavior(vtkAxis::FIXED);
    axis.SetUnscaledRange(range->first, range->second);
  }
}

void check(const Chart& chart, const std::filesystem::path& path) {
  const std::string where = path.string();
  if (chart.width < 16 || chart.height < 16 || chart.width > 16384 || chart.height > 16384) {
    fail("{}: chart size {}x{} is out of range (16..16384 pixels)", where, chart.width, chart.height);
  }
  for (const auto& s : chart.series) {
    if (s.x.size() != s.y.size()) {
      fail("{}: series '{}' has {} x values but {} y values", where, s.label, s.x.size(), s.y.size());
    }
    if (!(s.width > 0.0f) || !std::isfinite(s.width))
      fail("{}: series '{}' has line width {}", where, s.label, s.width);
  }
  auto check_range = [&](const char* axis, bool log, const std::optional<std::pair<double, double>>& r) {
    if (!r) return;
    if (!std::isfinite(r->first) || !std::isfinite(r->second) || !(r->first < r->second)) {
      fail("{}: {} range [{}, {}] is not an increasing finite interval", where, axis, r->first, r->second);
    }
    if (log && r->first <= 0.0)
      fail("{}: {} range [{}, {}] must be positive on a log axis", where, axis, r->first, r->second);
  };
  check_range("x", chart.log_x, chart.x_range);
  check_range("y", chart.log_y, chart.y_range);
}

}  // namespace

RenderOutcome save_chart_png(const Chart& chart, const std::filesystem::path& path) {
  check(chart, path);
  detail::require_writable_folder(path);
  RenderOutcome outcome;
  if (!ensure_display(&outcome.reason)) return outcome;
  detail::quiet_vtk_messages();

  const FontSizes fonts = font_sizes(chart.width, chart.height);
  // A bare window with a context actor, not a vtkContextView: the view brings an X interactor
  // whose initialisation crashes intermittently (XSync) on an offscreen window.
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(chart.width, chart.height);
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1.0, 1.0, 1.0);
  window->AddRenderer(renderer);
  vtkNew<vtkContextActor> actor;
  renderer->AddActor(actor);

  vtkNew<vtkChartXY> xy;
  actor->GetScene()->AddItem(xy);
  xy->SetTitle(chart.title);
  detail::set_font(*xy->GetTitleProperties(), fonts.title, true);
  style_axis(*xy->GetAxis(vtkAxis::BOTTOM), chart.x_label, chart.log_x, chart.x_range, fonts);
  style_axis(*xy->GetAxis(vtkAxis::LEFT), chart.y_label, chart.log_y, chart.y_range, fonts);

  bool any_label = false;
  std::vector<std::pair<Points, bool>> drawn;  // points, and whether they are joined by lines
  std::size_t legend_chars = 0;
  int legend_entries = 0;
  for (const Series& s : chart.series) {
    Points p = plottable(s, chart);
    if (p.x.empty()) continue;
    if (!s.label.empty()) {
      legend_chars = std::max(legend_chars, s.label.size());
      ++legend_entries;
    }
    const bool markers = s.style == LineStyle::markers;
    vtkPlot* plot = add_plot(*xy, p, s.label, markers);
    plot->SetColor(s.color[0], s.color[1], s.color[2], 255);
    plot->SetWidth(s.width);
    plot->SetLegendVisibility(!s.label.empty());
    any_label = any_label || !s.label.empty();
    if (markers) {
      auto* points = vtkPlotPoints::SafeDownCast(plot);
      points->SetMarkerStyle(vtkPlotPoints::CIRCLE);
      points->SetMarkerSize(std::max(5.0f, 3.0f * s.width));
    } else {
      vtkPlotPoints::SafeDownCast(plot)->SetMarkerStyle(vtkPlotPoints::NONE);
      plot->GetPen()->SetLineType(s.style == LineStyle::dashed   ? vtkPen::DASH_LINE
                                  : s.style == LineStyle::dotted ? vtkPen::DOT_LINE
                                                                 : vtkPen::SOLID_LINE);
    }
    drawn.emplace_back(std::move(p), !markers);
  }

  // The axes' automatic ranges are known only after a first layout; the legend corner and the
  // vertical markers depend on them.
  if (any_label || !chart.vertical_lines.empty()) {
    const HeldFpExceptions hold;  // Mesa's software rasterizer overflows in clipping
    window->Render();
  }

  // A vertical marker spans the y range shown: the fixed one, else the one the chart chose for
  // the data (known after a first layout), which is then frozen so the markers do not move it.
  if (!chart.vertical_lines.empty()) {
    double y_lo = 0.0;
    double y_hi = 1.0;
    if (chart.y_range) {
      y_lo = chart.y_range->first;
      y_hi = chart.y_range->second;
    } else {
      vtkAxis* left = xy->GetAxis(vtkAxis::LEFT);
      y_lo = left->GetUnscaledMinimum();
      y_hi = left->GetUnscaledMaximum();
      left->SetBehavior(vtkAxis::FIXED);
      left->SetUnscaledRange(y_lo, y_hi);
    }
    for (double x : chart.vertical_lines) {
      if (!std::isfinite(x) || (chart.log_x && x <= 0.0)) continue;
      vtkPlot* plot = add_plot(*xy, Points{{x, x}, {y_lo, y_hi}}, "", false);
      vtkPlotPoints::SafeDownCast(plot)->SetMarkerStyle(vtkPlotPoints::NONE);
      plot->SetColor(90, 90, 90, 255);
      plot->SetWidth(2.0f);
      plot->GetPen()->SetLineType(vtkPen::DASH_LINE);
      plot->SetLegendVisibility(false);
    }
  }

  xy->SetShowLegend(any_label);
  if (any_label) {
    vtkChartLegend& legend = *xy->GetLegend();
    detail::set_font(*legend.GetLabelProperties(), fonts.legend, false);
    // Roughly the box VTK draws: a line sample plus the longest label, one row per entry.
    const double plot_w = 0.85 * chart.width;
    const double plot_h = 0.8 * chart.height;
    const double box_w = std::min(0.9, (0.6 * fonts.legend * static_cast<double>(legend_chars) + 60.0) / plot_w);
    const double box_h = std::min(0.9, (legend_entries * (fonts.legend + 6.0) + 12.0) / plot_h);
    const Corner corner =
        emptiest_corner(drawn, *xy->GetAxis(vtkAxis::BOTTOM), *xy->GetAxis(vtkAxis::LEFT), box_w, box_h);
    legend.SetHorizontalAlignment(corner.right ? vtkChartLegend::RIGHT : vtkChartLegend::LEFT);
    legend.SetVerticalAlignment(corner.top ? vtkChartLegend::TOP : vtkChartLegend::BOTTOM);
  }

  write_atomically(path, [&](const std::filesystem::path& tmp) { detail::capture_png(*window, tmp, path); });
  outcome.written = true;
  return outcome;
}

}  // namespace weft::viz
