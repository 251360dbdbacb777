#pragma once
/// @file
/// @brief Image environment light: a lat-long radiance image, importance-sampled by a
/// piecewise-constant 2D distribution (marginal over rows, conditional over columns).

#include <filesystem>
#include <vector>

#include "weft/render/image.h"
#include "weft/render/scene.h"

namespace weft::render {

/// @brief A piecewise-constant density on [0,1]² from nu × nv non-negative cell values
/// (row-major, v = row). Sampling inverts the marginal CDF over rows, then the row's conditional
/// CDF over columns, each linearly inside its cell, so the density of a sample is exactly
/// f(cell)/∫f, the value pdf() returns.
class Distribution2D {
 public:
  Distribution2D(std::vector<double> f, int nu, int nv);

  struct Sample {
    double u = 0.0;
    double v = 0.0;
    double pdf = 0.0;  ///< density on [0,1]²
  };
  /// Maps (ξ₁, ξ₂) ∈ [0,1)² to a point; ξ₁ picks the row, ξ₂ the column.
  [[nodiscard]] Sample sample(double xi1, double xi2) const;
  /// Density at (u, v) ∈ [0,1]².
  [[nodiscard]] double pdf(double u, double v) const;
  /// ∫f over [0,1]²; 0 means nothing can be sampled.
  [[nodiscard]] double integral() const { return integral_; }

 private:
  int nu_;
  int nv_;
  std::vector<double> f_;
  std::vector<double> row_cdf_;   ///< nv × (nu + 1), each row normalised to end at 1
  std::vector<double> row_int_;   ///< ∫ over u of each row
  std::vector<double> marginal_;  ///< nv + 1 entries, ends at 1
  double integral_ = 0.0;
};

/// @brief Radiance arriving from direction ω, read from a lat-long image: row 0 looks straight
/// up (+y), the bottom row straight down; columns go once round the horizon, u = 0.5 looking
/// towards −z and u = 0.75 towards +x. Pixels are constant (no filtering), so the radiance and
/// the sampling density agree exactly. The solid-angle density is
/// p(ω) = p_uv(u, v)/(2π² sin θ) with θ = πv, φ = 2πu − π (Jacobian of the map (u, v) → ω);
/// cells are weighted by mean RGB × sin θ at their centre so that sampling follows L·dω.
class EnvironmentMap {
 public:
  /// `rgb`: width·height·3 linear values, each finite and ≥ 0 (checked by the caller).
  EnvironmentMap(int width, int height, std::vector<float> rgb, double scale);

  [[nodiscard]] Rgb radiance(const Vec3& dir) const;
  [[nodiscard]] double pdf(const Vec3& dir) const;

  struct Sample {
    Vec3 wi{0, 0, 1};
    Rgb radiance{0, 0, 0};
    double pdf = 0.0;  ///< solid-angle density; 0 when nothing could be sampled
  };
  [[nodiscard]] Sample sample(double xi1, double xi2) const;

  /// Direction of image coordinates (u, v) ∈ [0,1]² and back.
  [[nodiscard]] static Vec3 direction(double u, double v);
  static void coordinates(const Vec3& dir, double& u, double& v);

  /// Whether any direction carries radiance (a scale > 0 and a pixel > 0): an all-black image
  /// or a scale of 0 is a light that lights nothing.
  [[nodiscard]] bool emits() const;

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }

 private:
  [[nodiscard]] std::size_t pixel(double u, double v) const;
  int width_;
  int height_;
  std::vector<float> rgb_;
  double scale_;
  Distribution2D dist_;
};

/// @brief Reads a lat-long EXR for an environment light. Throws weft::Error naming the file for
/// a missing or unreadable image and for negative or non-finite pixels.
[[nodiscard]] EnvironmentMap load_environment(const std::filesystem::path& path, double scale);

}  // namespace weft::render
