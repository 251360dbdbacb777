#pragma once
/// @file
/// @brief Renders a scene by volumetric path tracing (docs/render.md).

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "weft/core/progress.h"
#include "weft/render/features.h"
#include "weft/render/image.h"
#include "weft/render/scene.h"
#include "weft/render/world.h"

namespace weft::render {

/// Which specialisation of the integrator runs (automatic: the least the scene needs).
enum class IntegratorChoice { automatic, surfaces, exponential, general };

/// Most samples per pixel a render takes: the one range of the scene format's "spp", --spp,
/// --reference-spp and Python's spp= (sample s of a pixel draws from stream (s << 32) | pixel,
/// so any int fits; 2^24 is already days for a small film).
inline constexpr int kMaxSpp = 1 << 24;

/// Most pixel samples (film pixels × spp, summed over every image a run renders) a run takes:
/// 10¹² is days at the 1–10 M samples/s of a 2-core machine, as a streaming pass's 10¹² steps
/// are (volume/pass_budget.h). Past it a run is refused before it spends anything.
inline constexpr double kMaxPixelSamples = 1e12;

/// Refuses `samples` pixel samples past kMaxPixelSamples with one line that starts with `what`
/// and names what to lower.
void require_pixel_samples(double samples, std::string_view what, std::string_view lower);

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

/// @brief Bytes a render of a `width` × `height` film holds at once, per pixel: the running sums
/// of the samples and of their squares (3 doubles each), the image it returns and the image a
/// pass hands to `on_pass` (3 floats of mean and 3 of variance each), and the 8-bit codes and the
/// PNG writer's copy of them (3 bytes each).
[[nodiscard]] std::uint64_t film_bytes(int width, int height);

/// @brief Renders a built world. Deterministic for a given seed and spp whatever the thread
/// count. A film whose film_bytes exceed the memory budget (core/memory.h) is refused before
/// anything is allocated. Callers that render one scene several times (studies, convergence runs) build the
/// world once and render it each time.
[[nodiscard]] RenderResult render(const World& world, const RenderOptions& options = {},
                                  ProgressSink& progress = null_progress());

/// @brief Builds the world of `scene` (build_world) and renders it. Throws weft::Error for
/// scenes that cannot be built (e.g. a mesh file that vanished), naming the key.
[[nodiscard]] RenderResult render(const SceneDesc& scene, const RenderOptions& options = {},
                                  ProgressSink& progress = null_progress());

}  // namespace weft::render
