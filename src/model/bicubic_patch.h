// Bicubic Bezier patches (the .bpt input's exact surface): evaluation and the exact unit normal.
// One place for what the .bpt reader tessellates and the error analysis takes as reference.
#pragma once
#include <glm/glm.hpp>

#include "model/mesh.h"

namespace sffd {

// S(u, v), Su, Sv of P = sum_r sum_c B3_r(u) B3_c(v) points[4r+c].
void evaluateBicubic(const BicubicPatch& P, double u, double v, glm::dvec3& S, glm::dvec3& Su, glm::dvec3& Sv);

// The exact unit normal Su x Sv; where it vanishes (a collapsed patch edge or corner: the teapot's lid
// apex and bottom centre), taken at a parameter nudged toward the patch interior, where it tends to
// the limit normal. +z for a patch collapsed to a curve or a point.
glm::dvec3 bicubicNormal(const BicubicPatch& P, double u, double v);

}  // namespace sffd
