#pragma once
/// @file
/// @brief Yarn centrelines of woven and knitted cloth.

#include <string>

#include "data_gen/cloth/fibers.h"
#include "data_gen/cloth/spec.h"

namespace weft::cloth {

/// @brief Whether warp yarn `j` passes over weft yarn `i` in a woven `pattern` (plain, twill21,
/// twill22, twill31, satin5, basket); any integers, periodic with pattern_repeat().
bool warp_over(const std::string& pattern, int i, int j);
/// Repeat of the interlacing in both directions (2 for plain, a+b for twill a/b, 5 for satin5, 4 for basket).
int pattern_repeat(const std::string& pattern);

/// @brief Height of warp `j`'s centreline at x (mm) for a resolved woven spec: ±crimp at each
/// crossing, joined by a cosine ease so the centreline is C¹ and periodic in x.
double warp_height(const ClothSpec& spec, int j, double x);
/// Height of weft `i`'s centreline at y (mm).
double weft_height(const ClothSpec& spec, int i, double y);

/// @brief Centrelines of a woven pattern: warps along x at y = (j + ½)·warp_spacing, wefts along y
/// at x = (i + ½)·weft_spacing, each spanning the cloth. `spec` must be resolved.
CurveSet woven_centerlines(const ClothSpec& spec);

/// @brief Stockinette (plain knit): one yarn per course r (warp_count courses, weft_count wales),
/// x = W(t/2π + a·sin 2t), y = rH + h(1 − cos t)/2, z = D·cos t for t ∈ [0, 2π·wales], with
/// W = wale spacing, H = course spacing, loop height h = 1.5 H (so each loop head reaches through
/// the next course's loop), depth D = crimp, a = 0.05. Heads sit behind (z = −D) the legs of the
/// next course: the interlock of a knitted loop.
CurveSet knit_centerlines(const ClothSpec& spec);

/// Centrelines for any resolved spec (woven, knit or imported from spec.input).
CurveSet cloth_centerlines(const ClothSpec& spec);

}  // namespace weft::cloth
