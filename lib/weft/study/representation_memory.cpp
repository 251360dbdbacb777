// The memory of a representation, from its scene file (representation_memory.h).
#include "weft/study/representation_memory.h"

#include <string>

#include "weft/core/error.h"
#include "weft/render/scene.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_io.h"

namespace weft::study {

RepresentationMemory representation_memory(const std::filesystem::path& scene_file, const std::string& medium) {
  const render::SceneDesc scene = render::load_scene(scene_file);
  const auto it = scene.media.find(medium);
  if (it == scene.media.end()) fail("{}: no medium '{}' to count the memory of", scene_file.string(), medium);
  const render::MediumDesc& d = it->second;
  RepresentationMemory m;
  const auto add = [&](const volume::Grid& g) {
    m.values += static_cast<std::uint64_t>(g.value_bytes()) * g.active_voxel_count();
    m.tree += g.memory_bytes();
    ++m.channels;
  };
  if (d.kind == render::MediumKind::grid) {
    if (d.axis_grids.empty()) {
      add(volume::Grid::load(d.file, d.grid_name));
    } else {
      for (const std::string& axis : d.axis_grids) add(volume::Grid::load(d.file, axis));  // σ'_x, σ'_y, σ'_z
    }
  } else if (d.kind == render::MediumKind::local_gamma) {
    // Every grid of the fields file (fit/local_fields.h), also any the medium does not read:
    // the study writes only the four it reads (fit::FieldChannels::render), a file of `weft
    // fit --block --fields all` would count ten. Each at the bytes its file stores a value in.
    // Counted without Grid::load's value check (α, β hold +∞ on exponential blocks).
    for (const volume::GridCount& g : volume::count_grids(d.file)) {
      m.values += static_cast<std::uint64_t>(g.value_bytes) * g.active_voxels;
      m.tree += g.tree_bytes;
      ++m.channels;
    }
  } else if (d.kind == render::MediumKind::homogeneous) {
    // One value per parameter of the law, as a float.
    m.values += 4 * d.law.params.size();
    m.channels += static_cast<int>(d.law.params.size());
  }
  return m;
}

}  // namespace weft::study
