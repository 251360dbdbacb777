// The two-scale prediction's loops over quadrature nodes and the models' log-mean-exp
// (fit/node_kernels.h).
#include "weft/fit/node_kernels.h"

#include <algorithm>
#include <cmath>
#include <limits>

// GCC on x86-64 with glibc: declaring exp and log1p with vector variants lets `omp simd` loops
// call libmvec (2 lanes, and 4 in the AVX2 clone of each loop, chosen at run time). libmvec's
// results are within 4 ulp (glibc manual, "Errors in Math Functions"), not always the scalar
// libm's bits: T moves in the last digits only (docs/validate.md "The prediction"). The file is
// built with -fno-math-errno (CMakeLists.txt): a call that may set errno is a side effect GCC
// will not vectorise, so without it every loop with a log1p ran scalar.
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
  // Without variance every κ_j is 0: the straight hazard, no log1p.
  if (!(vb > 0.0)) {
    for (std::size_t j = 0; j < live; ++j) out[j] = sigma_mean * p[j] * length;
    return;
  }
  // With variance κ_j = 0 only where μ_j = 0 (or μ_j·v_b underflows, μ_j < 10⁻³⁰⁰), and there
  // the curved expression on κ = 1 is μ_j·log1p(…) = 0 (or < 10⁻³⁰⁰) like μ_j·length: one
  // expression for every lane, κ = 1 where κ = 0 so that no lane divides 0 by 0
  // (docs/robustness.md "Floating-point traps"). κ + (κ = 0) rather than a select: GCC threads a
  // select into two copies of the body, and a loop with control flow runs scalar.
  WEFT_SIMD_LOOP
  for (std::size_t j = 0; j < live; ++j) {
    const double mu = sigma_mean * p[j];
    const double kappa = mu * vb;
    const double k = kappa + static_cast<double>(kappa == 0.0);
    out[j] = mu / k * std::log1p(k * length / (1.0 + k * s));
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

WEFT_SIMD_CLONES
double log_sum_exp_mean(const std::vector<double>& log_terms, const std::vector<double>& weights) {
  double hi = -std::numeric_limits<double>::infinity();
  double wsum = 0.0;
  const std::size_t count = log_terms.size();
  for (std::size_t i = 0; i < count; ++i) {
    if (weights[i] > 0.0) hi = std::max(hi, log_terms[i]);
    wsum += weights[i];
  }
  if (!(wsum > 0.0) || !std::isfinite(hi)) return hi;
  // Every term in a vector lane, a term of weight 0 as 0·e^{min(x, 0)} = 0 (its exponent capped
  // so that it cannot overflow: docs/robustness.md "Floating-point traps"); then added in order,
  // one running sum: adding those zeros leaves the sum's bits, so it is the sum over the terms of
  // positive weight for any lane count. The cap is hi − hi (= 0, hi is finite): a literal 0 lets
  // GCC fold e^0 into a copy of the loop, and a loop with control flow runs scalar.
  const double cap = hi - hi;
  const double* x = log_terms.data();
  const double* w = weights.data();
  std::vector<double> terms(count);
  double* t = terms.data();
  WEFT_SIMD_LOOP
  for (std::size_t i = 0; i < count; ++i) t[i] = w[i] * std::exp(std::min(x[i] - hi, cap));
  double s = 0.0;
  for (std::size_t i = 0; i < count; ++i) s += t[i];
  return hi + std::log(s / wsum);
}

}  // namespace weft::fit::detail
