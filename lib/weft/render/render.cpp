#include "weft/render/render.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstring>
#include <memory>
#include <span>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "weft/core/error.h"
#include "weft/core/memory.h"
#include "weft/dist/distributed.h"
#include "weft/render/camera.h"
#include "weft/render/integrator.h"
#include "weft/render/medium.h"
#include "weft/render/tiling.h"
#include "weft/render/world.h"

namespace weft::render {

namespace {

template <bool kMedia, bool kNonExp>
void render_pass(const World& world, const Camera& camera, const Tiling& tiling, std::uint64_t seed, int s_begin,
                 int s_end, std::span<double> sum, std::span<double> sum2, std::atomic<std::uint64_t>& rays,
                 std::atomic<std::uint64_t>& invalid, std::atomic<std::uint64_t>& cells,
                 std::atomic<std::uint64_t>& lookups, ProgressTask& task) {
  const Integrator<kMedia, kNonExp> integrator(world);
  const int side = tiling.side;
  const int tiles_x = tiling.tiles_x;
  tbb::enumerable_thread_specific<PathCounters> thread_counters(world.media);
  // Tiles are the work units, over threads and MPI ranks (dist::run_units), unit u rendering
  // tile tiling.tile(u). A run without a store gives unit u to rank u mod N in every pass, so each rank keeps the
  // running sums of its own tiles in `sum`/`sum2` across passes and every pixel accumulates its samples in order, as in
  // one process. A tile's result carries its ray counts and, from ranks other than 0, its sums
  // after this pass (rank 0's own tiles are already in place).
  dist::UnitsOptions how;
  how.progress = &task;
  how.name = [&](std::size_t u) {
    const std::size_t t = tiling.tile(u);
    return fmt::format("render tile {} (x {}, y {}, {} px a side), samples {}..{}", t, (t % tiles_x) * side,
                       (t / tiles_x) * side, side, s_begin, s_end - 1);
  };
  const auto tile_pixels = [&](std::size_t u, auto&& f) {
    const std::size_t t = tiling.tile(u);
    const int tx = static_cast<int>(t % static_cast<std::size_t>(tiles_x));
    const int ty = static_cast<int>(t / static_cast<std::size_t>(tiles_x));
    for (int y = ty * side; y < std::min(camera.height, (ty + 1) * side); ++y) {
      for (int x = tx * side; x < std::min(camera.width, (tx + 1) * side); ++x) {
        f(x, y, static_cast<std::size_t>(y) * camera.width + x);
      }
    }
  };
  const std::vector<dist::Bytes> tiles = dist::run_units(
      tiling.count(),
      [&](std::size_t t) {
        PathCounters& counters = thread_counters.local();
        const std::uint64_t rays_before = counters.rays;
        const auto work_of = [&] {
          MediumWork total;
          for (std::size_t m = 0; m < world.media.size(); ++m) {
            const MediumWork w = world.media[m]->work(counters.scratch[m].get());
            total.cells += w.cells;
            total.lookups += w.lookups;
          }
          return total;
        };
        const MediumWork work_before = work_of();
        std::uint64_t bad = 0;
        tile_pixels(t, [&](int x, int y, std::size_t pixel) {
          for (int s = s_begin; s < s_end; ++s) {
            // One stream per (sample, pixel): the image is the same for any tiling or thread count.
            Pcg32 rng = stream_for(seed, (static_cast<std::uint64_t>(s) << 32U) | pixel);
            Vec3 o;
            Vec3 d;
            camera.generate(x + rng.uniform(), y + rng.uniform(), rng, o, d);
            Rgb value = integrator.li(o, d, rng, counters);
            if (!value.isFinite().all()) {
              value.setZero();
              ++bad;
            }
            for (int c = 0; c < 3; ++c) {
              sum[pixel * 3 + c] += value[c];
              sum2[pixel * 3 + c] += value[c] * value[c];
            }
          }
        });
        const MediumWork work_after = work_of();
        std::vector<double> out{static_cast<double>(counters.rays - rays_before), static_cast<double>(bad),
                                static_cast<double>(work_after.cells - work_before.cells),
                                static_cast<double>(work_after.lookups - work_before.lookups)};
        if (!dist::is_root()) {
          tile_pixels(t, [&](int, int, std::size_t pixel) {
            out.insert(out.end(), sum.begin() + static_cast<std::ptrdiff_t>(pixel * 3),
                       sum.begin() + static_cast<std::ptrdiff_t>(pixel * 3 + 3));
            out.insert(out.end(), sum2.begin() + static_cast<std::ptrdiff_t>(pixel * 3),
                       sum2.begin() + static_cast<std::ptrdiff_t>(pixel * 3 + 3));
          });
        }
        dist::Bytes b(out.size() * sizeof(double));
        std::memcpy(b.data(), out.data(), b.size());
        return b;
      },
      how);
  for (std::size_t t = 0; t < tiles.size(); ++t) {
    std::vector<double> in(tiles[t].size() / sizeof(double));
    std::memcpy(in.data(), tiles[t].data(), in.size() * sizeof(double));
    rays += static_cast<std::uint64_t>(in[0]);
    invalid += static_cast<std::uint64_t>(in[1]);
    cells += static_cast<std::uint64_t>(in[2]);
    lookups += static_cast<std::uint64_t>(in[3]);
    if (in.size() == 4) continue;  // rank 0's own tile
    std::size_t k = 4;
    tile_pixels(t, [&](int, int, std::size_t pixel) {
      std::copy(in.begin() + static_cast<std::ptrdiff_t>(k), in.begin() + static_cast<std::ptrdiff_t>(k + 3),
                sum.begin() + static_cast<std::ptrdiff_t>(pixel * 3));
      std::copy(in.begin() + static_cast<std::ptrdiff_t>(k + 3), in.begin() + static_cast<std::ptrdiff_t>(k + 6),
                sum2.begin() + static_cast<std::ptrdiff_t>(pixel * 3));
      k += 6;
    });
  }
}

/// The film's sample sums, zeroed over the threads: the first write to a fresh allocation's pages
/// faults them in, so a std::vector(n, 0.0) of a large film at few spp was a serial 20 ms that one
/// core ran while the other waited (docs/benchmarks.md "Threads: 1 vs 2").
std::unique_ptr<double[]> parallel_zeros(std::size_t n) {
  auto v = std::make_unique_for_overwrite<double[]>(n);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, std::size_t{1} << 15U),
                    [&](const tbb::blocked_range<std::size_t>& r) { std::fill(&v[r.begin()], &v[0] + r.end(), 0.0); });
  return v;
}

Image make_image(int width, int height, int n, std::span<const double> sum, std::span<const double> sum2) {
  Image image;
  image.width = width;
  image.height = height;
  image.spp = n;
  image.rgb.resize(sum.size());
  image.variance.resize(sum.size());
  // Each value on its own, so spread over the threads: on a large film at few spp this loop (and
  // the first touch of its 8 bytes a value) was a serial tail of tens of milliseconds that one
  // core ran while the other waited (docs/benchmarks.md "Threads: 1 vs 2").
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, sum.size(), std::size_t{1} << 14U),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) {
                        const double mean = sum[i] / n;
                        const double var = n > 1 ? std::max(0.0, (sum2[i] - n * mean * mean) / (n - 1)) : 0.0;
                        image.rgb[i] = static_cast<float>(mean);
                        image.variance[i] = static_cast<float>(var / n);
                      }
                    });
  return image;
}

}  // namespace

std::uint64_t film_bytes(int width, int height) {
  constexpr std::uint64_t kSums = std::uint64_t{2} * 3 * sizeof(double);       // samples and squares
  constexpr std::uint64_t kImages = std::uint64_t{2} * 2 * 3 * sizeof(float);  // returned + a pass's
  constexpr std::uint64_t kPerPixel = kSums + kImages + std::uint64_t{2} * 3;  // + 8-bit codes, PNG copy
  return static_cast<std::uint64_t>(std::max(width, 0)) * static_cast<std::uint64_t>(std::max(height, 0)) * kPerPixel;
}

void require_pixel_samples(double samples, std::string_view what, std::string_view lower) {
  if (samples > kMaxPixelSamples)
    // Whole numbers: rounded to a few digits, a count just past the limit would read as the limit.
    fail("{}: {:.0f} pixel samples, over the limit of {:.0f} (10^12) a run takes (days at 10 M samples/s): lower {}",
         what, samples, kMaxPixelSamples, lower);
}

RenderResult render(const SceneDesc& scene, const RenderOptions& options, ProgressSink& progress) {
  return render(build_world(scene), options, progress);
}

RenderResult render(const World& world, const RenderOptions& options, ProgressSink& progress) {
  const auto start = std::chrono::steady_clock::now();
  const Camera camera(world.camera);
  const int spp = options.spp.value_or(world.settings.spp);
  if (spp < 1 || spp > kMaxSpp) fail("spp must be in [1, {}], got {}", kMaxSpp, spp);
  // With a time budget the spp is a cap the budget ends before.
  if (options.time_budget_seconds == 0.0)
    require_pixel_samples(static_cast<double>(camera.width) * camera.height * spp, world.source,
                          "the spp or camera.width and camera.height");
  const std::uint64_t seed = options.seed.value_or(world.settings.seed);
  if (options.time_budget_seconds < 0.0 || !std::isfinite(options.time_budget_seconds))
    fail("time budget must be finite and >= 0, got {}", options.time_budget_seconds);

  // The same rule as every "estimate before spending" guard (core/memory.h): a film the budget
  // cannot hold is one line, not std::bad_alloc half-way through.
  const std::uint64_t budget = default_memory_budget();
  if (film_bytes(camera.width, camera.height) > budget) {
    const auto [need, limit] = format_bytes_apart(film_bytes(camera.width, camera.height), budget);
    fail(
        "{}: the camera's {}x{} film needs about {} (sample sums and images), over the memory budget of {}: lower "
        "camera.width and camera.height",
        world.source, camera.width, camera.height, need, limit);
  }

  RenderResult result;
  result.stats.features = world.features;
  const Features& f = result.stats.features;
  const std::size_t n = static_cast<std::size_t>(camera.width) * camera.height * 3;
  const std::unique_ptr<double[]> sums = parallel_zeros(2 * n);
  const std::span<double> sum(sums.get(), n);
  const std::span<double> sum2(sums.get() + n, n);
  std::atomic<std::uint64_t> rays{0};
  std::atomic<std::uint64_t> invalid{0};
  std::atomic<std::uint64_t> cells{0};
  std::atomic<std::uint64_t> lookups{0};

  const bool passes = options.time_budget_seconds > 0.0 || static_cast<bool>(options.on_pass);
  // A render without passes of its own still runs in passes when its units would otherwise be
  // long: a unit is where progress is reported and a Ctrl-C stops (render/tiling.h).
  const int per_pass =
      passes ? std::max(1, options.spp_per_pass) : Tiling::bounded_pass_spp(camera.width, camera.height, spp);
  const Tiling tiling(camera.width, camera.height, per_pass);
  const std::size_t tiles = tiling.count();
  const int pass_count = (spp + per_pass - 1) / per_pass;
  ProgressTask task(progress, "render", static_cast<std::uint64_t>(tiles) * static_cast<std::uint64_t>(pass_count));
  IntegratorChoice choice = options.integrator;
  const IntegratorChoice needed = !f.media          ? IntegratorChoice::surfaces
                                  : f.general_media ? IntegratorChoice::general
                                                    : IntegratorChoice::exponential;
  if (choice == IntegratorChoice::automatic) choice = needed;
  if (static_cast<int>(choice) < static_cast<int>(needed))
    fail("the scene needs a more general integrator than the one requested");
  result.stats.integrator = choice == IntegratorChoice::surfaces      ? "surfaces"
                            : choice == IntegratorChoice::exponential ? "volpath<exponential>"
                                                                      : "volpath<general>";

  int done = 0;
  auto seconds = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  while (done < spp) {
    const int end = std::min(spp, done + per_pass);
    if (choice == IntegratorChoice::surfaces) {
      render_pass<false, false>(world, camera, tiling, seed, done, end, sum, sum2, rays, invalid, cells, lookups, task);
    } else if (choice == IntegratorChoice::exponential) {
      render_pass<true, false>(world, camera, tiling, seed, done, end, sum, sum2, rays, invalid, cells, lookups, task);
    } else {
      render_pass<true, true>(world, camera, tiling, seed, done, end, sum, sum2, rays, invalid, cells, lookups, task);
    }
    done = end;
    // Rank 0 holds the whole image after each pass (render_pass) and decides for every rank
    // whether the time budget is spent.
    if (options.on_pass && dist::is_root())
      options.on_pass(done, seconds(), make_image(camera.width, camera.height, done, sum, sum2));
    if (options.time_budget_seconds > 0.0 && dist::root_decides(seconds() >= options.time_budget_seconds)) break;
  }
  result.image = make_image(camera.width, camera.height, done, sum, sum2);
  result.stats.spp = done;
  result.stats.seconds = seconds();
  result.stats.paths = static_cast<std::uint64_t>(done) * camera.width * camera.height;
  result.stats.rays = rays.load();
  result.stats.invalid_samples = invalid.load();
  result.stats.medium_cells = cells.load();
  result.stats.medium_lookups = lookups.load();
  return result;
}

}  // namespace weft::render