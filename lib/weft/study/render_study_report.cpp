// The image study's reports (render_study_report.h; docs/render.md §6c).
#include "weft/study/render_study_report.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/render/convergence.h"
#include "weft/render/image.h"

namespace weft::study {

using nlohmann::json;
using render::Image;
using render::mean_variance;
using render::SheetTile;

std::string study_csv(const StudyResult& result) {
  std::string csv =
      "candidate,model,factor,spp,seconds,cpu_seconds,seconds_per_spp,rmse,rmse_raw,bias,bias_sq,bias_sq_stderr,"
      "bias_z,noise,relative_rmse,speedup,seed,scene,cloth_bias,cloth_bias_sq_stderr,cloth_relative_bias,cloth_"
      "difference,cloth_rmse,cloth_noise,memory_bytes,memory_channels,albedo_factor,fitted_to_images,memory_tree_"
      "bytes," +
      scale_bias_csv_header() + "," + component_csv_header() + "\n";
  for (const auto& c : result.candidates) {
    csv += fmt::format(
        "{},{},{},{},{:.6g},{:.6g},{:.6g},{:.8g},{:.8g},{:.8g},{:.8g},{:.8g},{:.4g},{:.8g},{:.6g},{:.6g},{},{},{:.8g},"
        "{:.8g},{:.6g},{:.6g},{:.8g},{:.8g},{},{},{:.8g},{},{},{},{}\n",
        c.name, c.model, c.factor, c.spp, c.seconds, c.cpu_seconds, c.seconds / std::max(1, c.spp), c.rmse, c.rmse_raw,
        c.bias, c.bias_sq, c.bias_sq_stderr, c.bias_z(), c.noise,
        result.reference_mean > 0.0 ? c.rmse / result.reference_mean : 0.0, c.speedup, c.seed_a, c.scene_file.string(),
        c.cloth_bias, c.cloth_bias_sq_stderr, result.cloth_mean > 0.0 ? c.cloth_bias / result.cloth_mean : 0.0,
        c.cloth_difference, c.cloth_rmse, c.cloth_noise, c.memory_bytes, c.memory_channels, c.albedo_factor,
        c.fitted_to_images ? 1 : 0, c.memory_tree_bytes, scale_bias_csv(c.cloth_scales), component_csv(c.components));
  }
  return csv;
}

void judge_study(StudyResult& r) {
  // Speedups against the fine grid's t^{-1/2} law, and the headline.
  const StudyCandidate& f = r.candidates.front();
  const StudyCandidate* best = nullptr;
  for (StudyCandidate& c : r.candidates) {
    if (&c == &f) {
      c.speedup = std::numeric_limits<double>::quiet_NaN();
      continue;
    }
    const double t_fine =
        c.rmse > 0.0 ? f.seconds * (f.rmse / c.rmse) * (f.rmse / c.rmse) : std::numeric_limits<double>::infinity();
    c.speedup = t_fine / c.seconds;
    // A candidate fitted to images was chosen against the fine grid (with `--study-albedo fit`,
    // on this very reference): its figures are reported, labelled uses_ground_truth, but it is
    // not a prediction, so the headline never names it (docs/render.md §6d (b)).
    if (c.fitted_to_images) continue;
    if (best == nullptr || c.speedup > best->speedup) best = &c;
  }
  if (std::any_of(r.candidates.begin(), r.candidates.end(), [](const auto& c) { return c.fitted_to_images; }))
    r.notes.emplace_back(
        "the albedo-corrected candidates are fitted to images (uses_ground_truth) and are not judged in this "
        "headline: judge them on set-ups they were not fitted on, as the study matrix does (--study-albedo fit "
        "fits them to this study's own reference)");
  // Two digits, but never in exponent form: 150 % reads "150", not "1.5e+02".
  const auto relative = [&](double e) {
    const double pct = r.reference_mean > 0.0 ? 100.0 * e / r.reference_mean : 0.0;
    return std::abs(pct) >= 100.0 ? fmt::format("{:.0f}", pct) : fmt::format("{:.2g}", pct);
  };
  const auto coarser = [](const StudyCandidate& c) {
    return c.factor == 0 ? std::string("as one homogeneous slab") : fmt::format("at {}x coarser", c.factor);
  };
  if (best != nullptr && best->speedup > 1.0) {
    r.headline = fmt::format(
        "{} and {:.3g}x less time, {} ({}) is within RMSE {:.3g} ({}% of the mean pixel) of the fine grid: "
        "{:.3g} s at {} spp, bias {:.3g}, noise {:.3g}; the fine grid needs about {:.3g} s to get as close",
        coarser(*best), best->speedup, best->name, best->model, best->rmse, relative(best->rmse), best->seconds,
        best->spp, best->bias, best->noise, best->speedup * best->seconds);
  } else if (best != nullptr) {
    r.headline = fmt::format(
        "no coarse model beats the fine grid here: in {:.3g} s the fine grid is within RMSE {:.3g} ({}% of the "
        "mean pixel); the best coarse candidate, {} ({}), is within {:.3g} (bias {:.3g}) in {:.3g} s",
        f.seconds, f.rmse, relative(f.rmse), best->name, coarser(*best), best->rmse, best->bias, best->seconds);
  }
}

std::string study_curves_csv(const StudyResult& result) {
  std::string csv = "candidate,spp,seconds,rmse\n";
  for (const auto& c : result.candidates)
    for (const auto& p : c.curve) csv += fmt::format("{},{},{:.6g},{:.8g}\n", c.name, p.spp, p.seconds, p.rmse);
  return csv;
}

namespace {
json finite_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }
}  // namespace

json study_candidate_json(const StudyCandidate& c) {
  json curve = json::array();
  for (const auto& p : c.curve) curve.push_back({{"spp", p.spp}, {"seconds", p.seconds}, {"rmse", p.rmse}});
  return {{"name", c.name},
          {"model", c.model},
          {"factor", c.factor},
          {"spp", c.spp},
          {"seconds", c.seconds},
          {"cpu_seconds", c.cpu_seconds},
          {"rmse", c.rmse},
          {"rmse_raw", c.rmse_raw},
          {"bias", c.bias},
          {"bias_sq", c.bias_sq},
          {"bias_sq_stderr", c.bias_sq_stderr},
          {"bias_z", c.bias_z()},
          {"cloth_bias", c.cloth_bias},
          {"cloth_bias_sq", c.cloth_bias_sq},
          {"cloth_bias_sq_stderr", c.cloth_bias_sq_stderr},
          {"cloth_difference", c.cloth_difference},
          {"cloth_rmse", c.cloth_rmse},
          {"cloth_noise", c.cloth_noise},
          {"noise", c.noise},
          {"speedup", finite_or_null(c.speedup)},
          {"seed", c.seed_a},
          {"second_seed", c.seed_b},
          {"scene", c.scene_file.string()},
          {"memory_bytes", c.memory_bytes},
          {"memory_tree_bytes", c.memory_tree_bytes},
          {"memory_channels", c.memory_channels},
          {"albedo_factor", c.albedo_factor},
          {"fitted_to_images", c.fitted_to_images},
          {"uses_ground_truth", c.fitted_to_images},
          {"cloth_scales", scale_bias_json(c.cloth_scales)},
          {"components", component_biases_json(c.components)},
          {"curve", curve}};
}

StudyCandidate study_candidate_from_json(const json& j) {
  StudyCandidate c;
  c.name = j.at("name").get<std::string>();
  c.model = j.at("model").get<std::string>();
  c.factor = j.at("factor").get<int>();
  c.spp = j.at("spp").get<int>();
  c.seconds = j.at("seconds").get<double>();
  c.cpu_seconds = j.at("cpu_seconds").get<double>();
  c.rmse = j.at("rmse").get<double>();
  c.rmse_raw = j.at("rmse_raw").get<double>();
  c.bias = j.at("bias").get<double>();
  c.bias_sq = j.at("bias_sq").get<double>();
  c.bias_sq_stderr = j.at("bias_sq_stderr").get<double>();
  c.cloth_bias = j.at("cloth_bias").get<double>();
  c.cloth_bias_sq = j.at("cloth_bias_sq").get<double>();
  c.cloth_bias_sq_stderr = j.at("cloth_bias_sq_stderr").get<double>();
  c.cloth_difference = j.at("cloth_difference").get<double>();
  c.cloth_rmse = j.at("cloth_rmse").get<double>();
  c.cloth_noise = j.at("cloth_noise").get<double>();
  c.noise = j.at("noise").get<double>();
  c.speedup = j.at("speedup").is_number() ? j.at("speedup").get<double>() : std::numeric_limits<double>::quiet_NaN();
  c.seed_a = j.at("seed").get<std::uint64_t>();
  c.seed_b = j.at("second_seed").get<std::uint64_t>();
  if (const auto s = j.find("scene"); s != j.end()) c.scene_file = s->get<std::string>();
  c.memory_bytes = j.at("memory_bytes").get<std::uint64_t>();
  c.memory_tree_bytes = j.at("memory_tree_bytes").get<std::uint64_t>();
  c.memory_channels = j.at("memory_channels").get<int>();
  c.albedo_factor = j.at("albedo_factor").get<double>();
  c.fitted_to_images = j.at("fitted_to_images").get<bool>();
  c.cloth_scales = scale_bias_from_json(j.at("cloth_scales"));
  c.components = component_biases_from_json(j.at("components"));
  for (const auto& p : j.at("curve"))
    c.curve.push_back({p.at("spp").get<int>(), p.at("seconds").get<double>(), p.at("rmse").get<double>()});
  return c;
}

std::string study_json(const StudyResult& result) {
  json j;
  j["mode"] = result.mode;
  j["headline"] = result.headline;
  j["reference"] = {{"spp", result.reference.spp},
                    {"seconds", result.reference_seconds},
                    {"seed", result.reference_seed},
                    {"mean_pixel", result.reference_mean},
                    {"mean_variance", mean_variance(result.reference)},
                    {"cloth_pixels", result.cloth_pixels},
                    {"cloth_mean_pixel", result.cloth_mean},
                    {"scene", result.reference_scene.string()},
                    {"width", result.reference.width},
                    {"height", result.reference.height}};
  json axes = json::object();
  for (const auto& [axis, name] : result.best_by_ground_truth_per_axis) axes[axis] = name;
  // (c) is chosen by comparing the models with the ground truth: labelled, as validate labels it
  // (fit/report.cpp), and under the former key too, with the same content.
  const json best = {{"model", result.best_by_ground_truth},
                     {"per_axis", axes},
                     {"uses_ground_truth", true},
                     {"note", result.best_by_ground_truth_note}};
  j["best_by_ground_truth"] = best;
  j["best_predictive"] = best;
  j["slab_law"] = {{"sigma", result.sigma},
                   {"mean_concentration", result.slab_mean_concentration},
                   {"var_concentration", result.slab_var_concentration},
                   {"alpha", finite_or_null(result.slab_alpha)},
                   {"scale", result.scale}};
  j["notes"] = result.notes;
  j["resolution_floors"] = json::array();
  for (const auto& f : result.resolution_floors) j["resolution_floors"].push_back(resolution_floor_json(f));
  j["candidates"] = json::array();
  for (const auto& c : result.candidates) j["candidates"].push_back(study_candidate_json(c));
  return j.dump(2) + "\n";
}

StudySheet study_sheet(const StudyResult& result, double exposure, double error_white) {
  if (!(error_white > 0.0) || !std::isfinite(error_white))
    fail("study contact sheet: error scale must be finite and > 0, got {}", error_white);
  std::vector<const StudyCandidate*> exp_row;
  std::vector<const StudyCandidate*> gamma_row;
  const StudyCandidate* fine = nullptr;
  const StudyCandidate* slab = nullptr;
  for (const auto& c : result.candidates) {
    if (c.model == "exponential") exp_row.push_back(&c);
    if (c.model == "local-gamma") gamma_row.push_back(&c);
    if (c.factor == 1) fine = &c;
    if (c.factor == 0) slab = &c;
  }
  // Both rows hold one candidate per factor, so every row is full.
  StudySheet sheet;
  sheet.columns = 1 + static_cast<int>(std::max(exp_row.size(), gamma_row.size()));
  const auto gain = 1.0 / error_white;
  const auto image_tile = [&](const StudyCandidate& c) {
    return SheetTile{c.image, fmt::format("{}: {} spp, {:.3g} s", c.name, c.spp, c.seconds), exposure};
  };
  const auto error_tile = [&](const StudyCandidate& c) {
    return SheetTile{c.error_map, fmt::format("|A-R|: RMSE {:.3g}, bias {:.3g}", c.rmse, c.bias), gain};
  };
  // The reference's own per-pixel standard error on the error maps' scale: the noise floor
  // every RMSE is corrected for.
  Image sd = result.reference;
  for (std::size_t j = 0; j < sd.rgb.size(); ++j)
    sd.rgb[j] = sd.variance.empty() ? 0.0F : std::sqrt(std::max(0.0F, sd.variance[j]));
  sd.variance.clear();
  const auto rows = [&](const SheetTile& first_image, const SheetTile& first_error,
                        const std::vector<const StudyCandidate*>& rest) {
    sheet.tiles.push_back(first_image);
    for (const auto* c : rest) sheet.tiles.push_back(image_tile(*c));
    sheet.tiles.push_back(first_error);
    for (const auto* c : rest) sheet.tiles.push_back(error_tile(*c));
  };
  rows(SheetTile{result.reference, fmt::format("reference (fine grid): {} spp", result.reference.spp), exposure},
       SheetTile{sd, "reference: standard error", gain}, exp_row);
  if (fine != nullptr) rows(image_tile(*fine), error_tile(*fine), gamma_row);
  if (slab != nullptr) {
    sheet.tiles.push_back(image_tile(*slab));
    sheet.tiles.push_back(error_tile(*slab));
  }
  return sheet;
}

namespace {
std::filesystem::path beside(const std::filesystem::path& exr, const std::string& suffix) {
  std::filesystem::path p = exr;
  p.replace_extension(suffix);
  return p;
}
}  // namespace

std::vector<StudyFile> write_study_files(const StudyResult& r, const std::filesystem::path& exr,
                                         const std::filesystem::path& work_dir, double exposure) {
  std::vector<StudyFile> files;
  render::write_exr(exr, r.reference);
  files.push_back({exr, "reference (fine grid), linear"});
  const auto png = beside(exr, ".png");
  render::write_png(png, r.reference, exposure);
  files.push_back({png, "reference, sRGB"});
  for (const auto& c : r.candidates) {
    const auto p = work_dir / (c.name + ".exr");
    render::write_exr(p, c.image);
    files.push_back({p, fmt::format("{} at {} spp (seed {}; scene {})", c.name, c.spp, c.seed_a,
                                    c.scene_file.filename().string())});
  }
  const auto text = [&](const std::string& suffix, const std::string& content, const std::string& what) {
    const auto p = beside(exr, suffix);
    write_text_atomically(p, content);
    files.push_back({p, what});
  };
  text(".study.csv", study_csv(r), "RMSE, bias, noise, spp and time per candidate");
  text(".study.curves.csv", study_curves_csv(r), "RMSE vs spp and time per candidate");
  text(".study.json", study_json(r), "study summary and headline");
  // Error maps: white at 4x the fine grid's RMSE at equal time (its noise shows as grey speckle).
  const double fine_rmse = r.candidates.empty() ? 0.0 : r.candidates.front().rmse;
  const double white = fine_rmse > 0.0 ? 4.0 * fine_rmse : std::max(1e-6, r.reference_mean);
  const auto sheet_path = beside(exr, ".study.contact.png");
  const StudySheet tiles = study_sheet(r, exposure, white);
  render::SheetLayout layout;
  layout.columns = tiles.columns;
  render::write_contact_sheet_png(sheet_path, tiles.tiles, layout);
  files.push_back({sheet_path, fmt::format("images over their error maps |A - R| (white = {:.3g})", white)});
  return files;
}

}  // namespace weft::study
