#pragma once
/// @file
/// @brief The per-node arithmetic of the two-scale prediction (fit/local_models.h,
/// two_scale_curve) as loops over the quadrature nodes, and the weighted log-mean-exp every
/// model's mean over columns or bins uses, vectorised where the compiler and the
/// C library allow it (glibc's vector exp and log1p with GCC on x86-64; plain loops elsewhere):
/// per coarse column and slice every node needs one log1p and one exp, and with 32 nodes these
/// are most of the prediction's cost (docs/benchmarks.md "Validate: predictions against the truth").

#include <cstddef>
#include <vector>

namespace weft::fit::detail {

/// Once a node's hazard exceeds the first node's by this much, its term in the mean of e^{−H} is
/// below e^{−40} ≈ 4·10⁻¹⁸ of the largest term, which is added first and is ≈ 1 after the shift
/// of log_mean_exp_nodes: added to a sum ≥ ½ such a term is below half an ulp and leaves the
/// sum's bits unchanged.
inline constexpr double kNegligibleHazard = 40.0;

/// The hazard over memories [s, s + length] of each of the first `live` nodes of a block, node j
/// with concentration factor p[j]: the gamma hazard of transmittance::GammaCell with rate
/// μ_j = sigma_mean·p[j] and κ_j = μ_j·vb, i.e. (μ_j/κ_j)·log1p(κ_j·length/(1 + κ_j·s)), or
/// μ_j·length when κ_j = 0 (the same expression as GammaCell::integral).
void node_hazards(const double* p, std::size_t live, double sigma_mean, double vb, double s, double length,
                  double* out);

/// log of the mean of e^{at[j]} over `nodes` equally weighted nodes of which only the first
/// `live` can contribute (the others are kNegligibleHazard below the first); `scratch` holds
/// `live` doubles.
[[nodiscard]] double log_mean_exp_nodes(const double* at, std::size_t live, std::size_t nodes, double* scratch);

/// log of the weighted mean of exp(log_terms) (weights ≥ 0), without overflow or underflow: the
/// mean over coarse columns of every local model and the empirical model's mean over histogram
/// bins, one exp per term at every depth (vectorised like the node loops).
[[nodiscard]] double log_sum_exp_mean(const std::vector<double>& log_terms, const std::vector<double>& weights);

}  // namespace weft::fit::detail
