#include "weft/viz/vtk_support.h"

#include <algorithm>
#include <mutex>
#include <string>

#include <dlfcn.h>
#include <link.h>
#include <unistd.h>

#include <fmt/format.h>
#include <vtkFreeTypeTools.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkObjectFactory.h>
#include <vtkOutputWindow.h>
#include <vtkPNGWriter.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkSmartPointer.h>
#include <vtkStdString.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkWindowToImageFilter.h>

#include "weft/core/atomic_file.h"
#include "weft/core/error.h"
#include "weft/core/fp_hold.h"

namespace weft::viz::detail {
namespace {

std::mutex g_message_mutex;
std::string g_last_message;

#if defined(__SANITIZE_ADDRESS__)
// LeakSanitizer runs after libGL has dlclose'd Mesa's DRI driver, so every block the driver still
// pointed to (one per render window) reads as leaked from "<unknown module>" and cannot be
// suppressed by name. In sanitizer builds the driver is pinned (RTLD_NODELETE) once it is loaded.
void pin_gl_driver() {
  static std::once_flag once;
  std::call_once(once, [] {
    dl_iterate_phdr(
        [](dl_phdr_info* info, std::size_t, void*) {
          const std::string name = info->dlpi_name != nullptr ? info->dlpi_name : "";
          if (name.ends_with("_dri.so")) dlopen(name.c_str(), RTLD_LAZY | RTLD_NOLOAD | RTLD_NODELETE);
          return 0;
        },
        nullptr);
  });
}
#else
void pin_gl_driver() {}
#endif

// VTK reports through a process-wide output window; this one remembers instead of printing.
class BufferedOutputWindow : public vtkOutputWindow {
 public:
  static BufferedOutputWindow* New();
  vtkTypeMacro(BufferedOutputWindow, vtkOutputWindow)

      public : void DisplayText(const char* text) override {
    if (text == nullptr) return;
    std::string line(text);
    for (char& c : line) {
      if (c == '\n' || c == '\r') c = ' ';
    }
    while (!line.empty() && line.back() == ' ') line.pop_back();
    const std::lock_guard<std::mutex> lock(g_message_mutex);
    g_last_message = std::move(line);
  }
};
vtkStandardNewMacro(BufferedOutputWindow);

}  // namespace

void quiet_vtk_messages() {
  static std::once_flag once;
  std::call_once(once, [] {
    vtkNew<BufferedOutputWindow> window;
    vtkOutputWindow::SetInstance(window);
    // VTK 9 also logs errors to stderr through its own logger (loguru), besides the window.
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  });
}

std::string take_vtk_message() {
  const std::lock_guard<std::mutex> lock(g_message_mutex);
  std::string message;
  message.swap(g_last_message);
  return message;
}

void set_font(vtkTextProperty& text, int size, bool bold) {
  static const std::filesystem::path kDir = "/usr/share/fonts/truetype/dejavu";
  static const bool have_regular = std::filesystem::exists(kDir / "DejaVuSans.ttf");
  static const bool have_bold = std::filesystem::exists(kDir / "DejaVuSans-Bold.ttf");
  text.SetFontSize(size);
  if (bold ? have_bold : have_regular) {
    text.SetFontFamily(VTK_FONT_FILE);
    text.SetFontFile((kDir / (bold ? "DejaVuSans-Bold.ttf" : "DejaVuSans.ttf")).c_str());
    text.BoldOff();
  } else {
    text.SetBold(bold ? 1 : 0);
  }
}

std::string wrap_text(vtkTextProperty& text, const std::string& s, int max_width) {
  auto width_of = [&](const std::string& line) {
    int bbox[4] = {0, 0, 0, 0};
    if (!vtkFreeTypeTools::GetInstance()->GetBoundingBox(&text, vtkStdString(line), 72, bbox)) return 0;
    return bbox[1] - bbox[0];
  };
  std::string out;
  std::string line;
  std::size_t pos = 0;
  while (pos <= s.size()) {
    const std::size_t end = std::min(s.find(' ', pos), s.size());
    const std::string word = s.substr(pos, end - pos);
    const std::string candidate = line.empty() ? word : fmt::format("{} {}", line, word);
    if (!line.empty() && width_of(candidate) > max_width) {
      out += line + "\n";
      line = word;
    } else {
      line = candidate;
    }
    pos = end + 1;
  }
  return out + line;
}

void require_writable_folder(const std::filesystem::path& target) {
  const std::filesystem::path dir = target.has_parent_path() ? target.parent_path() : std::filesystem::path(".");
  std::error_code ec;
  if (!std::filesystem::is_directory(dir, ec))
    fail("{}: output folder '{}' does not exist", target.string(), dir.string());
  if (::access(dir.c_str(), W_OK) != 0) fail("{}: output folder '{}' is not writable", target.string(), dir.string());
}

void prepare_window(vtkRenderWindow& window, int width, int height) {
  window.SetOffScreenRendering(1);
  window.SetMultiSamples(0);
  window.SetSize(width, height);
}

void prepare_renderer(vtkRenderer& renderer) {
  renderer.SetBackground(1.0, 1.0, 1.0);
  renderer.UseFXAAOn();
}

void capture_png(vtkRenderWindow& window, const std::filesystem::path& target) {
  const HeldFpExceptions hold;  // Mesa's software rasterizer (llvmpipe) overflows in clipping
  window.Render();
  pin_gl_driver();
  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(&window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();  // offscreen windows draw to the back buffer
  grab->ShouldRerenderOff();   // just rendered: a second pass would double the (software) cost
  grab->Update();
  // Encoded in memory, then written through a checked stream (write_stream_atomically): a full
  // disk is one error naming the file, not that and libpng's own line on stderr.
  vtkNew<vtkPNGWriter> writer;
  writer->SetWriteToMemory(1);
  // zlib's fastest level: pictures of flat colours compress nearly as well, in a fraction of the
  // time (level 5, VTK's default, was a visible part of each picture's cost).
  writer->SetCompressionLevel(1);
  writer->SetInputConnection(grab->GetOutputPort());
  writer->Write();
  vtkUnsignedCharArray* png = writer->GetResult();
  if (writer->GetErrorCode() != 0 || png == nullptr || png->GetNumberOfValues() == 0) {
    const std::string detail = take_vtk_message();
    fail("{}: cannot encode PNG{}{}", target.string(), detail.empty() ? "" : ": ", detail);
  }
  write_stream_atomically(target, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(png->GetPointer(0)),
              static_cast<std::streamsize>(png->GetNumberOfValues()));
  });
}

}  // namespace weft::viz::detail
