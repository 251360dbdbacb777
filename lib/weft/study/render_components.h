#pragma once
/// @file
/// @brief What a candidate's error is made of (docs/render.md §6e, "Transmission, single and
/// multiple scattering"): the reference and a candidate rendered also with albedo 0 and with at
/// most one scattering event, so that each image splits into
///   transmission T = the albedo-0 image (light that crosses the medium unscattered, and what the
///                    medium blocks),
///   single       S = L≤1 − T (L≤1: the image of paths with at most one scattering event),
///   multiple     M = L − L≤1,
/// with T + S + M = L exactly, image by image. Each component's bias and level come from the
/// estimators of bias_estimate.h and bias_scales.h applied to the component images: component
/// images are differences of independent renders (every render its own seed), so a component's
/// A, B and R stay independent, A and B alike, and the variance of R's component is the sum of
/// its renders' variances.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json_fwd.hpp>

#include "weft/core/progress.h"
#include "weft/render/image.h"
#include "weft/render/scene.h"
#include "weft/study/bias_scales.h"

namespace weft::study {

/// The three components, in this order.
inline const std::vector<std::string> kComponentNames{"transmission", "single", "multiple"};

/// One component's cloth bias (k = 1 only) and level over the cloth's pixels.
struct ComponentBias {
  std::string name;  ///< one of kComponentNames
  ScaleBias bias;
};

/// The two extra renders of one image: with albedo 0 and with at most one scattering event.
struct ComponentRenders {
  render::Image transmission;
  render::Image upto_single;
};

/// Throws weft::Error unless every surface of `scene` is a null boundary or an emitter: then the
/// integrator's max_depth counts the medium's scattering events only (docs/render.md §1), and
/// max_depth 1 renders exactly the paths with at most one of them.
void check_component_scene(const render::SceneDesc& scene);

/// True when candidate `name` ("exponential-4x") is split by `families` ("exponential",
/// "local-gamma", "local-gamma-segment", …, or "all"): its name without the "-Nx" suffix is listed. The
/// fine grid is split whenever anything is (it is the control: its component biases are 0).
[[nodiscard]] bool splits_components(const std::vector<std::string>& families, const std::string& name);

/// @brief Renders `scene` (JSON, canonical form) with medium `medium`'s albedo set to 0, and with
/// max_depth 1, at `spp` with seeds derived from `seed` (independent of every other image of the
/// study). Collective like render().
[[nodiscard]] ComponentRenders render_components(const nlohmann::json& scene, const std::string& medium, int spp,
                                                 std::uint64_t seed, const std::filesystem::path& base_dir,
                                                 ProgressSink& progress);

/// @brief The three components' cloth bias and level: full images A, B, R and their component
/// renders; `mask` the cloth's pixels.
[[nodiscard]] std::vector<ComponentBias> component_biases(const render::Image& a, const render::Image& b,
                                                          const render::Image& r, const ComponentRenders& ca,
                                                          const ComponentRenders& cb, const ComponentRenders& cr,
                                                          const std::vector<bool>& mask);

/// The JSON of a candidate's components, the one format of the reports and the stored cases:
/// [{"name", "bias": scale_bias_json}, …]; and back.
[[nodiscard]] nlohmann::json component_biases_json(const std::vector<ComponentBias>& components);
[[nodiscard]] std::vector<ComponentBias> component_biases_from_json(const nlohmann::json& j);

/// CSV columns per component (kComponentNames): "<name>_bias,<name>_bias_z,<name>_difference,
/// <name>_difference_stderr"; and one row's fields (empty when the candidate was not split).
[[nodiscard]] std::string component_csv_header();
[[nodiscard]] std::string component_csv(const std::vector<ComponentBias>& components);

/// x − y value by value, with variance var x + var y (independent renders); empty variances
/// count as 0. Throws weft::Error for images of different sizes.
[[nodiscard]] render::Image difference_image(const render::Image& x, const render::Image& y);

}  // namespace weft::study
