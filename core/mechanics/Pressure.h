#pragma once
// Turgor as an energy of volume (DESIGN.md §1; PolyFEM's PressureAssembler idea):
// W = −Σ_c p_c V_c(x), V_c = (1/6) Σ_{t ∈ ∂c} x₀·(x₁ × x₂) with t wound outward from c.
// Per triangle this is W_t = −(Δp_t/6) x₀·(x₁ × x₂), Δp_t = p(cell) − p(neighbor), p(outside) = 0.
// A wall between two cells at equal pressure carries no load. Units: MPa, µm, pJ.

#include "mechanics/Membrane.h"

namespace tp {

/// Energy of one triangle with pressure difference dp (MPa) across it (normal side is low).
double pressureEnergy(double dp, const Vec3& x0, const Vec3& x1, const Vec3& x2, Vec9* grad,
                      Mat9* hess);

}  // namespace tp
