#pragma once
/// @file
/// @brief An X display for VTK's renderer: Debian's VTK 9.1 renders only through X.

#include <string>

namespace weft::viz {

/// Makes sure $DISPLAY points at a working X server, starting a private Xvfb (kept for the
/// life of the process) when none is set. Returns false with `why` filled when none can be had.
bool ensure_display(std::string* why);

}  // namespace weft::viz
