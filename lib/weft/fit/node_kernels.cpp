// The two-scale prediction's loops over quadrature nodes (fit/node_kernels.h).
#include "weft/fit/node_kernels.h"

#include <algorithm>
#include <cmath>
#include <limits>

// GCC on x86-64 with glibc: declaring exp and log1p with vector variants lets `omp simd` loops
// call libmvec (2 lanes, and 4 in the AVX2 clone of each loop, chosen at run time). libmvec's
// results are within 4 ulp (glibc manual, "Errors in Math Functions"), not always the scalar
// libm's bits: T moves in the last digits only (docs/validate.md "The prediction").
#if defined(WEFT_NODE_SIMD)
extern "C" {
__attribute__((simd("notinbranch"))) double exp(double) noexcept;
__attribute__((simd("notinbranch"))) double log1p(double) noexcept;
}
#define WEFT_SIMD_LOOP _Pragma("omp simd")
#define WEFT_SIMD_CLONES __attribute__((target_clones("avx2", "default")))
#else
#define WEFT_SIMD_LOOP
#define WEFT_SIMD_CLONES
#endif

namespace weft::fit::detail {

WEFT_SIMD_CLONES
void node_hazards(const double* p, std::size_t live, double sigma_mean, double vb, double s, double length,
                  double* out) {
  WEFT_SIMD_LOOP
  for (std::size_t j = 0; j < live; ++j) {
    const double mu = sigma_mean * p[j];
    const double kappa = vb > 0.0 ? mu * vb : 0.0;
    // Both branches are computed in a vector lane: the curved one on κ = 1 where κ = 0, so no
    // lane divides 0 by 0 (docs/robustness.md "Floating-point traps").
    const double k = kappa != 0.0 ? kappa : 1.0;
    const double curved = mu / k * std::log1p(k * length / (1.0 + k * s));
    out[j] = kappa != 0.0 ? curved : mu * length;
  }
}

WEFT_SIMD_CLONES
double log_mean_exp_nodes(const double* at, std::size_t live, std::size_t nodes, double* scratch) {
  double hi = -std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < live; ++j) hi = std::max(hi, at[j]);
  if (!std::isfinite(hi)) return hi;
  if (nodes == 1) return hi + 0.0;  // hi + log(e^0 / 1), bit for bit
  WEFT_SIMD_LOOP
  for (std::size_t j = 0; j < live; ++j) scratch[j] = std::exp(at[j] - hi);
  // Added in node order (the largest first), one running sum: the same bits for any lane count.
  double sum = 0.0;
  for (std::size_t j = 0; j < live; ++j) sum += scratch[j];
  return hi + std::log(sum / static_cast<double>(nodes));
}

}  // namespace weft::fit::detail
