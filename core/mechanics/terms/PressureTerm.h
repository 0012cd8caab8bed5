#pragma once
// Turgor: the work of each cell's pressure on its volume, W = −Σ_c p_c V_c, written per wall
// triangle with the pressure difference across it (mechanics/Pressure.h). Units: MPa, µm, pJ.

#include <vector>

#include "mechanics/EnergyTerm.h"

namespace tp {

class PressureTerm final : public EnergyTerm {
 public:
  explicit PressureTerm(const TermContext& c);
  std::string name() const override { return "turgor pressure"; }
  EnergyPart part() const override { return EnergyPart::Pressure; }
  bool isLoad() const override { return true; }
  void bind(const MeshLayout& layout, int) override { layout_ = &layout; }
  double evaluate(const Points& x, const EvalOptions& o, TermSink& sink) const override;
  double energy(const Points& x, double& magnitude) const override;

  /// One pressure per cell (MPa), finite.
  void setCellPressures(std::vector<double> pressures);
  const std::vector<double>& cellPressures() const { return cellPressure_; }

 private:
  const CellComplex& cc_;
  const MeshLayout* layout_ = nullptr;
  std::vector<double> cellPressure_;
  std::vector<std::pair<int, double>> loads_;  // (triangle, Δp) with Δp ≠ 0
};

}  // namespace tp
