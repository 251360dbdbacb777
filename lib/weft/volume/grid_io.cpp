#include "weft/volume/grid_io.h"

#include <openvdb/io/File.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {

void save_grids(const std::vector<Grid>& grids, const std::filesystem::path& path) {
  ensure_openvdb_initialized();
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    try {
      openvdb::GridPtrVec out;
      for (const auto& g : grids) out.push_back(g.impl().grid);
      openvdb::io::File file(tmp.string());
      file.write(out);
      file.close();
    } catch (const openvdb::Exception& e) {
      fail("{}: cannot write OpenVDB file: {}", path.string(), e.what());
    }
  });
}

}  // namespace weft::volume
