#include <gtest/gtest.h>

#include <filesystem>

#include "data_gen/cloth/fibers.h"
#include "data_gen/cloth/yarn.h"
#include "weft/curves/curve_io.h"

namespace weft::cloth {
namespace {
namespace fs = std::filesystem;

TEST(FiberCurves, BccRoundTripOfGeneratedFibresKeepsFloatPrecision) {
  YarnParams y = yarn_preset("cotton");
  Curve c;
  c.points = {{0, 0, 0}, {0.5, 0.1, 0.0}, {1.0, 0.0, 0.05}};
  const FiberSet f = yarn_fibers(c, y, 11, 0);
  const auto curves = fiber_curves(f);
  ASSERT_EQ(curves.size(), f.size());
  const fs::path p = fs::temp_directory_path() / "weft_fiber_curves_roundtrip.bcc";
  curves::write_bcc(p, curves);
  const auto back = curves::read_bcc(p);
  fs::remove(p);
  ASSERT_EQ(back.size(), curves.size());
  for (std::size_t i = 0; i < curves.size(); ++i) {
    ASSERT_EQ(back[i].points.size(), curves[i].points.size());
    EXPECT_FALSE(back[i].closed);
    for (std::size_t k = 0; k < curves[i].points.size(); ++k) {
      for (int a = 0; a < 3; ++a) ASSERT_NEAR(back[i].points[k][a], curves[i].points[k][a], 2e-7);
    }
  }
}

}  // namespace
}  // namespace weft::cloth
