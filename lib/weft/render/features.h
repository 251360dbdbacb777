#pragma once
/// @file
/// @brief What a scene uses, as built (world.h): selects the specialised integrator and is
/// reported in the run summary.

#include <string>
#include <vector>

namespace weft::render {

/// What the scene called for: selects the specialised integrator.
struct Features {
  bool media = false;  ///< any participating medium
  /// Some medium is not a homogeneous exponential one (MediumTraits::exponential): the general
  /// integrator runs.
  bool general_media = false;
  bool heterogeneous = false;   ///< some medium's density varies in space (grid, local fields)
  bool non_reciprocal = false;  ///< some medium needs the T_S/(c·p_Q) weights (same/explicit mode)
  /// "medium 'cloth': grid medium, exponential law, delta + ratio tracking", one per medium.
  std::vector<std::string> media_described;
  bool area_lights = false;
  bool environment = false;
  bool environment_image = false;  ///< an environment light reads a lat-long image (importance-sampled)
  bool curves = false;             ///< fibre curves (Embree round linear curves)
  [[nodiscard]] std::vector<std::string> names() const;
};

}  // namespace weft::render
