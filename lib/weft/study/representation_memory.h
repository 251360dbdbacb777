#pragma once
/// @file
/// @brief The memory a coarse representation holds, every channel counted, from its scene file:
/// the one count the image study and the study matrix report (docs/render.md §6e "Memory").

#include <cstdint>
#include <filesystem>
#include <string>

namespace weft::study {

/// `values` = Σ over the representation's channels of its active voxels (tiles counted per voxel)
/// × the bytes its file stores a value in (4, a float; 2 for the local fields' variances, stored
/// as half: fit/local_fields.h): the data a renderer must hold, which is the figure compared. It
/// depends on the grid's values only, not on where its index origin puts the sparse tree's nodes.
/// `tree` = Σ OpenVDB Tree::memUsage() of its grids (nodes, masks and values): the sparse tree's
/// fixed cost added, which moves with the index origin (node alignment); reported, not compared.
struct RepresentationMemory {
  std::uint64_t values = 0;
  std::uint64_t tree = 0;
  int channels = 0;
};

/// The memory of medium `medium` of the scene in `scene_file` (the representation of the cloth;
/// the scene's other media are not the representation's): a grid medium's grid (or its three
/// axis grids), every grid of a local-gamma medium's fields file (also any it does not read), a
/// homogeneous law's parameters (one float each, no tree). Throws weft::Error if the scene has no
/// such medium.
[[nodiscard]] RepresentationMemory representation_memory(const std::filesystem::path& scene_file,
                                                         const std::string& medium);

}  // namespace weft::study
