#include "weft/viz/chart.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotArea.h>
#include <vtkPlotPoints.h>
#include <vtkRect.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkTable.h>
#include <vtkTextProperty.h>

#include "weft/core/error.h"
#include "weft/viz/chart_items.h"
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
  int annotation;
};

FontSizes font_sizes(int width, int height) {
  const double scale = std::clamp(std::min(width / 1000.0, height / 700.0), 0.6, 3.0);
  auto px = [&](double base) {
    const int size = std::max(9, static_cast<int>(std::lround(base * scale)));
    // With VTK's built-in font (the fallback when DejaVu is missing), 16 px context text showed
    // a ghost of each glyph's top row below it under Mesa llvmpipe; 15 and 17 px were clean.
    return size == 16 ? 17 : size;
  };
  return {px(24), px(20), px(17), px(17), px(17)};
}

struct Points {
  std::vector<double> x;
  std::vector<double> y;
};

bool shown(double v, bool log) { return std::isfinite(v) && (!log || v > 0.0); }

// Runs of consecutive points both axes can show. Non-finite points and points a log axis cannot
// show (<= 0: a transmittance that underflowed, an empty histogram bin) end a run, so no line is
// drawn across the gap they leave.
std::vector<Points> runs_of(const std::vector<double>& x, const std::vector<double>& y, const Chart& chart) {
  std::vector<Points> runs(1);
  for (std::size_t i = 0; i < x.size(); ++i) {
    if (shown(x[i], chart.log_x) && shown(y[i], chart.log_y)) {
      runs.back().x.push_back(x[i]);
      runs.back().y.push_back(y[i]);
    } else if (!runs.back().x.empty()) {
      runs.emplace_back();
    }
  }
  if (runs.back().x.empty()) runs.pop_back();
  return runs;
}

vtkNew<vtkTable> table_of(const std::vector<const std::vector<double>*>& columns) {
  vtkNew<vtkTable> table;
  for (std::size_t c = 0; c < columns.size(); ++c) {
    vtkNew<vtkDoubleArray> a;
    // Column names must be unique in a table; legend text comes from SetLabel.
    a->SetName(std::string(1, static_cast<char>('a' + c)).c_str());
    a->SetNumberOfValues(static_cast<vtkIdType>(columns[c]->size()));
    for (std::size_t i = 0; i < columns[c]->size(); ++i) a->SetValue(static_cast<vtkIdType>(i), (*columns[c])[i]);
    table->AddColumn(a);
  }
  return table;
}

// Dash patterns in multiples of the line width, so thick lines keep their look.
detail::DashPattern pattern_for(LineStyle style, float width) {
  const float w = std::max(width, 2.0f);
  switch (style) {
    case LineStyle::dashed:
      return {5.0f * w, 3.0f * w};
    case LineStyle::dotted:
      return {1.2f * w, 1.8f * w};
    case LineStyle::dash_dot:
      return {5.0f * w, 2.0f * w, 1.2f * w, 2.0f * w};
    default:
      return {};
  }
}

int vtk_marker(Marker m) {
  switch (m) {
    case Marker::square:
      return vtkPlotPoints::SQUARE;
    case Marker::diamond:
      return vtkPlotPoints::DIAMOND;
    case Marker::cross:
      return vtkPlotPoints::CROSS;
    case Marker::plus:
      return vtkPlotPoints::PLUS;
    case Marker::none:
      return vtkPlotPoints::NONE;
    default:
      return vtkPlotPoints::CIRCLE;
  }
}

// Dotted lines thinner than 3 px read as a grey haze; they are drawn at least that wide.
float drawn_width(const Series& s) { return s.style == LineStyle::dotted ? std::max(s.width, 3.0f) : s.width; }

struct Corner {
  bool right;
  bool top;
};

double to_axis(double v, bool log) { return log ? std::log10(v) : v; }

// Position of a value along an axis as a fraction of the shown range (log axes in log10).
double fraction(double v, const std::pair<double, double>& range, bool log) {
  const double lo = to_axis(range.first, log);
  const double hi = to_axis(range.second, log);
  return hi > lo ? (to_axis(v, log) - lo) / (hi - lo) : 0.5;
}

struct Ranges {
  std::pair<double, double> x;
  std::pair<double, double> y;
};

// The legend goes where it hides the least data: the corner box (of the legend's size, in plot
// fractions) crossed by the fewest samples of the drawn curves. Ties keep the usual top right.
Corner emptiest_corner(const std::vector<std::pair<Points, bool>>& drawn, const Chart& chart, const Ranges& r,
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
      const double u1 = fraction(p.x[i], r.x, chart.log_x);
      const double v1 = fraction(p.y[i], r.y, chart.log_y);
      count(u1, v1);
      if (!joined || i + 1 == p.x.size()) continue;
      const double u2 = fraction(p.x[i + 1], r.x, chart.log_x);
      const double v2 = fraction(p.y[i + 1], r.y, chart.log_y);
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

// An automatic range covers every shown value with a margin of 4 % of the span on each side (in
// log10 on a log axis), so no marker or line touches the frame.
std::pair<double, double> auto_range(const std::vector<double>& values, bool log) {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -lo;
  for (double v : values) {
    if (!shown(v, log)) continue;
    lo = std::min(lo, to_axis(v, log));
    hi = std::max(hi, to_axis(v, log));
  }
  if (!(lo <= hi)) {
    lo = 0.0;
    hi = 1.0;
  } else if (hi - lo < 1e-12 * std::max(1.0, std::abs(hi))) {
    const double half = log ? 0.5 : std::max(0.5 * std::abs(hi), 0.5);
    lo -= half;
    hi += half;
  }
  const double pad = 0.04 * (hi - lo);
  lo -= pad;
  hi += pad;
  return log ? std::make_pair(std::pow(10.0, lo), std::pow(10.0, hi)) : std::make_pair(lo, hi);
}

Ranges ranges_of(const Chart& chart) {
  std::vector<double> xs;
  std::vector<double> ys;
  auto add = [&](const std::vector<double>& x, const std::vector<double>& y) {
    for (const Points& p : runs_of(x, y, chart)) {
      xs.insert(xs.end(), p.x.begin(), p.x.end());
      ys.insert(ys.end(), p.y.begin(), p.y.end());
    }
  };
  for (const Series& s : chart.series) add(s.x, s.y);
  for (const Band& b : chart.bands) {
    add(b.x, b.lower);
    add(b.x, b.upper);
  }
  for (const Annotation& a : chart.annotations) add({a.x}, {a.y});
  for (double v : chart.vertical_lines) {
    if (shown(v, chart.log_x)) xs.push_back(v);
  }
  return {chart.x_range ? *chart.x_range : auto_range(xs, chart.log_x),
          chart.y_range ? *chart.y_range : auto_range(ys, chart.log_y)};
}

void style_axis(vtkAxis& axis, const std::string& title, bool log, const std::pair<double, double>& range,
                const FontSizes& fonts) {
  axis.SetTitle(title);
  detail::set_font(*axis.GetTitleProperties(), fonts.axis_title, false);
  detail::set_font(*axis.GetLabelProperties(), fonts.labels, false);
  axis.SetLogScale(log);
  axis.SetBehavior(vtkAxis::FIXED);
  axis.SetUnscaledRange(range.first, range.second);
}

void check(const Chart& chart, const std::string& where) {
  if (chart.width < 16 || chart.height < 16 || chart.width > 16384 || chart.height > 16384) {
    fail("{}: chart size {}x{} is out of range (16..16384 pixels)", where, chart.width, chart.height);
  }
  for (const auto& s : chart.series) {
    if (s.x.size() != s.y.size()) {
      fail("{}: series '{}' has {} x values but {} y values", where, s.label, s.x.size(), s.y.size());
    }
    if (!(s.width > 0.0f) || !std::isfinite(s.width) || s.width > 100.0f)
      fail("{}: series '{}' has line width {} (want (0, 100] pixels)", where, s.label, s.width);
  }
  for (const auto& b : chart.bands) {
    if (b.x.size() != b.lower.size() || b.x.size() != b.upper.size()) {
      fail("{}: band '{}' has {} x values but {} lower and {} upper values", where, b.label, b.x.size(), b.lower.size(),
           b.upper.size());
    }
    if (!(b.opacity > 0.0 && b.opacity <= 1.0))
      fail("{}: band '{}' has opacity {} (want (0, 1])", where, b.label, b.opacity);
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

/// Whether a run of points is drawn as a line: a lone point (a series with one value shown, e.g.
/// a study at one factor) has no line, and VTK refuses to draw one; it is drawn as its marker.
bool joined(const Points& p, const Series& s) { return s.style != LineStyle::markers && p.x.size() >= 2; }

vtkPlot* add_line(vtkChartXY& xy, const Points& p, const Series& s, bool legend) {
  const bool markers_only = !joined(p, s);
  vtkPlot* plot =
      markers_only ? xy.AddPlot(vtkChart::POINTS) : detail::add_pattern_line(xy, pattern_for(s.style, s.width));
  plot->SetInputData(table_of({&p.x, &p.y}), 0, 1);
  plot->SetLabel(s.label);
  plot->SetColor(s.color[0], s.color[1], s.color[2], 255);
  plot->SetWidth(drawn_width(s));
  plot->SetLegendVisibility(legend);
  auto* points = vtkPlotPoints::SafeDownCast(plot);
  const Marker marker = markers_only && s.marker == Marker::none ? Marker::circle : s.marker;
  points->SetMarkerStyle(vtk_marker(marker));
  if (marker != Marker::none) points->SetMarkerSize(std::max(7.0f, 3.5f * s.width));
  return plot;
}

// Builds one panel into `xy`, which lays itself out in `cell` (scene pixels, origin bottom left).
void build_panel(vtkChartXY& xy, const Chart& chart, const vtkRectf& cell) {
  const FontSizes fonts = font_sizes(static_cast<int>(cell.GetWidth()), static_cast<int>(cell.GetHeight()));
  xy.SetAutoSize(false);
  xy.SetSize(cell);
  detail::set_font(*xy.GetTitleProperties(), fonts.title, true);
  // A title longer than the panel wraps onto more lines instead of running off both edges.
  xy.SetTitle(detail::wrap_text(*xy.GetTitleProperties(), chart.title, static_cast<int>(cell.GetWidth()) - 40));
  const Ranges r = ranges_of(chart);
  style_axis(*xy.GetAxis(vtkAxis::BOTTOM), chart.x_label, chart.log_x, r.x, fonts);
  style_axis(*xy.GetAxis(vtkAxis::LEFT), chart.y_label, chart.log_y, r.y, fonts);

  std::vector<std::pair<Points, bool>> drawn;  // points, and whether they are joined by lines
  std::size_t legend_chars = 0;
  int legend_entries = 0;
  auto count_label = [&](const std::string& label) {
    if (label.empty()) return;
    legend_chars = std::max(legend_chars, label.size());
    ++legend_entries;
  };

  // Bands first: drawn under the lines.
  for (const Band& b : chart.bands) {
    bool legend = !b.label.empty();
    std::vector<double> keep_x;
    std::vector<double> keep_lo;
    std::vector<double> keep_hi;
    auto flush = [&] {
      if (keep_x.size() >= 2) {
        vtkPlot* plot = xy.AddPlot(vtkChart::AREA);
        plot->SetInputData(table_of({&keep_x, &keep_lo, &keep_hi}));
        plot->SetInputArray(0, "a");
        plot->SetInputArray(1, "b");
        plot->SetInputArray(2, "c");
        plot->SetLabel(b.label);
        const auto alpha = static_cast<unsigned char>(std::lround(255.0 * b.opacity));
        plot->GetBrush()->SetColor(b.color[0], b.color[1], b.color[2], alpha);
        plot->GetPen()->SetLineType(vtkPen::NO_PEN);
        plot->SetLegendVisibility(legend);
        if (legend) count_label(b.label);
        legend = false;
      }
      keep_x.clear();
      keep_lo.clear();
      keep_hi.clear();
    };
    for (std::size_t i = 0; i < b.x.size(); ++i) {
      if (shown(b.x[i], chart.log_x) && shown(b.lower[i], chart.log_y) && shown(b.upper[i], chart.log_y)) {
        keep_x.push_back(b.x[i]);
        keep_lo.push_back(std::min(b.lower[i], b.upper[i]));
        keep_hi.push_back(std::max(b.lower[i], b.upper[i]));
      } else {
        flush();
      }
    }
    flush();
  }

  for (const Series& s : chart.series) {
    bool legend = !s.label.empty();
    if (legend) count_label(s.label);
    for (Points& p : runs_of(s.x, s.y, chart)) {
      add_line(xy, p, s, legend);
      legend = false;  // one legend entry for all runs of a series
      const bool line = joined(p, s);
      drawn.emplace_back(std::move(p), line);
    }
  }

  // A vertical marker spans the y range shown.
  for (double x : chart.vertical_lines) {
    if (!shown(x, chart.log_x)) continue;
    Series line{"", {x, x}, {r.y.first, r.y.second}, {90, 90, 90}, LineStyle::dashed, 2.0f};
    add_line(xy, Points{line.x, line.y}, line, false);
  }

  if (!chart.annotations.empty()) {
    std::vector<double> ax;
    std::vector<double> ay;
    std::vector<std::string> texts;
    std::vector<std::array<unsigned char, 3>> colors;
    for (const Annotation& a : chart.annotations) {
      if (!shown(a.x, chart.log_x) || !shown(a.y, chart.log_y) || a.text.empty()) continue;
      ax.push_back(a.x);
      ay.push_back(a.y);
      texts.push_back(a.text);
      colors.push_back(a.color);
    }
    if (!texts.empty()) {
      vtkPlot* plot = detail::add_annotations(xy, std::move(texts), std::move(colors), fonts.annotation);
      plot->SetInputData(table_of({&ax, &ay}), 0, 1);
    }
  }

  const bool any_label = legend_entries > 0;
  xy.SetShowLegend(any_label);
  if (any_label) {
    vtkChartLegend& legend = *xy.GetLegend();
    detail::set_font(*legend.GetLabelProperties(), fonts.legend, false);
    // Room for a few dashes of the patterned lines.
    const int symbol = std::max(30, static_cast<int>(std::lround(2.4 * fonts.legend)));
    legend.SetSymbolWidth(symbol);
    // Roughly the box VTK draws: a line sample plus the longest label, one row per entry.
    const double plot_w = 0.85 * cell.GetWidth();
    const double plot_h = 0.8 * cell.GetHeight();
    const double box_w =
        std::min(0.9, (0.6 * fonts.legend * static_cast<double>(legend_chars) + symbol + 30.0) / plot_w);
    const double box_h = std::min(0.9, (legend_entries * (fonts.legend + 6.0) + 12.0) / plot_h);
    const Corner corner = emptiest_corner(drawn, chart, r, box_w, box_h);
    legend.SetHorizontalAlignment(corner.right ? vtkChartLegend::RIGHT : vtkChartLegend::LEFT);
    legend.SetVerticalAlignment(corner.top ? vtkChartLegend::TOP : vtkChartLegend::BOTTOM);
  }
}

}  // namespace

RenderOutcome save_chart_grid_png(const std::vector<Chart>& panels, int columns, const std::filesystem::path& path,
                                  const std::string& title) {
  const std::string where = path.string();
  if (panels.empty()) fail("{}: a chart grid needs at least one panel", where);
  if (columns < 1) fail("{}: a chart grid needs at least one column, got {}", where, columns);
  for (const Chart& c : panels) check(c, where);
  int cell_w = 0;
  int cell_h = 0;
  for (const Chart& c : panels) {
    cell_w = std::max(cell_w, c.width);
    cell_h = std::max(cell_h, c.height);
  }
  const int cols = std::min(columns, static_cast<int>(panels.size()));
  const int rows = (static_cast<int>(panels.size()) + cols - 1) / cols;
  const FontSizes fonts = font_sizes(cell_w, cell_h);
  const int title_h = title.empty() ? 0 : 2 * fonts.title + 8;
  const long width = static_cast<long>(cols) * cell_w;
  const long height = static_cast<long>(rows) * cell_h + title_h;
  if (width > 16384 || height > 16384)
    fail("{}: chart grid of {}x{} pixels is too large (at most 16384 on a side)", where, width, height);
  detail::require_writable_folder(path);
  RenderOutcome outcome;
  if (!ensure_display(&outcome.reason)) return outcome;
  detail::quiet_vtk_messages();

  // A bare window with a context actor, not a vtkContextView: the view brings an X interactor
  // whose initialisation crashes intermittently (XSync) on an offscreen window.
  vtkNew<vtkRenderWindow> window;
  detail::prepare_window(*window, static_cast<int>(width), static_cast<int>(height));
  vtkNew<vtkRenderer> renderer;
  detail::prepare_renderer(*renderer);
  window->AddRenderer(renderer);
  vtkNew<vtkContextActor> actor;
  renderer->AddActor(actor);
  vtkContextScene& scene = *actor->GetScene();

  for (std::size_t i = 0; i < panels.size(); ++i) {
    const int col = static_cast<int>(i) % cols;
    const int row = static_cast<int>(i) / cols;
    vtkNew<vtkChartXY> xy;
    scene.AddItem(xy);
    // A gutter on the right and at the top of each cell, so one panel's legend or last tick label
    // does not run into the next panel's axis.
    const float gutter_x = panels.size() > 1 ? 0.03f * static_cast<float>(cell_w) : 0.0f;
    const float gutter_y = panels.size() > 1 ? 0.02f * static_cast<float>(cell_h) : 0.0f;
    const vtkRectf cell(static_cast<float>(col * cell_w), static_cast<float>((rows - 1 - row) * cell_h),
                        static_cast<float>(cell_w) - gutter_x, static_cast<float>(cell_h) - gutter_y);
    build_panel(*xy, panels[i], cell);
  }
  if (!title.empty()) {
    detail::add_scene_title(scene, 0.5f * static_cast<float>(width), static_cast<float>(height - 6), title,
                            fonts.title + 2);
  }
  detail::capture_png(*window, path);
  outcome.written = true;
  return outcome;
}

RenderOutcome save_chart_png(const Chart& chart, const std::filesystem::path& path) {
  return save_chart_grid_png({chart}, 1, path);
}

}  // namespace weft::viz
