#include "weft/viz/vtk_files.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkImageData.h>
#include <vtkLZ4DataCompressor.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkXMLImageDataReader.h>
#include <vtkXMLImageDataWriter.h>
#include <vtkXMLPolyDataReader.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

#include "image_probe.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"
#include "weft/volume/grid_openvdb.h"

namespace weft::viz {
namespace {

std::size_t entries(const std::filesystem::path& dir) {
  return static_cast<std::size_t>(std::distance(std::filesystem::directory_iterator(dir), {}));
}

PolylineSet two_polylines() {
  PolylineSet lines;
  lines.points = {{0, 0, 0}, {1, 0, 0}, {2, 0.5, 0}, {0, 1, 1}, {0, 2, 1.5}};
  lines.offsets = {0, 3, 5};
  lines.cell_ints["yarn"] = {7, -3};
  lines.cell_scalars["radius"] = {0.125, 0.25};
  lines.point_scalars["arc_length"] = {0.0, 1.0, 2.1, 0.0, 1.1};
  return lines;
}

TEST(VtkFiles, PolylinesRoundTripThroughVtkReader) {
  const auto dir = test::scratch_dir("vtp_lines");
  const auto file = dir / "fibres.vtp";
  const PolylineSet lines = two_polylines();
  write_vtp(lines, file);
  // Appended, zlib-compressed binary, as ParaView writes it.
  std::ifstream in(file, std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(text.find("vtkZLibDataCompressor"), std::string::npos);
  EXPECT_NE(text.find("<AppendedData encoding=\"raw\">"), std::string::npos);

  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkPolyData* poly = reader->GetOutput();
  ASSERT_EQ(poly->GetNumberOfPoints(), 5);
  ASSERT_EQ(poly->GetNumberOfLines(), 2);
  for (vtkIdType i = 0; i < 5; ++i) {
    double p[3];
    poly->GetPoint(i, p);
    for (int a = 0; a < 3; ++a)
      EXPECT_DOUBLE_EQ(p[a], lines.points[static_cast<std::size_t>(i)][static_cast<std::size_t>(a)]);
  }
  vtkNew<vtkIdList> ids;
  poly->GetLines()->GetCellAtId(1, ids);
  ASSERT_EQ(ids->GetNumberOfIds(), 2);
  EXPECT_EQ(ids->GetId(0), 3);
  EXPECT_EQ(ids->GetId(1), 4);
  vtkDataArray* yarn = poly->GetCellData()->GetArray("yarn");
  ASSERT_NE(yarn, nullptr);
  EXPECT_EQ(yarn->GetDataType(), VTK_INT);
  EXPECT_EQ(yarn->GetTuple1(0), 7);
  EXPECT_EQ(yarn->GetTuple1(1), -3);
  vtkDataArray* radius = poly->GetCellData()->GetArray("radius");
  ASSERT_NE(radius, nullptr);
  EXPECT_DOUBLE_EQ(radius->GetTuple1(1), 0.25);
  vtkDataArray* s = poly->GetPointData()->GetArray("arc_length");
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->GetDataType(), VTK_DOUBLE);
  EXPECT_DOUBLE_EQ(s->GetTuple1(2), 2.1);
  EXPECT_EQ(entries(dir), 1U) << "a temporary file was left behind";
  test::cleanup(dir);
}

TEST(VtkFiles, PointsRoundTripAsVertices) {
  const auto dir = test::scratch_dir("vtp_points");
  const auto file = dir / "particles.vtp";
  PointSet pts;
  pts.points = {{0, 0, 0}, {1, 2, 3}, {-1, 0.5, 4}};
  pts.point_scalars["radius"] = {0.1, 0.2, 0.3};
  write_vtp(pts, file);
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkPolyData* poly = reader->GetOutput();
  ASSERT_EQ(poly->GetNumberOfPoints(), 3);
  EXPECT_EQ(poly->GetNumberOfVerts(), 3);
  double p[3];
  poly->GetPoint(2, p);
  EXPECT_DOUBLE_EQ(p[0], -1.0);
  EXPECT_DOUBLE_EQ(p[2], 4.0);
  ASSERT_NE(poly->GetPointData()->GetArray("radius"), nullptr);
  EXPECT_DOUBLE_EQ(poly->GetPointData()->GetArray("radius")->GetTuple1(1), 0.2);
  test::cleanup(dir);
}

// vtp_bytes (sim2d makes its particles' file in memory beside the units) is the file write_vtp
// writes, byte for byte, and refuses what write_vtp refuses.
TEST(VtkFiles, PointBytesAreTheWrittenFile) {
  const auto dir = test::scratch_dir("vtp_bytes");
  const auto file = dir / "particles.vtp";
  PointSet pts;
  for (int i = 0; i < 5000; ++i) pts.points.push_back({0.001 * i, std::sin(0.01 * i), 0.0});
  pts.point_scalars["radius"] = std::vector<double>(pts.points.size(), 0.25);
  pts.point_scalars["cluster"] = std::vector<double>(pts.points.size(), 3.0);
  write_vtp(pts, file);
  std::ifstream in(file, std::ios::binary);
  const std::string written((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::string bytes = vtp_bytes(pts, file);
  EXPECT_GT(bytes.size(), 1000U);
  EXPECT_TRUE(bytes == written) << "vtp_bytes " << bytes.size() << " bytes, write_vtp " << written.size();
  pts.point_scalars["r"] = {};
  EXPECT_THROW((void)vtp_bytes(pts, file), weft::Error);
  test::cleanup(dir);
}

TEST(VtkFiles, InconsistentPolylinesAreRejectedWithoutAFile) {
  const auto dir = test::scratch_dir("vtp_bad");
  const auto file = dir / "bad.vtp";
  PolylineSet wrong_count = two_polylines();
  wrong_count.cell_scalars["radius"] = {0.1};
  EXPECT_THROW(write_vtp(wrong_count, file), weft::Error);
  PolylineSet bad_offsets = two_polylines();
  bad_offsets.offsets = {0, 3, 4};
  EXPECT_THROW(write_vtp(bad_offsets, file), weft::Error);
  PolylineSet clash = two_polylines();
  clash.cell_scalars["yarn"] = {1.0, 2.0};
  EXPECT_THROW(write_vtp(clash, file), weft::Error);
  PointSet pts;
  pts.points = {{0, 0, 0}};
  pts.point_scalars["r"] = {};
  EXPECT_THROW(write_vtp(pts, file), weft::Error);
  EXPECT_EQ(entries(dir), 0U);
  test::cleanup(dir);
}

TEST(VtkFiles, GridRoundTripsValuesAndWorldBounds) {
  const auto dir = test::scratch_dir("vti");
  const auto file = dir / "grid.vti";
  volume::Grid grid(0.5, "concentration");
  grid.set_origin({1.0, 2.0, 3.0});
  grid.set_value(2, 3, 4, 0.25f);
  grid.set_value(5, 3, 4, 0.5f);
  grid.set_value(2, 7, 6, 1.0f);
  write_vti(grid, file);

  vtkNew<vtkXMLImageDataReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkImageData* image = reader->GetOutput();
  int dims[3];
  image->GetDimensions(dims);
  // Box (2..5, 3..7, 4..6): 4x5x3 voxels, i.e. 5x6x4 points.
  EXPECT_EQ(dims[0], 5);
  EXPECT_EQ(dims[1], 6);
  EXPECT_EQ(dims[2], 4);
  double b[6];
  image->GetBounds(b);
  // Voxel i covers [origin + h·i, origin + h·(i+1)).
  EXPECT_DOUBLE_EQ(b[0], 1.0 + 0.5 * 2);
  EXPECT_DOUBLE_EQ(b[1], 1.0 + 0.5 * 6);
  EXPECT_DOUBLE_EQ(b[2], 2.0 + 0.5 * 3);
  EXPECT_DOUBLE_EQ(b[3], 2.0 + 0.5 * 8);
  EXPECT_DOUBLE_EQ(b[4], 3.0 + 0.5 * 4);
  EXPECT_DOUBLE_EQ(b[5], 3.0 + 0.5 * 7);
  vtkDataArray* values = image->GetCellData()->GetArray("concentration");
  ASSERT_NE(values, nullptr);
  ASSERT_EQ(values->GetNumberOfTuples(), 4 * 5 * 3);
  double sum = 0.0;
  for (vtkIdType c = 0; c < values->GetNumberOfTuples(); ++c) sum += values->GetTuple1(c);
  EXPECT_DOUBLE_EQ(sum, 1.75);
  // Find each voxel by the world position of its centre, as ParaView would.
  auto at = [&](int i, int j, int k) {
    double centre[3] = {1.0 + 0.5 * (i + 0.5), 2.0 + 0.5 * (j + 0.5), 3.0 + 0.5 * (k + 0.5)};
    int ijk[3];
    double pcoords[3];
    EXPECT_EQ(image->ComputeStructuredCoordinates(centre, ijk, pcoords), 1);
    return values->GetTuple1(image->ComputeCellId(ijk));
  };
  EXPECT_DOUBLE_EQ(at(2, 3, 4), 0.25);
  EXPECT_DOUBLE_EQ(at(5, 3, 4), 0.5);
  EXPECT_DOUBLE_EQ(at(2, 7, 6), 1.0);
  EXPECT_DOUBLE_EQ(at(3, 3, 4), 0.0);
  test::cleanup(dir);
}

TEST(VtkFiles, GridActiveTilesAreExpanded) {
  const auto dir = test::scratch_dir("vti_tiles");
  const auto file = dir / "tiles.vti";
  volume::Grid grid(1.0, "density");
  // An aligned 8³ block becomes an active tile, not 512 voxels.
  grid.impl().grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(7)), 0.75f, true);
  grid.set_value(8, 0, 0, 0.5f);
  ASSERT_GT(grid.impl().grid->tree().activeTileCount(), 0U);
  write_vti(grid, file);
  vtkNew<vtkXMLImageDataReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkDataArray* values = reader->GetOutput()->GetCellData()->GetArray("density");
  ASSERT_NE(values, nullptr);
  ASSERT_EQ(values->GetNumberOfTuples(), 9 * 8 * 8);
  double sum = 0.0;
  for (vtkIdType c = 0; c < values->GetNumberOfTuples(); ++c) sum += values->GetTuple1(c);
  EXPECT_DOUBLE_EQ(sum, 0.75 * 512 + 0.5);
  EXPECT_DOUBLE_EQ(values->GetTuple1(8), 0.5);  // voxel (8,0,0): x runs fastest
  test::cleanup(dir);
}

TEST(VtkFiles, GridWrittenInPiecesReadsBackAsTheSameImage) {
  // write_vti streams the box through VTK's pipeline in pieces (memory: one piece, not the dense
  // box); the file must read back as the image a single piece gives, tiles and voxels alike.
  const auto dir = test::scratch_dir("vti_pieces");
  volume::Grid grid(0.25, "density");
  grid.set_origin({-1.0, 0.5, 2.0});
  grid.impl().grid->tree().fill(openvdb::CoordBBox(openvdb::Coord(24, 16, 24), openvdb::Coord(31, 23, 31)), 0.5f, true);
  for (int n = 0; n < 200; ++n) grid.set_value((n * 7) % 23 - 3, (n * 5) % 17, (n * 3) % 29 - 4, 0.001f * n + 0.1f);
  ASSERT_GT(grid.impl().grid->tree().activeTileCount(), 0U);
  write_vti(grid, dir / "one.vti");
  write_vti(grid, dir / "pieces.vti", 256ULL << 20U, 500);
  const auto read = [](const std::filesystem::path& f) {
    vtkNew<vtkXMLImageDataReader> reader;
    reader->SetFileName(f.c_str());
    reader->Update();
    vtkSmartPointer<vtkImageData> image = reader->GetOutput();
    return image;
  };
  const auto one = read(dir / "one.vti");
  const auto pieces = read(dir / "pieces.vti");
  std::ifstream in(dir / "pieces.vti", std::ios::binary);
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  std::size_t count = 0;
  for (std::size_t at = text.find("<Piece"); at != std::string::npos; at = text.find("<Piece", at + 1)) ++count;
  EXPECT_GT(count, 10U);  // 35 x 24 x 36 voxels in pieces of <= 500
  int d1[3];
  int d2[3];
  one->GetDimensions(d1);
  pieces->GetDimensions(d2);
  for (int a = 0; a < 3; ++a) EXPECT_EQ(d1[a], d2[a]);
  double b1[6];
  double b2[6];
  one->GetBounds(b1);
  pieces->GetBounds(b2);
  for (int a = 0; a < 6; ++a) EXPECT_DOUBLE_EQ(b1[a], b2[a]);
  vtkDataArray* v1 = one->GetCellData()->GetArray("density");
  vtkDataArray* v2 = pieces->GetCellData()->GetArray("density");
  ASSERT_NE(v1, nullptr);
  ASSERT_NE(v2, nullptr);
  ASSERT_EQ(v1->GetNumberOfTuples(), v2->GetNumberOfTuples());
  double sum = 0.0;
  for (vtkIdType c = 0; c < v1->GetNumberOfTuples(); ++c) {
    ASSERT_EQ(v1->GetTuple1(c), v2->GetTuple1(c)) << c;
    sum += v2->GetTuple1(c);
  }
  EXPECT_NEAR(sum, grid.sum(), 1e-6 * grid.sum());
  test::cleanup(dir);
}

std::string file_bytes(const std::filesystem::path& f) {
  std::ifstream in(f, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

TEST(VtkFiles, GridCompressedOnAnyThreadCountIsVtksOwnFile) {
  // write_vti compresses each piece's LZ4 blocks on all threads before VTK's writer asks for
  // them: the file must be the one VTK writes alone (same blocks, same level), for any thread count.
  const auto dir = test::scratch_dir("vti_threads");
  volume::Grid grid(0.5, "density");
  // 70 x 40 x 30 voxels: 336 kB dense, about ten 32 kB blocks, values that compress unevenly.
  for (int k = 0; k < 30; ++k) {
    for (int j = 0; j < 40; ++j) {
      for (int i = 0; i < 70; ++i) {
        if ((i * 7 + j * 3 + k) % 5 != 0) grid.set_value(i, j, k, static_cast<float>(((i * j + k * 13) % 97) / 97.0));
      }
    }
  }
  {
    const ThreadLimit one(1);
    write_vti(grid, dir / "t1.vti");
    write_vti(grid, dir / "t1_pieces.vti", 256ULL << 20U, 20000);
  }
  {
    const ThreadLimit two(2);
    write_vti(grid, dir / "t2.vti");
    write_vti(grid, dir / "t2_pieces.vti", 256ULL << 20U, 20000);
  }
  EXPECT_EQ(file_bytes(dir / "t1.vti"), file_bytes(dir / "t2.vti"));
  EXPECT_EQ(file_bytes(dir / "t1_pieces.vti"), file_bytes(dir / "t2_pieces.vti"));
  // The same image written by VTK's writer with its own compressor, in one piece.
  vtkNew<vtkXMLImageDataReader> reader;
  reader->SetFileName((dir / "t2.vti").c_str());
  reader->Update();
  ASSERT_EQ(reader->GetOutput()->GetCellData()->GetArray("density")->GetNumberOfTuples(), 70 * 40 * 30);
  vtkNew<vtkXMLImageDataWriter> plain;
  plain->SetInputData(reader->GetOutput());
  plain->SetDataModeToAppended();
  plain->EncodeAppendedDataOff();
  plain->SetCompressorTypeToLZ4();
  vtkLZ4DataCompressor::SafeDownCast(plain->GetCompressor())->SetAccelerationLevel(1);
  plain->SetFileName((dir / "plain.vti").c_str());
  ASSERT_EQ(plain->Write(), 1);
  const std::string ours = file_bytes(dir / "t2.vti");
  EXPECT_GT(ours.size(), 30000U);
  EXPECT_NE(ours.find("vtkLZ4DataCompressor"), std::string::npos);
  EXPECT_EQ(ours, file_bytes(dir / "plain.vti"));
  test::cleanup(dir);
}

TEST(VtkFiles, GridTooLargeOrEmptyIsAnErrorWithoutAFile) {
  const auto dir = test::scratch_dir("vti_bad");
  volume::Grid grid(1.0, "density");
  EXPECT_THROW(write_vti(grid, dir / "empty.vti"), weft::Error);
  grid.set_value(0, 0, 0, 1.0f);
  grid.set_value(99, 99, 99, 1.0f);
  EXPECT_THAT([&] { write_vti(grid, dir / "big.vti", 1000); },
              ::testing::ThrowsMessage<weft::Error>(::testing::HasSubstr("1000000")))
      << "a 100³ box against a 1000-voxel limit";
  EXPECT_EQ(entries(dir), 0U);
  test::cleanup(dir);
}

TEST(VtkFiles, UnwritableTargetThrowsAndLeavesNoFile) {
  const auto dir = test::scratch_dir("vtk_unwritable");
  EXPECT_THROW(write_vtp(two_polylines(), dir / "no-such-folder" / "a.vtp"), weft::Error);
  std::filesystem::create_directory(dir / "taken.vtp");
  EXPECT_THROW(write_vtp(two_polylines(), dir / "taken.vtp"), weft::Error);
  EXPECT_EQ(entries(dir), 1U);
  test::cleanup(dir);
}

}  // namespace
}  // namespace weft::viz
