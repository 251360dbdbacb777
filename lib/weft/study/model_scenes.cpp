#include "weft/study/model_scenes.h"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/fit/local_fields.h"
#include "weft/render/cloth_scene.h"
#include "weft/volume/beam.h"

namespace weft::study {

namespace fs = std::filesystem;

ModelScenes write_model_scenes(const fit::Validation& v, const volume::Grid& grid, const fs::path& vdb,
                               const std::string& vdb_in_scene, const fs::path& folder, ProgressSink& progress) {
  ModelScenes out;
  std::vector<std::string>& notes = out.notes;
  ensure_directory(folder);
  using Kind = render::ClothSceneMedium::Kind;
  auto write = [&](const std::string& name, const std::string& text, const std::string& what) {
    write_text_atomically(folder / name, text);
    out.written.emplace_back(folder / name, what);
  };
  write("grid.json", render::cloth_scene_json(vdb, vdb_in_scene, {}), "scene: the fine grid (ground truth)");
  // The cloth's normal is the thinnest axis of the active box (as cloth_scene_json frames it).
  const auto extent = grid.active_bbox().extent();
  int normal = 0;
  for (int a = 1; a < 3; ++a)
    if (extent[static_cast<std::size_t>(a)] < extent[static_cast<std::size_t>(normal)]) normal = a;
  const fit::AxisValidation* axis = nullptr;
  for (const auto& a : v.axes)
    if (volume::beam_axis(a.direction) == normal) axis = &a;
  if (axis == nullptr) {
    notes.push_back(
        fmt::format("no beam along the cloth's normal ({}): no local fields or slab scenes", "xyz"[normal]));
    return out;
  }
  // The local-gamma model's fields: blocks of L³ voxels, L the scale along the normal.
  const int block = std::max(1, static_cast<int>(std::lround(axis->scale / grid.voxel_size())));
  fit::save_local_fields(fit::local_fields(grid, block, progress), folder / "local_fields.vdb",
                         fit::FieldChannels::render);
  out.written.emplace_back(folder / "local_fields.vdb", fmt::format("local fields of {}^3-voxel blocks", block));
  render::ClothSceneMedium fields;
  fields.kind = Kind::local_fields;
  fields.fields = folder / "local_fields.vdb";
  write("local_gamma.json", render::cloth_scene_json(vdb, "local_fields.vdb", fields), "scene: the local-gamma fields");
  // One homogeneous slab per predicted law of the normal's beam (predictions only: the
  // least-squares reference has seen the ground truth).
  for (const auto& m : axis->models) {
    if (m.uses_ground_truth || !m.law) continue;
    render::ClothSceneMedium slab;
    slab.kind = Kind::homogeneous;
    slab.law = m.law;
    try {
      write("slab_" + m.name + ".json", render::cloth_scene_json(vdb, "", slab),
            fmt::format("scene: homogeneous slab, {} law of model {}", m.law->name(), m.name));
    } catch (const Error& e) {
      notes.push_back(fmt::format("slab_{}.json not written: {}", m.name, e.what()));
    }
  }
  return out;
}

}  // namespace weft::study
