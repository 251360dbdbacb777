#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <string>

#include <fmt/format.h>

#include "error_matchers.h"
#include "weft/core/error.h"
#include "weft/curves/curve_io.h"

namespace weft::curves {
namespace {
namespace fs = std::filesystem;

class CurveFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("weft_curves_io_" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path dir_;
};

std::vector<Curve> sample_curves() {
  Curve open;
  for (int i = 0; i < 17; ++i) open.points.push_back({0.1 * i, std::sin(0.3 * i), -0.25 + 0.01 * i});
  Curve closed;
  for (int i = 0; i < 9; ++i) closed.points.push_back({std::cos(0.7 * i), std::sin(0.7 * i), 2.0});
  closed.closed = true;
  return {open, closed};
}

void expect_same(const std::vector<Curve>& a, const std::vector<Curve>& b, double tol) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t c = 0; c < a.size(); ++c) {
    ASSERT_EQ(a[c].closed, b[c].closed) << c;
    ASSERT_EQ(a[c].points.size(), b[c].points.size()) << c;
    for (std::size_t i = 0; i < a[c].points.size(); ++i) {
      for (int k = 0; k < 3; ++k) ASSERT_NEAR(a[c].points[i][k], b[c].points[i][k], tol) << c << " " << i;
    }
  }
}

std::string bytes_of(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
void write_bytes(const fs::path& p, const std::string& b) {
  std::ofstream out(p, std::ios::binary);
  out.write(b.data(), static_cast<std::streamsize>(b.size()));
}

TEST_F(CurveFiles, BccRoundTripKeepsPointsToFloatPrecision) {
  const auto curves = sample_curves();
  write_bcc(dir_ / "c.bcc", curves);
  const std::string b = bytes_of(dir_ / "c.bcc");
  ASSERT_EQ(b.size(), 64U + 2 * 4 + (17 + 9) * 12);
  EXPECT_EQ(b.substr(0, 3), "BCC");
  EXPECT_EQ(static_cast<unsigned char>(b[3]), 0x44);
  EXPECT_EQ(b.substr(4, 2), "PL");
  expect_same(curves, read_bcc(dir_ / "c.bcc"), 1e-6);
}

TEST_F(CurveFiles, BccBytesParseToTheSameCurvesAsTheFile) {
  const auto curves = sample_curves();
  const std::string bytes = bcc_bytes(curves, "in memory");
  write_bcc(dir_ / "c.bcc", curves, "in memory");
  EXPECT_EQ(bytes, bytes_of(dir_ / "c.bcc"));
  expect_same(read_bcc(dir_ / "c.bcc"), parse_bcc(bytes, "mem"), 0.0);
  EXPECT_EQ(bytes.substr(24, 9), "in memory");
}

TEST_F(CurveFiles, BccErrorsFromBytesStartWithTheGivenName) {
  EXPECT_THAT([] { parse_bcc(std::string_view("BCCD", 4), "yarns-in-memory"); },
              ::testing::ThrowsMessage<Error>(::testing::StartsWith("yarns-in-memory: truncated")));
  // An empty collection is valid: header only.
  EXPECT_TRUE(parse_bcc(bcc_bytes({}), "empty").empty());
}

TEST_F(CurveFiles, BccCatmullRomPassesThroughControlPoints) {
  // A C0 file by hand: one open curve of 4 control points.
  const std::vector<Point3> control = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {2, 1, 1}};
  std::string b = "BCC";
  b.push_back(static_cast<char>(0x44));
  b += "C0";
  b.push_back(3);
  b.push_back(2);
  const auto put64 = [&](std::uint64_t v) {
    for (int i = 0; i < 8; ++i) b.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  const auto put32 = [&](std::uint32_t v) {
    for (int i = 0; i < 4; ++i) b.push_back(static_cast<char>((v >> (8 * i)) & 0xFF));
  };
  put64(1);
  put64(4);
  b += std::string(40, '\0');
  put32(4);
  for (const auto& p : control) {
    for (double v : p) put32(std::bit_cast<std::uint32_t>(static_cast<float>(v)));
  }
  write_bytes(dir_ / "cr.bcc", b);
  const auto curves = read_bcc(dir_ / "cr.bcc", 8);
  ASSERT_EQ(curves.size(), 1U);
  ASSERT_EQ(curves[0].points.size(), 3U * 8U + 1U);
  for (std::size_t k = 0; k < control.size(); ++k) {
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(curves[0].points[k * 8][a], control[k][a], 1e-12);
  }
  // Mid-span of a uniform Catmull–Rom spline: (−P0 + 9P1 + 9P2 − P3)/16, off the chord in z.
  EXPECT_NEAR(curves[0].points[12][2], -1.0 / 16.0, 1e-7);
  EXPECT_NEAR(curves[0].points[12][1], 0.5, 1e-7);
}

struct Corruption {
  const char* name;
  std::function<void(std::string&)> damage;
  const char* expected;  // part of the message
};

TEST_F(CurveFiles, BccCountsThatDoNotFitSayWhatTheyTakeAndWhatTheFileHas) {
  const std::string header = bcc_bytes({}, "").substr(0, 64);
  const auto with_counts = [&](std::uint64_t curves, std::uint64_t points) {
    std::string b = header;
    std::memcpy(&b[8], &curves, 8);
    std::memcpy(&b[16], &points, 8);
    try {
      (void)parse_bcc(b + std::string(20, '\0'), "h.bcc");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string m = with_counts(1, 99);
  EXPECT_NE(m.find(fmt::format("1 curves and 99 points, which take {} bytes", 1 * 4 + 99 * 12)), std::string::npos)
      << m;
  EXPECT_NE(m.find("the file has 20"), std::string::npos) << m;
  const std::string huge = with_counts(std::numeric_limits<std::uint64_t>::max(), 1);
  EXPECT_NE(huge.find("take more than 18446744073709551615 bytes"), std::string::npos) << huge;
}

TEST_F(CurveFiles, CorruptBccFilesAreRejectedWithTheirName) {
  write_bcc(dir_ / "good.bcc", sample_curves());
  const std::string good = bytes_of(dir_ / "good.bcc");
  const std::vector<Corruption> cases = {
      {"signature", [](std::string& b) { b[1] = 'X'; }, "signature"},
      {"element_sizes", [](std::string& b) { b[3] = 0x48; }, "element sizes"},
      {"curve_type",
       [](std::string& b) {
         b[4] = 'B';
         b[5] = 'Z';
       },
       "curve type"},
      {"dimensions", [](std::string& b) { b[6] = 2; }, "dimensions"},
      {"truncated_header", [](std::string& b) { b.resize(40); }, "truncated"},
      {"truncated_body", [](std::string& b) { b.resize(b.size() - 5); }, "bytes"},
      {"trailing_bytes", [](std::string& b) { b += "junk"; }, "bytes"},
      {"huge_counts", [](std::string& b) { std::memset(&b[8], 0x7f, 16); }, "declares"},
      {"curve_overflows", [](std::string& b) { b[64] = 100; }, "points"},
      {"nan_point",
       [](std::string& b) {
         const auto nan = std::bit_cast<std::uint32_t>(std::numeric_limits<float>::quiet_NaN());
         std::memcpy(&b[68], &nan, 4);
       },
       "not finite"},
  };
  for (const auto& c : cases) {
    std::string b = good;
    c.damage(b);
    const fs::path p = dir_ / (std::string(c.name) + ".bcc");
    write_bytes(p, b);
    EXPECT_THAT([&] { read_bcc(p); }, weft::test::throws_one_line_error_with({p.string(), c.expected})) << c.name;
  }
  EXPECT_THROW(read_bcc(dir_ / "missing.bcc"), Error);
}

TEST_F(CurveFiles, ObjRoundTripIsExact) {
  const auto curves = sample_curves();
  write_obj_curves(dir_ / "c.obj", curves);
  expect_same(curves, read_obj_curves(dir_ / "c.obj"), 0.0);
  expect_same(curves, read_curves(dir_ / "c.obj"), 0.0);
}

TEST_F(CurveFiles, ObjEdgeByEdgeExportChainsIntoOnePolyline) {
  write_bytes(dir_ / "edges.obj",
              "# edges\nv 0 0 0\nv 1 0 0\nv 2 0 0\nv 3 1 0\nv 9 9 9\nv 8 8 8\nl 1 2\nl 2 3\nl 3 4\nl -1 -2\n");
  const auto curves = read_obj_curves(dir_ / "edges.obj");
  ASSERT_EQ(curves.size(), 2U);
  EXPECT_EQ(curves[0].points.size(), 4U);
  EXPECT_EQ(curves[0].points[3][1], 1.0);
  EXPECT_EQ(curves[1].points[0][0], 8.0);
}

TEST_F(CurveFiles, ObjSignedNumbersTrailingCommentsAndContinuationsAreRead) {
  // All valid OBJ: a '+' sign, a comment after an element, a line continued with a backslash.
  write_bytes(dir_ / "forms.obj", "v +3e-3 0 0\nv 1 +0 0 # second\nv 2 \\\n 1 0\nl 1 2 \\\n 3 # the yarn\n");
  const auto curves = read_obj_curves(dir_ / "forms.obj");
  ASSERT_EQ(curves.size(), 1U);
  ASSERT_EQ(curves[0].points.size(), 3U);
  EXPECT_EQ(curves[0].points[0][0], 3e-3);
  EXPECT_EQ(curves[0].points[2][1], 1.0);
}

TEST_F(CurveFiles, CorruptObjFilesAreRejected) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"v 0 0 0\nv 1 1 1\nl 1 3\n", "out of range"},
      {"v 0 0 0\nv 1 1\nl 1 2\n", "3 coordinates"},
      {"v 0 0 0\nv 1 1 zz\nl 1 2\n", "not a finite number"},
      {"v 0 0 0\nv 1 1 1\n", "no polylines"},
      {"v 0 0 0\nv 1 1 1\nl 1\n", "at least 2"},
      {"v 0 0 0\nv 1 1 1\nl 1 x\n", "vertex index"},
      {"v 0 0 0\nv 1 1 nan\nl 1 2\n", "not a finite number"},
      {"v 0 0 0\nv 1 1 1\nl 1 2\nv 3 3", "3 coordinates"},  // truncated mid-line
  };
  int n = 0;
  for (const auto& [text, expected] : cases) {
    const fs::path p = dir_ / ("bad" + std::to_string(n++) + ".obj");
    write_bytes(p, text);
    EXPECT_THAT([&] { read_obj_curves(p); }, weft::test::throws_one_line_error_with({expected, p.string()})) << text;
  }
  EXPECT_THROW(read_curves(dir_ / "missing.obj"), Error);
  EXPECT_THROW(read_curves(dir_ / "curves.txt"), Error);
}

}  // namespace
}  // namespace weft::curves
