// Wavefront OBJ statements, numbers and vertex references, shared by the yarn-curve and mesh loaders.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "weft/core/obj_text.h"

namespace weft {
namespace {

std::vector<ObjStatement> statements_of(const std::string& text) {
  std::vector<ObjStatement> out;
  ObjStatements reader(text);
  for (ObjStatement s; reader.next(s);) out.push_back(s);
  return out;
}

TEST(ObjText, CommentsRunToTheEndOfTheLineWhereverTheyStart) {
  const auto s = statements_of("# header\n\nv 1 2 3 # a vertex\n  # indented\nl 1 2#tight\n");
  ASSERT_EQ(s.size(), 2U);
  EXPECT_EQ(s[0].tag, "v");
  EXPECT_EQ(s[0].args, (std::vector<std::string>{"1", "2", "3"}));
  EXPECT_EQ(s[0].line, 3U);
  EXPECT_EQ(s[1].tag, "l");
  EXPECT_EQ(s[1].args, (std::vector<std::string>{"1", "2"}));
  EXPECT_EQ(s[1].line, 5U);
}

TEST(ObjText, ABackslashContinuesTheLine) {
  const auto s = statements_of("l 1 2 \\\r\n  3\\\n4\nv 0 0 0");
  ASSERT_EQ(s.size(), 2U);
  EXPECT_EQ(s[0].args, (std::vector<std::string>{"1", "2", "3", "4"}));
  EXPECT_EQ(s[0].line, 1U);
  EXPECT_EQ(s[1].line, 4U);  // numbering counts the continued lines
  EXPECT_EQ(s[1].args.size(), 3U);
}

TEST(ObjText, NumbersTakeALeadingPlusAndMustBeFinite) {
  EXPECT_EQ(obj_number("+3e-3"), 3e-3);
  EXPECT_EQ(obj_number("-0.5"), -0.5);
  EXPECT_FALSE(obj_number("+-1"));
  EXPECT_FALSE(obj_number("nan"));
  EXPECT_FALSE(obj_number("inf"));
  EXPECT_FALSE(obj_number("1,5"));
  EXPECT_FALSE(obj_number(""));
}

TEST(ObjText, VertexReferencesCountFromOneOrBackFromTheLast) {
  EXPECT_EQ(obj_vertex("1", 3), 0U);
  EXPECT_EQ(obj_vertex("3/7/2", 3), 2U);
  EXPECT_EQ(obj_vertex("-1//4", 3), 2U);
  long long spelled = 0;
  EXPECT_FALSE(obj_vertex("4", 3, &spelled));
  EXPECT_EQ(spelled, 4);  // out of range: the number is there to name
  spelled = 0;
  EXPECT_FALSE(obj_vertex("x", 3, &spelled));
  EXPECT_EQ(spelled, 0);
  EXPECT_FALSE(obj_vertex("0", 3));
}

}  // namespace
}  // namespace weft
