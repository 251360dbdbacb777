#include "weft/viz/display.h"

#include <cstdlib>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <vtkNew.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>

#include "image_probe.h"
#include "weft/core/fp_hold.h"

namespace weft::viz {
namespace {

// Runs in a fresh process (threadsafe death-test style re-executes the binary), so the
// once-per-process display is set up from scratch with $DISPLAY unset.
[[noreturn]] void start_without_display_and_render(const std::string& record) {
  ::unsetenv("DISPLAY");
  std::string why;
  if (!ensure_display(&why)) {
    std::fprintf(stderr, "ensure_display failed: %s\n", why.c_str());
    std::exit(2);
  }
  const char* display = std::getenv("DISPLAY");
  if (display == nullptr) std::exit(3);
  std::ofstream(record) << display << "\n";
  vtkNew<vtkRenderWindow> window;
  window->SetOffScreenRendering(1);
  window->SetSize(64, 48);
  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(1.0, 0.0, 0.0);
  window->AddRenderer(renderer);
  const weft::HeldFpExceptions hold;  // Mesa's software rasterizer computes with NaN on purpose
  window->Render();
  vtkNew<vtkUnsignedCharArray> pixels;
  window->GetPixelData(0, 0, 63, 47, 0, pixels);
  const unsigned char* p = pixels->GetPointer(3 * (24 * 64 + 32));
  if (p[0] < 250 || p[1] > 5 || p[2] > 5) {
    std::fprintf(stderr, "centre pixel is %d %d %d, expected red\n", p[0], p[1], p[2]);
    std::exit(4);
  }
  std::exit(0);
}

TEST(Display, StartsPrivateXvfbWhenDisplayUnsetAndStopsItAtExit) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  // The child re-runs this body in a new process: it finds the record path in the environment.
  if (std::getenv("WEFT_VIZ_TEST_DISPLAY_RECORD") == nullptr) {
    ::setenv("WEFT_VIZ_TEST_DISPLAY_RECORD", test::scratch_dir("display").append("display.txt").c_str(), 1);
  }
  const std::filesystem::path record = std::getenv("WEFT_VIZ_TEST_DISPLAY_RECORD");
  const auto dir = record.parent_path();
  EXPECT_EXIT(start_without_display_and_render(record.string()), ::testing::ExitedWithCode(0), "");
  std::ifstream in(record);
  std::string name;
  ASSERT_TRUE(std::getline(in, name)) << "the child recorded no display";
  ASSERT_GT(name.size(), 1U);
  EXPECT_EQ(name[0], ':');
  // Xvfb removes its lock file when it terminates; the child waited for that at exit.
  EXPECT_FALSE(std::filesystem::exists("/tmp/.X" + name.substr(1) + "-lock"))
      << "Xvfb on " << name << " outlived its process";
  test::cleanup(dir);
}

[[noreturn]] void try_without_xvfb() {
  ::unsetenv("DISPLAY");
  ::setenv("PATH", "/nonexistent-weft-test-path", 1);
  std::string why;
  const bool ok = ensure_display(&why);
  std::fprintf(stderr, "reason: %s\n", why.c_str());
  std::exit(!ok && why.find("Xvfb") != std::string::npos && why.find('\n') == std::string::npos ? 0 : 1);
}

TEST(Display, ReportsWhyWhenXvfbIsMissing) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(try_without_xvfb(), ::testing::ExitedWithCode(0), "reason: .*Xvfb is not installed");
}

[[noreturn]] void replace_dead_display() {
  ::setenv("DISPLAY", ":4711", 1);  // nothing listens there
  std::string why;
  if (!ensure_display(&why)) std::exit(2);
  const std::string now = std::getenv("DISPLAY");
  std::exit(now != ":4711" ? 0 : 3);
}

TEST(Display, ReplacesUnreachableDisplay) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  EXPECT_EXIT(replace_dead_display(), ::testing::ExitedWithCode(0), "");
}

TEST(Display, ConcurrentCallersShareOneDisplay) {
  constexpr int kThreads = 4;
  std::vector<int> ok(kThreads, -1);
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) {
    threads.emplace_back([&ok, t] { ok[static_cast<std::size_t>(t)] = ensure_display(nullptr) ? 1 : 0; });
  }
  for (auto& th : threads) th.join();
  for (int t = 1; t < kThreads; ++t) EXPECT_EQ(ok[static_cast<std::size_t>(t)], ok[0]);
  ASSERT_EQ(ok[0], 1) << "this machine has Xvfb (docs/architecture.md §9), so a display must be available";
  const std::string first = std::getenv("DISPLAY");
  EXPECT_TRUE(ensure_display(nullptr));
  EXPECT_EQ(std::string(std::getenv("DISPLAY")), first);
}

}  // namespace
}  // namespace weft::viz
