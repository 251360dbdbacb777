// Checks that a rendered cloth image shows the cloth (CLI tests of `weft render` with no scene,
// of `weft gen` + `weft render <out>/scene.json`, and of the model scenes of `weft fit --block`
// and `weft validate --scenes`). The scene (cloth_scene.h) puts a bright backlight behind the
// patch: without a cloth the centre of the frame is that light (uniform, saturated) or empty
// space (dark). A visible cloth makes a large share of the centre's pixels partly transmitting
// (between 2% and 85% of the backlight's radiance) and, for a grid or its local fields,
// textured (the weave's gaps and yarns).
//
//   cloth_image_check IMAGE.exr                  share >= 0.25 and CoV >= 0.1
//   cloth_image_check --slab IMAGE.exr           share >= 0.25 (a homogeneous slab is smooth)
//   cloth_image_check --slab IMAGE.exr --brighter-than OTHER.exr
//                                                also: IMAGE's centre mean exceeds OTHER's by
//                                                more than 5 standard errors (each the pixel
//                                                spread of its centre over sqrt(n))
//   cloth_image_check --picture SCENE.json IMAGE.exr
//                                                the default picture (docs/render.md §5c): the
//                                                cloth covers >= 85 % of the film and <= 2 % of
//                                                its pixels clip (a channel >= 1 at exposure 1).
//                                                The cloth's pixels are those whose camera ray
//                                                hits the box of the scene's medium: SCENE
//                                                rendered with that box as a black emitter of
//                                                radiance 1 and nothing else (its silhouette).
// Exit 0 when all hold, 1 with the measured statistics otherwise, 2 for bad usage.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

#include "weft/core/error.h"
#include "weft/render/image.h"
#include "weft/render/render.h"
#include "weft/render/scene.h"

namespace {

struct Stats {
  double backlight = 0.0;
  double mean = 0.0;
  double cov = 0.0;
  double share = 0.0;
  double stderr_mean = 0.0;
  bool finite = true;
};

Stats measure(const char* path) {
  const weft::render::Image im = weft::render::read_exr(path);
  std::vector<double> all;
  std::vector<double> centre;
  Stats s;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      const double l = (im.at(x, y, 0) + im.at(x, y, 1) + im.at(x, y, 2)) / 3.0;
      if (!std::isfinite(l)) {
        std::fprintf(stderr, "%s: pixel %d,%d is not finite\n", path, x, y);
        s.finite = false;
        return s;
      }
      all.push_back(l);
      if (x >= im.width / 4 && x < 3 * im.width / 4 && y >= im.height / 4 && y < 3 * im.height / 4) centre.push_back(l);
    }
  std::sort(all.begin(), all.end());
  s.backlight = all[static_cast<std::size_t>(0.99 * static_cast<double>(all.size() - 1))];
  double sum = 0.0;
  double sum2 = 0.0;
  int partial = 0;
  for (double l : centre) {
    if (l > 0.02 * s.backlight && l < 0.85 * s.backlight) ++partial;
    sum += l;
    sum2 += l * l;
  }
  const double n = static_cast<double>(centre.size());
  s.mean = sum / n;
  const double sd = std::sqrt(std::max(0.0, sum2 / n - s.mean * s.mean));
  s.cov = sd / std::max(s.mean, 1e-300);
  s.stderr_mean = sd / std::sqrt(n);
  s.share = partial / n;
  std::printf("%s: backlight %.4g, centre mean %.4g +- %.2g, centre CoV %.3f, partly transmitting share %.3f\n", path,
              s.backlight, s.mean, s.stderr_mean, s.cov, s.share);
  return s;
}

/// The share of the film the medium's box covers and the share of those pixels that clip.
int check_picture(const char* scene_path, const char* image_path) {
  weft::render::SceneDesc scene = weft::render::load_scene(scene_path);
  std::vector<weft::render::ShapeDesc> boxes;
  for (auto s : scene.shapes) {
    if (s.kind != weft::render::ShapeKind::box || s.interior.empty()) continue;
    s.interior.clear();
    s.material = "black";
    s.emission = weft::render::Rgb(1.0, 1.0, 1.0);
    boxes.push_back(s);
  }
  if (boxes.empty()) {
    std::fprintf(stderr, "%s: no box holding a medium\n", scene_path);
    return 1;
  }
  scene.shapes = boxes;
  scene.media.clear();
  scene.lights.clear();
  scene.materials = {{"black", weft::render::MaterialDesc{weft::render::MaterialKind::diffuse, {0, 0, 0}, 1.5}}};
  weft::render::RenderOptions options;
  options.spp = 4;
  const weft::render::Image mask = weft::render::render(scene, options).image;
  const weft::render::Image im = weft::render::read_exr(image_path);
  if (im.width != mask.width || im.height != mask.height) {
    std::fprintf(stderr, "%s is %dx%d, the scene films %dx%d\n", image_path, im.width, im.height, mask.width,
                 mask.height);
    return 1;
  }
  double cloth = 0.0;
  int clipped = 0;
  int inside = 0;
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x) {
      cloth += mask.at(x, y, 0);
      if (mask.at(x, y, 0) < 0.99F) continue;
      ++inside;
      if (std::max({im.at(x, y, 0), im.at(x, y, 1), im.at(x, y, 2)}) >= 1.0F) ++clipped;
    }
  const double coverage = cloth / (static_cast<double>(im.width) * im.height);
  const double clip_share = inside > 0 ? static_cast<double>(clipped) / inside : 1.0;
  std::printf("%s: cloth covers %.3f of the film; %d of its %d pixels clip (%.4f)\n", image_path, coverage, clipped,
              inside, clip_share);
  if (coverage < 0.85 || clip_share > 0.02) {
    std::fprintf(stderr, "not the default picture: coverage %.3f (need >= 0.85), clipped share %.4f (need <= 0.02)\n",
                 coverage, clip_share);
    return 1;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 4 && std::strcmp(argv[1], "--picture") == 0) {
    try {
      return check_picture(argv[2], argv[3]);
    } catch (const weft::Error& e) {
      std::fprintf(stderr, "cloth_image_check: %s\n", e.what());
      return 1;
    }
  }
  bool slab = false;
  const char* image = nullptr;
  const char* dimmer = nullptr;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--slab") == 0) {
      slab = true;
    } else if (std::strcmp(argv[i], "--brighter-than") == 0 && i + 1 < argc) {
      dimmer = argv[++i];
    } else if (image == nullptr) {
      image = argv[i];
    } else {
      image = nullptr;
      break;
    }
  }
  if (image == nullptr) {
    std::fprintf(stderr, "usage: cloth_image_check [--slab] IMAGE.exr [--brighter-than OTHER.exr]\n");
    return 2;
  }
  try {
    const Stats s = measure(image);
    if (!s.finite) return 1;
    if (!(s.backlight > 0.0) || s.share < 0.25 || (!slab && s.cov < 0.1)) {
      std::fprintf(stderr, "the cloth is not visible: share %.3f (need >= 0.25), CoV %.3f (need >= %s)\n", s.share,
                   s.cov, slab ? "0, a slab" : "0.1");
      return 1;
    }
    if (dimmer != nullptr) {
      const Stats d = measure(dimmer);
      if (!d.finite) return 1;
      const double se = std::hypot(s.stderr_mean, d.stderr_mean);
      if (!(s.mean - d.mean > 5.0 * se)) {
        std::fprintf(stderr, "%s (centre mean %.4g) is not brighter than %s (%.4g) by 5 standard errors (%.2g)\n",
                     image, s.mean, dimmer, d.mean, se);
        return 1;
      }
    }
    return 0;
  } catch (const weft::Error& e) {
    std::fprintf(stderr, "cloth_image_check: %s\n", e.what());
    return 1;
  }
}
