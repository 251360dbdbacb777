// file_kind names what a file's first bytes look like, for loaders handed the wrong kind of file.
#include <gtest/gtest.h>

#include <string>

#include "weft/core/file_kind.h"

namespace weft {
namespace {

TEST(FileKind, RecognisesTheFormatsWeftReadsAndWrites) {
  EXPECT_EQ(file_kind(std::string_view(" BDV\0\0\0\0", 8)), "an OpenVDB grid file");
  EXPECT_EQ(file_kind(std::string_view("BCC\x44PL\x03\0", 8)), "a BCC curve file");
  EXPECT_EQ(file_kind("\x89PNG\r\n\x1a\n"), "a PNG image");
  EXPECT_EQ(file_kind(std::string_view("\x76\x2f\x31\x01\x02\0\0\0", 8)), "an OpenEXR image");
  EXPECT_EQ(file_kind("  \n{\"pattern\": \"plain\"}"), "a JSON text (an object)");
  EXPECT_EQ(file_kind("[1, 2]"), "a JSON text (an array)");
  EXPECT_EQ(file_kind("# yarns\nv 0 0 0\nv 1 0 0\nl 1 2\n"), "a Wavefront OBJ text");
  EXPECT_EQ(file_kind("t,T\n0,1\n"), "a CSV text");
  EXPECT_EQ(file_kind("<?xml version=\"1.0\"?>\n<VTKFile type=\"PolyData\">"), "a VTK XML file");
  EXPECT_EQ(file_kind("ply\nformat ascii 1.0\n"), "a PLY mesh");
  EXPECT_EQ(file_kind("hello world\n"), "a text file");
  EXPECT_EQ(file_kind(""), "an empty file");
  EXPECT_EQ(file_kind(std::string_view("\x01\x02\0\x03", 4)), "a binary file");
}

TEST(FileKind, JsonTestSkipsLeadingWhiteSpace) {
  EXPECT_TRUE(looks_like_json(" \n\t{"));
  EXPECT_TRUE(looks_like_json("["));
  EXPECT_FALSE(looks_like_json(" BDV"));
  EXPECT_FALSE(looks_like_json(""));
}

TEST(FileKind, AUtf8ByteOrderMarkIsSkippedOnce) {
  EXPECT_EQ(skip_utf8_bom("\xEF\xBB\xBF{}"), "{}");
  EXPECT_EQ(skip_utf8_bom("{}"), "{}");
  EXPECT_EQ(skip_utf8_bom("\xEF\xBB"), "\xEF\xBB");  // a mark cut short is not one
  EXPECT_EQ(skip_utf8_bom("\xEF\xBB\xBF\xEF\xBB\xBF{"), "\xEF\xBB\xBF{");
  EXPECT_TRUE(looks_like_json("\xEF\xBB\xBF\n {"));
  EXPECT_FALSE(looks_like_json("\xEF\xBB\xBF"));
}

TEST(FileKind, UnreadablePathIsSaidSo) { EXPECT_EQ(file_kind_at("/nonexistent/weft/file"), "an unreadable file"); }

}  // namespace
}  // namespace weft
