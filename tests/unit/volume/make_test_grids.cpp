// Writes the .vdb fixtures of the CLI tests into the folder given as argv[1]: a good grid and
// the bad inputs every command must refuse with a one-line error (empty, negative, NaN,
// non-float, non-uniform voxel scale, rotated, mirrored or sheared voxels, corrupt), a grid whose
// metadata says its values are extinction, and scenes around the rotated and the extinction grids
// for `weft render`.
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <string>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

namespace {

void write(const std::string& path, const openvdb::GridBase::Ptr& grid) {
  openvdb::io::File file(path);
  file.write({grid});
  file.close();
}

openvdb::FloatGrid::Ptr float_grid(const std::string& name) {
  auto g = openvdb::FloatGrid::create(0.0f);
  g->setName(name);
  g->setTransform(openvdb::math::Transform::createLinearTransform(0.05));
  return g;
}

// DIR/NAME_scene.json: a grid medium of DIR/NAME.vdb (read as concentration, σ = 1) in a box, for
// `weft render`.
void write_scene(const std::string& dir, const std::string& name) {
  std::ofstream(dir + "/" + name + "_scene.json")
      << R"({"camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 1, "width": 8, "height": 8},)"
      << R"( "materials": {"b": {"type": "null"}},)"
      << R"( "media": {"m": {"type": "grid", "file": ")" << name << R"(.vdb", "sigma": 1, "albedo": 0}},)"
      << R"( "shapes": [{"type": "box", "min": [-3, -3, -3], "max": [3, 3, 3], "material": "b", "interior": "m"}],)"
      << R"( "lights": [{"type": "environment", "radiance": 1}]})" << '\n';
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUTPUT_FOLDER\n", argv[0]);
    return 2;
  }
  const std::string dir = argv[1];
  openvdb::initialize();
  // good.vdb: layered slab with holes, 24×20×10 voxels: non-exponential on every axis.
  auto good = float_grid("density");
  auto acc = good->getAccessor();
  for (int i = 0; i < 24; ++i) {
    for (int j = 0; j < 20; ++j) {
      for (int k = 0; k < 10; ++k) {
        const bool fibre = ((i / 3 + j / 4 + k / 2) % 3) != 0;
        acc.setValue(openvdb::Coord(i, j, k), fibre ? 0.3f + 0.05f * static_cast<float>(k % 3) : 0.0f);
      }
    }
  }
  write(dir + "/good.vdb", good);
  // extinction.vdb: good.vdb's values recorded as extinction μ in 1/mm (weft:value_kind, weft:units), as
  // extinction_grid writes them, and a scene that reads it as concentration (the default).
  auto extinction = good->deepCopy();
  extinction->insertMeta("weft:value_kind", openvdb::StringMetadata("extinction"));
  extinction->insertMeta("weft:units", openvdb::StringMetadata("mm"));
  write(dir + "/extinction.vdb", extinction);
  write_scene(dir, "extinction");
  auto empty = float_grid("density");
  write(dir + "/empty.vdb", empty);
  auto negative = float_grid("density");
  negative->getAccessor().setValue(openvdb::Coord(1, 2, 3), -0.5f);
  write(dir + "/negative.vdb", negative);
  auto nan = float_grid("density");
  nan->getAccessor().setValue(openvdb::Coord(0, 0, 0), std::nanf(""));
  write(dir + "/nan.vdb", nan);
  auto ints = openvdb::Int32Grid::create(0);
  ints->setName("labels");
  ints->getAccessor().setValue(openvdb::Coord(0, 0, 0), 3);
  write(dir + "/int.vdb", ints);
  auto stretched = float_grid("density");
  stretched->transform().preScale(openvdb::Vec3d(1.0, 2.0, 1.0));
  stretched->getAccessor().setValue(openvdb::Coord(0, 0, 0), 0.5f);
  write(dir + "/stretched.vdb", stretched);
  // Voxels that are cubic but not axis-aligned: weft would lay them out as origin + h·(i, j, k)
  // (docs/scene-format.md, "Grid media"), so they are refused.
  auto rotated = float_grid("density");
  rotated->transform().postRotate(std::numbers::pi / 4.0, openvdb::math::Z_AXIS);
  rotated->getAccessor().setValue(openvdb::Coord(0, 0, 0), 0.5f);
  write(dir + "/rotated.vdb", rotated);
  auto mirrored = float_grid("density");
  mirrored->transform().preScale(openvdb::Vec3d(-1.0, 1.0, 1.0));
  mirrored->getAccessor().setValue(openvdb::Coord(0, 0, 0), 0.5f);
  write(dir + "/mirrored.vdb", mirrored);
  auto sheared = float_grid("density");
  openvdb::math::Mat4d shear = openvdb::math::Mat4d::identity();
  shear.setMat3(openvdb::math::Mat3d(0.05, 0.0, 0.0, 0.025, 0.05 * std::sqrt(0.75), 0.0, 0.0, 0.0, 0.05));
  sheared->setTransform(openvdb::math::Transform::createLinearTransform(shear));
  sheared->getAccessor().setValue(openvdb::Coord(0, 0, 0), 0.5f);
  write(dir + "/sheared.vdb", sheared);
  write_scene(dir, "rotated");
  // far.vdb: two voxels 10⁶ voxels apart on every axis: a sparse grid of a dense box of 10¹⁸
  // voxels, which passes over its box must refuse before allocating (docs/robustness.md).
  auto far = float_grid("density");
  far->getAccessor().setValue(openvdb::Coord(0, 0, 0), 0.5f);
  far->getAccessor().setValue(openvdb::Coord(1000000, 1000000, 1000000), 0.5f);
  write(dir + "/far.vdb", far);
  // far_index.vdb: 10×8×6 voxels from i = 2147483000, in the outermost root child, where
  // OpenVDB's node walks overflow int32: refused on reading (docs/robustness.md "Index range").
  auto far_index = float_grid("density");
  for (int i = 0; i < 10; ++i) {
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 6; ++k) far_index->getAccessor().setValue(openvdb::Coord(2147483000 + i, j, k), 0.4f);
    }
  }
  write(dir + "/far_index.vdb", far_index);
  // half_index.vdb: 8×8×8 voxels from i = 2³⁰, inside the index range but where OpenVDB's
  // parallel dense copy split its box at (min + max) >> 1 and overflowed (docs/robustness.md
  // "Index range"); half_index_near.vdb: the same voxels with the world origin moved so that they
  // lie near the world origin. `weft export` refuses what single-precision renderers cannot
  // resolve there (docs/export.md "Where the renderers' floats are").
  constexpr int kHalf = 1 << 30;
  auto half_index = float_grid("density");
  for (int i = 0; i < 8; ++i) {
    for (int j = 0; j < 8; ++j) {
      for (int k = 0; k < 8; ++k) half_index->getAccessor().setValue(openvdb::Coord(kHalf + i, j, k), 0.4f);
    }
  }
  write(dir + "/half_index.vdb", half_index);
  half_index->transform().postTranslate(openvdb::Vec3d(-0.05 * kHalf, 0.0, 0.0));
  write(dir + "/half_index_near.vdb", half_index);
  // uniform.vdb: 4×4×4 voxels of C = 0.3: no structure, so no yarn scale can be measured.
  auto uniform = float_grid("density");
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      for (int k = 0; k < 4; ++k) uniform->getAccessor().setValue(openvdb::Coord(i, j, k), 0.3f);
    }
  }
  write(dir + "/uniform.vdb", uniform);
  // uniform_fields.vdb: uniform.vdb's local fields of blocks of 2 voxels (`weft fit --block 2`'s
  // grids: 2×2×2 cells of mean 0.3, no variance), on good.vdb's voxel corners and over a corner of
  // it: the fields of another cloth for good.vdb. extinction_fields.vdb: the same recording that
  // its values are extinction.
  const auto write_fields = [&](const std::string& name, const char* kind) {
    openvdb::GridPtrVec grids;
    for (const char* channel :
         {"mean_concentration", "var_concentration_x", "var_concentration_y", "var_concentration_z"}) {
      auto g = openvdb::FloatGrid::create(0.0f);
      g->setName(channel);
      // Cell 0 spans good.vdb's voxels 0 and 1: [-0.025, 0.075) (voxel centres at 0.05 i).
      g->setTransform(openvdb::math::Transform::createLinearTransform(0.1));
      g->transform().postTranslate(openvdb::Vec3d(0.025));
      const bool mean = std::string(channel) == "mean_concentration";
      for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
          for (int k = 0; k < 2; ++k) g->getAccessor().setValue(openvdb::Coord(i, j, k), mean ? 0.3f : 0.0f);
      if (kind != nullptr) g->insertMeta("weft:value_kind", openvdb::StringMetadata(kind));
      grids.push_back(g);
    }
    openvdb::io::File file(dir + "/" + name);
    file.write(grids);
    file.close();
  };
  write_fields("uniform_fields.vdb", nullptr);
  write_fields("extinction_fields.vdb", "extinction");
  std::ofstream(dir + "/corrupt.vdb", std::ios::binary) << "this is not an OpenVDB file\n";
  return 0;
}
