#include "weft/render/image.h"

#include <algorithm>
#include <cmath>
#include <functional>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfThreading.h>
#include <tbb/blocked_range.h>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkUnsignedCharArray.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/parallel.h"

namespace weft::render {
namespace {

// Threads OpenEXR may compress on: TBB's limit (`--threads`), its global pool resized to it;
// 0 (the calling thread alone) under one thread.
int exr_threads() {
  const auto limit = static_cast<int>(tbb::global_control::active_value(tbb::global_control::max_allowed_parallelism));
  const int threads = limit > 1 ? limit : 0;
  if (Imf::globalThreadCount() != threads) Imf::setGlobalThreadCount(threads);
  return threads;
}

std::vector<unsigned char> srgb8_pixels(const Image& image, double exposure) {
  std::vector<unsigned char> rgb(image.rgb.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rgb.size(), 1U << 14U),
                    [&](const tbb::blocked_range<std::size_t>& r) {
                      for (std::size_t i = r.begin(); i != r.end(); ++i) rgb[i] = srgb8(image.rgb[i], exposure);
                    });
  return rgb;
}

/// An EXR holds finite values only (as weft.write_exr refuses non-finite arrays): the float mean of
/// finite double samples overflows to inf past 3.4e38, and an inf pixel written silently reads as
/// a broken render. Refused before any file is made, with the count.
void check_finite(const std::filesystem::path& path, const Image& image) {
  // A count (exact in any order), over the threads: it reads the whole film before the writes.
  const std::size_t pixels = image.rgb.size() / 3;
  const std::size_t bad = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, pixels, std::size_t{1} << 14U), std::size_t{0},
      [&](const tbb::blocked_range<std::size_t>& r, std::size_t count) {
        for (std::size_t q = r.begin(); q != r.end(); ++q) {
          const float* v = &image.rgb[3 * q];
          if (!std::isfinite(v[0]) || !std::isfinite(v[1]) || !std::isfinite(v[2])) ++count;
        }
        return count;
      },
      std::plus<>());
  if (bad > 0)
    fail(
        "cannot write EXR '{}': {} of {} pixels are not finite (a value beyond the float range, 3.4e38: lights or "
        "emission too strong); nothing written",
        path.string(), bad, image.rgb.size() / 3);
}

}  // namespace

void write_exr(const std::filesystem::path& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0) fail("cannot write empty image to '{}'", path.string());
  check_finite(path, image);
  write_atomically(path, [&](const std::filesystem::path& tmp) {
    try {
      Imf::Header header(image.width, image.height);
      const char* names[3] = {"R", "G", "B"};
      for (const char* n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
      // The ZIP blocks (16 rows each) are compressed on OpenEXR's pool, as many as weft's thread
      // limit; the file writes them in row order, so its bytes do not depend on the count.
      const int threads = exr_threads();
      Imf::OutputFile file(tmp.c_str(), header, threads);
      Imf::FrameBuffer fb;
      const std::size_t xs = 3 * sizeof(float);
      const std::size_t ys = xs * static_cast<std::size_t>(image.width);
      for (int c = 0; c < 3; ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT,
                                       const_cast<char*>(reinterpret_cast<const char*>(image.rgb.data() + c)), xs, ys));
      file.setFrameBuffer(fb);
      file.writePixels(image.height);
    } catch (const std::exception& e) {
      fail("cannot write EXR '{}': {}", path.string(), e.what());
    }
  });
}

Image read_exr(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) fail("EXR file '{}' does not exist", path.string());
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i dw = file.header().dataWindow();
    Image image;
    image.width = dw.max.x - dw.min.x + 1;
    image.height = dw.max.y - dw.min.y + 1;
    image.rgb.assign(static_cast<std::size_t>(image.width) * image.height * 3, 0.0f);
    Imf::FrameBuffer fb;
    const std::size_t xs = 3 * sizeof(float);
    const std::size_t ys = xs * static_cast<std::size_t>(image.width);
    char* base = reinterpret_cast<char*>(image.rgb.data()) -
                 (static_cast<std::ptrdiff_t>(dw.min.x) * xs + static_cast<std::ptrdiff_t>(dw.min.y) * ys);
    const char* names[3] = {"R", "G", "B"};
    for (int c = 0; c < 3; ++c) fb.insert(names[c], Imf::Slice(Imf::FLOAT, base + c * sizeof(float), xs, ys));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return image;
  } catch (const std::exception& e) {
    fail("cannot read EXR '{}': {}", path.string(), e.what());
  }
}

unsigned char srgb8(float linear, double exposure) {
  // IEC 61966-2-1 transfer curve.
  const double v = std::clamp(static_cast<double>(linear) * exposure, 0.0, 1.0);
  const double e = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
  return static_cast<unsigned char>(std::lround(255.0 * e));
}

void write_rgb8_png(const std::filesystem::path& path, int width, int height, const std::vector<unsigned char>& rgb) {
  if (width <= 0 || height <= 0) fail("cannot write empty image to '{}'", path.string());
  if (rgb.size() != static_cast<std::size_t>(width) * height * 3)
    fail("PNG '{}': {} bytes for a {}x{} RGB image", path.string(), rgb.size(), width, height);
  vtkNew<vtkImageData> data;
  data->SetDimensions(width, height, 1);
  data->AllocateScalars(VTK_UNSIGNED_CHAR, 3);
  auto* pixels = static_cast<unsigned char*>(data->GetScalarPointer());
  const auto row_bytes = static_cast<std::size_t>(width) * 3;
  for (int y = 0; y < height; ++y)  // VTK images start at the bottom row
    std::copy_n(&rgb[static_cast<std::size_t>(y) * row_bytes], row_bytes,
                &pixels[static_cast<std::size_t>(height - 1 - y) * row_bytes]);
  // Encoded in memory, then written through a checked stream: a full disk is one error naming
  // the file (write_stream_atomically), not that and libpng's and VTK's own lines on stderr.
  vtkNew<vtkPNGWriter> writer;
  writer->SetWriteToMemory(1);
  // zlib's fastest level, as for every picture weft writes (viz/vtk_support.cpp): the PNG is
  // the sRGB view of the EXR, and at VTK's default (5) its compression on one thread was the
  // longest serial stretch of a large film's render (docs/benchmarks.md "Threads").
  writer->SetCompressionLevel(1);
  writer->SetInputData(data);
  writer->Write();
  vtkUnsignedCharArray* png = writer->GetResult();
  if (writer->GetErrorCode() != 0 || png == nullptr || png->GetNumberOfValues() == 0)
    fail("cannot encode PNG '{}'", path.string());
  write_stream_atomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png->GetPointer(0)),
              static_cast<std::streamsize>(png->GetNumberOfValues()));
  });
}

void write_png(const std::filesystem::path& path, const Image& image, double exposure) {
  if (image.width <= 0 || image.height <= 0) fail("cannot write empty image to '{}'", path.string());
  write_rgb8_png(path, image.width, image.height, srgb8_pixels(image, exposure));
}

void write_exr_and_png(const std::filesystem::path& exr, const std::filesystem::path& png, const Image& image,
                       double exposure) {
  check_finite(exr, image);  // both files or neither
  // The sRGB codes first, on every thread (a pow per value: as long as the PNG's compression),
  // then the two files side by side.
  const std::vector<unsigned char> rgb = srgb8_pixels(image, exposure);
  parallel_units(2, [&](std::size_t i) {
    if (i == 0) {
      write_exr(exr, image);
    } else {
      write_rgb8_png(png, image.width, image.height, rgb);
    }
  });
}

double rmse(const Image& a, const Image& b) {
  if (a.width != b.width || a.height != b.height)
    fail("images differ in size: {}x{} vs {}x{}", a.width, a.height, b.width, b.height);
  double sum = 0.0;
  for (std::size_t i = 0; i < a.rgb.size(); ++i) {
    const double d = static_cast<double>(a.rgb[i]) - b.rgb[i];
    sum += d * d;
  }
  return a.rgb.empty() ? 0.0 : std::sqrt(sum / static_cast<double>(a.rgb.size()));
}

}  // namespace weft::render
