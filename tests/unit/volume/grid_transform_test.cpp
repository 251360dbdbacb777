// A grid's transform must be a positive uniform scale plus a translation (docs/scene-format.md,
// "Grid media"): weft lays voxels out as origin + h·(i, j, k), so a rotated, mirrored or sheared
// file is refused in one line naming the file, the grid and what the transform does, rather than
// read as axis-aligned; a matrix within floating-point noise of that still loads.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>

#include "error_matchers.h"
#include "weft/volume/grid.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::volume {
namespace {

using test::throws_one_line_error_with;

constexpr double kH = 0.25;

/// A 2³ block of C = 1 under `transform`, written to a temporary .vdb; its path.
std::filesystem::path write_grid(const std::string& stem, const openvdb::math::Transform::Ptr& transform) {
  ensure_openvdb_initialized();
  auto grid = openvdb::FloatGrid::create(0.0F);
  grid->setName("density");
  for (int i = 0; i < 2; ++i) {
    for (int j = 0; j < 2; ++j) {
      for (int k = 0; k < 2; ++k) grid->getAccessor().setValue(openvdb::Coord(i, j, k), 1.0F);
    }
  }
  grid->setTransform(transform);
  auto path = std::filesystem::temp_directory_path() / ("weft_grid_transform_" + stem + ".vdb");
  openvdb::io::File file(path.string());
  file.write({grid});
  file.close();
  return path;
}

/// The linear transform of the 3×3 matrix `m` (rows are the images of the index axes) plus a
/// translation, as a file written by another tool holds it.
openvdb::math::Transform::Ptr linear(const openvdb::math::Mat3d& m, const openvdb::Vec3d& translation) {
  openvdb::math::Mat4d mat = openvdb::math::Mat4d::identity();
  mat.setMat3(m);
  mat.setTranslation(translation);
  return openvdb::math::Transform::createLinearTransform(mat);
}

openvdb::math::Transform::Ptr rotated_about_z(double angle) {
  auto t = openvdb::math::Transform::createLinearTransform(kH);
  t->postRotate(angle, openvdb::math::Z_AXIS);
  return t;
}

TEST(GridTransform, ARotationIsRefused) {
  // 45° (the tester's file) and 180° about z: the second is diagonal, its entries -h, -h, h.
  for (const double angle : {std::numbers::pi / 4.0, std::numbers::pi}) {
    const auto path = write_grid("rotated", rotated_about_z(angle));
    EXPECT_THAT([&] { (void)Grid::load(path); },
                throws_one_line_error_with({path.string(), "grid 'density'", "its transform rotates the voxels",
                                            "weft needs axis-aligned voxels"}))
        << angle;
    std::filesystem::remove(path);
  }
}

TEST(GridTransform, AMirrorIsRefused) {
  // A negative scale along one axis (OpenVDB simplifies it to a ScaleMap), and along all three
  // with a translation.
  const auto one_axis = linear(openvdb::math::Mat3d(-kH, 0.0, 0.0, 0.0, kH, 0.0, 0.0, 0.0, kH), {0.0, 0.0, 0.0});
  const auto all_axes = linear(openvdb::math::Mat3d(-kH, 0.0, 0.0, 0.0, -kH, 0.0, 0.0, 0.0, -kH), {1.0, 2.0, 3.0});
  for (const auto& transform : {one_axis, all_axes}) {
    const auto path = write_grid("mirror", transform);
    EXPECT_THAT([&] { (void)Grid::load(path); },
                throws_one_line_error_with({path.string(), "grid 'density'", "mirrors the voxels"}));
    std::filesystem::remove(path);
  }
}

TEST(GridTransform, AShearIsRefused) {
  // The y axis leans 30° towards x: every index axis still has length h, so the voxel-size
  // check alone would let it through.
  const double s = kH * std::sin(std::numbers::pi / 6.0);
  const double c = kH * std::cos(std::numbers::pi / 6.0);
  const auto path =
      write_grid("shear", linear(openvdb::math::Mat3d(kH, 0.0, 0.0, s, c, 0.0, 0.0, 0.0, kH), {0.0, 0.0, 0.0}));
  EXPECT_THAT([&] { (void)Grid::load(path); },
              throws_one_line_error_with({path.string(), "grid 'density'", "shears the voxels"}));
  std::filesystem::remove(path);
}

TEST(GridTransform, FloatingPointNoiseStillLoads) {
  // A rotation by 1e-12 rad (a file's matrix rounded on its way through another tool) loads with
  // the voxel size and origin of the unrotated grid; one by 1e-6 rad is a rotation.
  const auto path = write_grid("noise", rotated_about_z(1e-12));
  const Grid g = Grid::load(path);
  EXPECT_NEAR(g.voxel_size(), kH, 1e-12);
  for (const double o : g.origin()) EXPECT_NEAR(o, -0.5 * kH, 1e-12);
  EXPECT_EQ(g.value(1, 1, 1), 1.0F);
  std::filesystem::remove(path);
  const auto turned = write_grid("turned", rotated_about_z(1e-6));
  EXPECT_THAT([&] { (void)Grid::load(turned); }, throws_one_line_error_with({"rotates the voxels"}));
  std::filesystem::remove(turned);
}

TEST(GridTransform, AWrappedOpenVdbGridIsCheckedToo) {
  // The Python bindings and weft's own passes hand OpenVDB grids over through wrap_openvdb.
  ensure_openvdb_initialized();
  auto grid = openvdb::FloatGrid::create(0.0F);
  grid->setName("density");
  grid->setTransform(rotated_about_z(std::numbers::pi / 4.0));
  EXPECT_THAT([&] { (void)wrap_openvdb(grid); }, throws_one_line_error_with({"grid 'density'", "rotates the voxels"}));
}

}  // namespace
}  // namespace weft::volume
