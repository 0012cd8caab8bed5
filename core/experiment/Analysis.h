#pragma once
// Reading a force–depth curve as experimentalists do (DESIGN.md §4).

#include <vector>

#include "experiment/Indentation.h"

namespace tp {

/// Least-squares fit of the Hertz law F = (4/3) E/(1−ν²) √R δ^{3/2} to the converged loading
/// points: returns the apparent modulus E (MPa) for a probe of radius R (µm), or NaN when the
/// curve has no usable point.
double hertzApparentModulus(const std::vector<CurvePoint>& curve, double probeRadius, double nu);

/// Secant stiffness F/δ (µN/µm) of the last converged loading point, NaN if none.
double secantStiffness(const std::vector<CurvePoint>& curve);

}  // namespace tp
