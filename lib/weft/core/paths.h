#pragma once
/// @file
/// @brief Files named inside input files (a scene's grids and meshes, a cloth config's curves), and
/// the file types their names give.

#include <filesystem>
#include <string>

namespace weft {

/// @brief The file `name` as written in an input file whose folder is `base_dir`: a relative name
/// is relative to that folder, not to the working folder, so the input means the same wherever it
/// is run from (docs/scene-format.md, docs/cloth.md "Patterns"). Returned absolute and
/// lexically normal, so a description written back out (a scene, cloth.json) names the same file
/// wherever it is saved, and reading it again does not join the folder twice.
[[nodiscard]] std::string resolve_beside(const std::string& name, const std::filesystem::path& base_dir);

/// The extension of `path` in lower case (".EXR" → ".exr"): a file type is the same in any case.
[[nodiscard]] std::string lower_extension(const std::filesystem::path& path);

}  // namespace weft
