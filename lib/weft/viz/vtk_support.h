#pragma once
/// @file
/// @brief Internal to weft_viz (includes VTK): VTK's messages kept off the terminal, and a render
/// window captured to PNG. Include only from this module's .cpp files.

#include <filesystem>
#include <string>

class vtkRenderWindow;
class vtkRenderer;
class vtkTextProperty;

namespace weft::viz::detail {

/// @brief Routes VTK's warnings and errors into a buffer instead of stderr (library code never
/// prints); call before creating any VTK object that may complain.
void quiet_vtk_messages();

/// @brief The last VTK error or warning text since the previous call (one line), then clears it.
std::string take_vtk_message();

/// @brief Sets DejaVu Sans (Debian's fontconfig default, with Greek and math symbols, which
/// VTK's built-in fonts lack) at `size` pixels; keeps VTK's own font when the file is missing.
void set_font(vtkTextProperty& text, int size, bool bold);

/// @brief `s` with spaces turned into line breaks (greedily, at word boundaries) so that no
/// line is wider than `max_width` pixels in the font of `text` (measured by FreeType, as VTK
/// draws it). A single word wider than that stays on its own line.
std::string wrap_text(vtkTextProperty& text, const std::string& s, int max_width);

/// @brief Throws weft::Error unless `target`'s folder exists and is writable: checked before a
/// display is sought, so a bad path is reported even on a machine without one.
void require_writable_folder(const std::filesystem::path& target);

/// @brief An offscreen window of `width` x `height` without multisampling. VTK 9.1 asks for 8x
/// MSAA by default, which Mesa's llvmpipe pays for in full: it was about 60 % of a volume view's
/// render and 30 % of a chart's (docs/viz.md); prepare_renderer's FXAA smooths the edges instead.
void prepare_window(vtkRenderWindow& window, int width, int height);

/// @brief White background and FXAA (a cheap post-pass antialiasing) for a renderer.
void prepare_renderer(vtkRenderer& renderer);

/// @brief Renders `window` and writes its pixels as a PNG to `target`, atomically
/// (write_stream_atomically: a short write is an error naming `target`, and a stop requested while
/// the window rendered leaves the earlier file). Throws weft::Error naming `target` on failure.
void capture_png(vtkRenderWindow& window, const std::filesystem::path& target);

}  // namespace weft::viz::detail
