#pragma once
// The loop shared by the bending terms whose elements are hinges (two triangles sharing an edge,
// Topology::hinges): the discrete-shell hinge and the linear bending vector. A hinge term is its
// rest data and one element energy; this class does the rest (pattern, threads, read-out).
// Units: µm, pJ.

#include <vector>

#include "mechanics/Bending.h"
#include "mechanics/EnergyTerm.h"

namespace tp {

template <class Rest, auto RestFn, auto EnergyFn>
class HingeElementTerm : public EnergyTerm {
 public:
  explicit HingeElementTerm(const TermContext& c) : topo_(c.topology) {
    const Points& X = c.complex.rest;
    const double D = c.material.bendingRigidity();
    rest_.reserve(topo_.hinges.size());
    verts_.reserve(4 * topo_.hinges.size());
    for (const auto& h : topo_.hinges) {
      const auto& v = h.v;
      rest_.push_back(RestFn(X.col(v[0]), X.col(v[1]), X.col(v[2]), X.col(v[3]), D));
      verts_.insert(verts_.end(), v.begin(), v.end());
    }
  }
  EnergyPart part() const override { return EnergyPart::Bending; }
  bool threaded() const override { return true; }
  void couplings(const MeshLayout&, int, Couplings& c) override {
    c.vertexElements.emplace_back(4, verts_);
  }
  void bind(const MeshLayout& layout, int) override {
    slots_ = SlotTable(*layout.pattern, *layout.dofs, 4, verts_);
  }
  double evaluate(const Points& x, const EvalOptions& o, TermSink& sink) const override {
    const int H = static_cast<int>(rest_.size());
    double energy = 0;
    Vec12 g;
    Mat12 Hm;
#pragma omp for schedule(static) nowait
    for (int k = 0; k < H; ++k) {
      const int* v = &verts_[4 * k];
      energy += EnergyFn(rest_[k], x.col(v[0]), x.col(v[1]), x.col(v[2]), x.col(v[3]), &g,
                         o.hessian ? &Hm : nullptr);
      scatterElement<12>(v, slots_.element(k), g, o.hessian ? &Hm : nullptr, sink.gradient,
                         sink.hessian);
    }
    return energy;
  }
  double energy(const Points& x, double& magnitude) const override {
    double e = 0;
    for (size_t k = 0; k < rest_.size(); ++k) e += hinge(x, k);
    magnitude += std::abs(e);
    return e;
  }
  /// Half of each hinge's energy to each of its two triangles.
  void readOut(const Points& x, TriangleReadout& r) const override {
    if (!r.bendingEnergy) return;
    for (size_t k = 0; k < rest_.size(); ++k) {
      const double w = hinge(x, k);
      (*r.bendingEnergy)[topo_.hinges[k].triA] += 0.5 * w;
      (*r.bendingEnergy)[topo_.hinges[k].triB] += 0.5 * w;
    }
  }

 private:
  double hinge(const Points& x, size_t k) const {
    const int* v = &verts_[4 * k];
    return EnergyFn(rest_[k], x.col(v[0]), x.col(v[1]), x.col(v[2]), x.col(v[3]), nullptr, nullptr);
  }
  const Topology& topo_;
  std::vector<Rest> rest_;
  std::vector<int> verts_;
  SlotTable slots_;
};

}  // namespace tp
