#pragma once
/// @file
/// @brief Renders a scene by volumetric path tracing (docs/render.md).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "weft/core/progress.h"
#include "weft/render/image.h"
#include "weft/render/scene.h"

namespace weft::render {

/// Which specialisation of the integrator runs (automatic: the least the scene needs).
enum class IntegratorChoice { automatic, surfaces, exponential, general };

/// Overrides of the scene's own settings, as given on the command line.
struct RenderOptions {
  /// Forces a more general specialisation than the scene needs (benchmarks and tests compare
  /// them); forcing one that cannot render the scene is an error.
  IntegratorChoice integrator = IntegratorChoice::automatic;
  std::optional<int> spp;             ///< samples per pixel (scene's when unset)
  std::optional<std::uint64_t> seed;  ///< run seed (scene's when unset)
  double time_budget_seconds = 0.0;   ///< > 0: stop after the first pass that ends past it
  /// > 0: called after each pass (samples per pixel so far, image so far) for convergence runs.
  std::function<void(int spp_done, double seconds, const Image& image)> on_pass;
  /// Sample passes of this many spp when a time budget or on_pass is set (the image does not
  /// depend on it: sample s of pixel p always draws from stream_for(seed, (s << 32) | p)).
  int spp_per_pass = 1;
};

/// What the scene called for: selects the specialised integrator.
struct Features {
  bool media = false;  ///< any participating medium
  /// Some medium is not a homogeneous exponential one (MediumTraits::exponential): the general
  /// integrator runs.
  bool general_media = false;
  bool heterogeneous = false;   ///< some medium's density varies in space (grid, local fields)
  bool non_reciprocal = false;  ///< some medium needs the T_S/(c·p_Q) weights (same/explicit mode)
  /// "medium 'cloth': grid medium, exponential law, delta + ratio tracking", one per medium.
  std::vector<std::string> media_described;
  bool area_lights = false;
  bool environment = false;
  bool environment_image = false;  ///< an environment light reads a lat-long image (importance-sampled)
  bool curves = false;             ///< fibre curves (Embree round linear curves)
  [[nodiscard]] std::vector<std::string> names() const;
};

struct RenderStats {
  Features features;
  std::string integrator;  ///< which specialisation ran
  int spp = 0;             ///< samples per pixel rendered
  double seconds = 0.0;
  std::uint64_t paths = 0;
  std::uint64_t rays = 0;             ///< closest-hit and shadow rays traced
  std::uint64_t invalid_samples = 0;  ///< NaN/inf samples replaced by 0 (should be 0)
  std::uint64_t medium_cells = 0;     ///< voxels/majorant cells crossed by grid media (MediumWork)
  std::uint64_t medium_lookups = 0;   ///< density lookups of grid media (tentative collisions)
};

struct RenderResult {
  Image image;
  RenderStats stats;
};

/// @brief Renders `scene`. Deterministic for a given seed and spp whatever the thread count.
/// Throws weft::Error for scenes that cannot be built (e.g. a mesh file that vanished).
[[nodiscard]] RenderResult render(const SceneDesc& scene, const RenderOptions& options = {},
                                  ProgressSink& progress = null_progress());

/// The features `scene` uses (what render() will specialise on).
[[nodiscard]] Features scene_features(const SceneDesc& scene);

}  // namespace weft::render
