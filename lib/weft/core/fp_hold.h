#pragma once
/// @file
/// @brief HeldFpExceptions: an RAII scope in which floating-point exceptions do not trap.
///
/// Some library code computes with infinities or overflow on purpose and still returns the right
/// finite answer: Embree's ray traversal takes reciprocals of zero direction components, OpenVDB's
/// math::Ray does the same, Mesa's software rasterizer (VTK's plots under Xvfb) overflows in
/// clipping, Boost.Math's incomplete gamma functions let intermediate prefixes overflow
/// (their error policy then decides, and gamma_path.cpp asks for underflow to 0 and overflow to
/// +inf), and Boost's exp-sinh quadrature divides by zero and overflows while it builds its
/// abscissas far out on the half line. In a build that traps FE_INVALID, FE_DIVBYZERO and
/// FE_OVERFLOW (preset `fp-trap`) such a call would stop the program although nothing is wrong.
/// Each use of this scope wraps one such library call and says at the call why the exceptions
/// are intentional; weft's own arithmetic must not rely on it (docs/robustness.md, "Floating-point
/// traps").

#include <cfenv>

namespace weft {

/// @brief While alive, floating-point exceptions raise flags only (no traps); on destruction the
/// caller's environment (enabled traps and the flags raised before the scope) is restored and
/// the flags raised inside are discarded. Compiled to nothing unless the build traps
/// (WEFT_TRAP_FP, preset `fp-trap`): it sits on hot paths such as every Embree ray query.
class HeldFpExceptions {
 public:
#if defined(WEFT_TRAP_FP)
  HeldFpExceptions() {
#if defined(__GLIBC__)
    // fegetexcept (glibc) reads the control words only; skip the save/restore when nothing traps.
    held_ = fegetexcept() != 0;
#endif
    if (held_) std::feholdexcept(&saved_);
  }
  ~HeldFpExceptions() {
    if (held_) std::fesetenv(&saved_);
  }
#else
  // User-provided, so a scope variable of this type does not read as "unused".
  HeldFpExceptions() {}   // NOLINT(modernize-use-equals-default)
  ~HeldFpExceptions() {}  // NOLINT(modernize-use-equals-default)
#endif
  HeldFpExceptions(const HeldFpExceptions&) = delete;
  HeldFpExceptions& operator=(const HeldFpExceptions&) = delete;
  HeldFpExceptions(HeldFpExceptions&&) = delete;
  HeldFpExceptions& operator=(HeldFpExceptions&&) = delete;

#if defined(WEFT_TRAP_FP)
 private:
  std::fenv_t saved_{};
  bool held_ = true;
#endif
};

}  // namespace weft
