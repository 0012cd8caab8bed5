// The walls' in-plane (membrane) energy: one constant-strain triangle per mesh triangle, the
// St Venant–Kirchhoff law of mechanics/Membrane.h with the plane-stress Lamé constants.
// Units: µm, MPa, pJ.
#include <vector>

#include "mechanics/EnergyTerm.h"
#include "mechanics/terms/Terms.h"

namespace tp {

namespace {

class MembraneTerm final : public EnergyTerm {
 public:
  explicit MembraneTerm(const TermContext& c)
      : cc_(c.complex), mu_(c.material.mu()), lambda_(c.material.lambdaPlaneStress()),
        h_(c.material.thickness) {
    const Points& X = cc_.rest;
    rest_.reserve(cc_.triangleCount());
    for (const auto& t : cc_.triangles) rest_.push_back(membraneRest(X.col(t[0]), X.col(t[1]), X.col(t[2])));
    for (const auto& r : rest_) magnitude_ += 2.0 * (mu_ + lambda_) * h_ * r.area;
  }
  std::string name() const override { return "membrane"; }
  EnergyPart part() const override { return EnergyPart::Membrane; }
  bool threaded() const override { return true; }
  // The triangles' blocks are in every pattern (MeshLayout::triangleSlots): no couplings of its own.

  double evaluate(const Points& x, const EvalOptions& o, TermSink& sink) const override {
    const int T = cc_.triangleCount();
    const int* verts = layoutVerts_;
    double energy = 0;
    Vec9 g;
    Mat9 H;
#pragma omp for schedule(static) nowait
    for (int t = 0; t < T; ++t) {
      const auto& tri = cc_.triangles[t];
      energy += membraneEnergy(rest_[t], x.col(tri[0]), x.col(tri[1]), x.col(tri[2]), mu_, lambda_,
                               h_, &g, o.hessian ? &H : nullptr);
      scatterElement<9>(verts + 3 * t, slots_->element(t), g, o.hessian ? &H : nullptr,
                        sink.gradient, sink.hessian);
    }
    return energy;
  }
  void bind(const MeshLayout& layout, int) override {
    layoutVerts_ = layout.triangleVerts.data();
    slots_ = &layout.triangleSlots;
  }

  double energy(const Points& x, double& magnitude) const override {
    double e = 0;
    for (int t = 0; t < cc_.triangleCount(); ++t) {
      const auto& tri = cc_.triangles[t];
      e += membraneEnergy(rest_[t], x.col(tri[0]), x.col(tri[1]), x.col(tri[2]), mu_, lambda_, h_,
                          nullptr, nullptr);
    }
    magnitude += magnitude_;
    return e;
  }
  // Ψ is a difference of terms of size μ I₁ h A₀ per triangle: Σ 2(μ + λ*) h A₀ bounds them.
  double magnitudeOf(double) const override { return magnitude_; }

  void readOut(const Points& x, TriangleReadout& r) const override {
    if (!r.stress) return;
    r.stress->resize(cc_.triangleCount());
    for (int t = 0; t < cc_.triangleCount(); ++t) {
      const auto& tri = cc_.triangles[t];
      (*r.stress)[t] = membraneStress(rest_[t], x.col(tri[0]), x.col(tri[1]), x.col(tri[2]), mu_, lambda_);
    }
  }

 private:
  const CellComplex& cc_;
  double mu_, lambda_, h_;
  std::vector<MembraneRest> rest_;
  double magnitude_ = 0;
  const int* layoutVerts_ = nullptr;
  const SlotTable* slots_ = nullptr;
};

}  // namespace

std::unique_ptr<EnergyTerm> makeMembraneTerm(const TermContext& c) {
  return std::make_unique<MembraneTerm>(c);
}

}  // namespace tp
