// Koiter (Kirchhoff–Love) plate bending with the wall's ν, rotation-free triangles with edge
// unknowns (mechanics/PlateBending.h): the default bending model. Units: µm, µN·µm, pJ.
#include <omp.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "mechanics/EnergyTerm.h"
#include "mechanics/Bending.h"
#include "mechanics/PlateBending.h"
#include "mechanics/terms/Terms.h"

namespace tp {

namespace {

class KoiterTerm final : public EnergyTerm {
 public:
  static constexpr int kMaxArity = 6;  // a triangle and one wing per edge
  static constexpr int kMaxUnknowns = 3 * kMaxArity + 3;  // and an edge unknown per edge

  explicit KoiterTerm(const TermContext& c)
      : cc_(c.complex),
        plate_(buildPlateBending(c.complex, c.topology, c.material.bendingRigidity(),
                                 c.material.poissonRatio, c.material.junctions)) {
    if (plate_.maxArity > kMaxArity)  // each edge has one pair at most (PlateBending.cpp)
      throw std::logic_error("Koiter bending: an element with more than one wing per edge");
    for (const auto& pr : plate_.pairs) pairVerts_.insert(pairVerts_.end(), pr.v.begin(), pr.v.end());
    pairTheta_.resize(plate_.pairs.size());
    pairGrad_.resize(plate_.pairs.size());
    plateY_.resize(plate_.elements.size());
    angleSlopes_.resize(plate_.elements.size());
    phi_.setZero(plate_.edgeUnknowns);
  }
  std::string name() const override { return "Koiter bending"; }
  EnergyPart part() const override { return EnergyPart::Bending; }
  bool threaded() const override { return true; }
  int ownUnknowns() const override { return plate_.edgeUnknowns; }

  // Each element couples its vertices' free components and its edge unknowns.
  void couplings(const MeshLayout& layout, int first, Couplings& c) override {
    const DofMap& dofs = *layout.dofs;
    const int T = cc_.triangleCount();
    unknowns_.clear();
    unknownBegin_.assign(1, 0);
    for (int t = 0; t < T; ++t) {
      const auto& el = plate_.elements[t];
      if (el.refBegin[3] > el.refBegin[0] || el.edgeUnknown[0] >= 0 || el.edgeUnknown[1] >= 0 ||
          el.edgeUnknown[2] >= 0) {
        for (int i = plate_.vertexBegin[t]; i < plate_.vertexBegin[t + 1]; ++i)
          for (int k = 0; k < 3; ++k) unknowns_.push_back(dofs.index(3 * plate_.elementVertices[i] + k));
        for (int k = 0; k < 3; ++k)
          if (el.edgeUnknown[k] >= 0) unknowns_.push_back(first + el.edgeUnknown[k]);
      }
      unknownBegin_.push_back(static_cast<int>(unknowns_.size()));
    }
    // An element's work is about its upper-triangle entries (one for a rigid one, skipped).
    workBefore_.assign(1, 0.0);
    for (int t = 0; t < T; ++t) {
      const double m = unknownBegin_[t + 1] - unknownBegin_[t];
      workBefore_.push_back(workBefore_.back() + 1.0 + m * (m + 1) / 2);
    }
    for (int t = 0; t < T; ++t)
      if (unknownBegin_[t + 1] > unknownBegin_[t])
        c.unknownElements.emplace_back(unknowns_.data() + unknownBegin_[t],
                                       unknownBegin_[t + 1] - unknownBegin_[t]);
  }

  void bind(const MeshLayout& layout, int) override {
    const SparsePattern& pattern = *layout.pattern;
    pairSlots_ = SlotTable(pattern, *layout.dofs, 4, pairVerts_);  // a pair lies inside its elements
    std::vector<int> slots, slotBegin;
    elementPositions(pattern, unknowns_, unknownBegin_, slotBegin, slots);
    // Each element's stored entries (prescribed ones dropped) by position, with their index in
    // its upper triangle row by row (< 21·22/2).
    const int T = static_cast<int>(unknownBegin_.size()) - 1;
    entries_.clear();
    std::vector<std::pair<int, int>> e;
    for (int t = 0; t < T; ++t) {
      e.clear();
      for (int s = slotBegin[t]; s < slotBegin[t + 1]; ++s)
        if (slots[s] >= 0) e.emplace_back(slots[s], s - slotBegin[t]);
      entries_.add(e);
    }
  }

  // Five passes, every thread of the model's parallel region taking part: (1) each pair's
  // dihedral angle and its gradient (closed form); (2) each element's slope changes from those
  // angles; (3) the edge unknowns that minimise the energy for them (A's blocks, factorised once,
  // solved side by side, mechanics/PlateBending.h); (4) each element's energy ½ ΔsᵀBΔs, its
  // gradient Σ_k y_k ∇s_k (y = B Δs; the edge unknowns' part is zero at the minimum) and the matrix
  // Gᵀ B G over its positions and edge unknowns, G = ∂Δs/∂(x, φ); (5) the curvature part, each
  // pair's Σ (coeff · y_k) ∇²θ gathered from the elements that use it (the Hessian of θ alone: its
  // gradient is pass 1's).
  double evaluate(const Points& x, const EvalOptions& o, TermSink& sink) const override {
    const int P = static_cast<int>(plate_.pairs.size());
    const int T = static_cast<int>(plate_.elements.size());
    // Passes 1 and 2 write each pair's and element's own scratch, so any schedule gives the same
    // result: dynamic chunks take up whatever the terms before left unbalanced.
#pragma omp for schedule(dynamic, 256)
    for (int p = 0; p < P; ++p) {
      const auto& pv = plate_.pairs[p].v;
      pairTheta_[p] = dihedralAngleGradient(x.col(pv[0]), x.col(pv[1]), x.col(pv[2]), x.col(pv[3]),
                                            pairGrad_[p]);
    }
#pragma omp for schedule(dynamic, 512)
    for (int t = 0; t < T; ++t) angleSlopes_[t] = plateAngleSlopes(plate_, t, pairTheta_);
    const int blocks = static_cast<int>(plate_.edgeBlocks->size());
#pragma omp for schedule(dynamic, 1)
    for (int b = 0; b < blocks; ++b) plateEdgeRotationsOfBlock(plate_, b, angleSlopes_, phi_);
    double energy = 0;
    constexpr int kMax = kMaxUnknowns;
    using LocalGrads = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMax, 3>;
    double* g = sink.gradient;
    double* v = sink.hessian;
    // Contiguous ranges of equal work rather than of equal count: the refined triangles, whose
    // elements all carry edge unknowns, come last (at level 4 an even split of the count left one
    // thread 6.5 ms against the other's 10.9). Fixed for a given number of threads, so the sums
    // come out the same from run to run.
    const int tid = omp_get_thread_num(), threads = omp_get_num_threads();
    const auto split = [&](int k) {  // where thread k's range starts (k = threads: T)
      const double share = workBefore_.back() * k / threads;
      return std::min(T, static_cast<int>(std::lower_bound(workBefore_.begin(), workBefore_.end(),
                                                           share) - workBefore_.begin()));
    };
    for (int t = split(tid), tEnd = split(tid + 1); t < tEnd; ++t) {
      const int begin = unknownBegin_[t], m = unknownBegin_[t + 1] - begin;
      if (m == 0) {
        plateY_[t].setZero();
        continue;
      }
      const ElementEntries::Entries entries = entries_.element(t);
      if (o.hessian)  // its stored entries fetched while its matrix is computed (−3 to −5 %)
        for (int q = 0; q < entries.count; q += 2) __builtin_prefetch(v + entries.slot[q], 1, 3);
      const auto& el = plate_.elements[t];
      const Eigen::Vector3d ds = plateSlopeChanges(plate_, t, angleSlopes_[t], phi_);
      const Eigen::Vector3d y = el.B * ds;
      energy += 0.5 * ds.dot(y);
      plateY_[t] = y;
      const int* ev = plate_.elementVertices.data() + plate_.vertexBegin[t];
      const int mx = 3 * (plate_.vertexBegin[t + 1] - plate_.vertexBegin[t]);
      LocalGrads G = LocalGrads::Zero(m, 3);  // ∂Δs_k/∂(local unknowns)
      int aux = mx;
      for (int k = 0; k < 3; ++k) {
        for (int r = el.refBegin[k]; r < el.refBegin[k + 1]; ++r) {
          const auto& ref = plate_.refs[r];
          const Vec12& gp = pairGrad_[ref.pair];
          for (int i = 0; i < 4; ++i) G.block<3, 1>(3 * ref.local[i], k) += ref.coeff * gp.segment<3>(3 * i);
        }
        if (el.edgeUnknown[k] >= 0) G(aux++, k) = el.edgeSign[k];
      }
      const Eigen::Matrix<double, Eigen::Dynamic, 1, 0, kMax, 1> ge = G.topRows(mx).lazyProduct(y);
      for (int i = 0; i < mx; ++i) g[3 * ev[i / 3] + i % 3] += ge[i];
      if (!o.hessian) continue;
      // G B Gᵀ, upper triangle row by row (no small-matrix product kernels), then added to the
      // values in the order of their positions.
      double upper[kMax * (kMax + 1) / 2];
      if (m == kMax)  // the usual element inside a refined wall: sizes known to the compiler
        upperOfGBGt<kMax>(G.data(), el.B, upper);
      else
        upperOfGBGt<Eigen::Dynamic>(G.data(), el.B, upper, m);
      for (int q = 0; q < entries.count; ++q) v[entries.slot[q]] += upper[entries.local[q]];
    }
#pragma omp barrier
    if (!o.hessian) return energy;
      // Chunks dealt in turn rather than two halves: the pairs of the refined walls, last, cost
      // more (their writes spread further); fixed for a given number of threads like the split
      // above.
#pragma omp for schedule(static, 512) nowait
    for (int p = 0; p < P; ++p) {
      double mu = 0;
      for (int k = plate_.useBegin[p]; k < plate_.useBegin[p + 1]; ++k) {
        const auto& u = plate_.pairUses[k];
        mu += u.coeff * plateY_[u.element](u.edge);
      }
      if (mu == 0.0) continue;
      const SlotTable::Entries entries = pairSlots_.element(p);
      for (int q = 0; q < entries.count; q += 2) __builtin_prefetch(v + entries.slot[q], 1, 3);
      const auto& pv = plate_.pairs[p].v;
      Mat12 Hp;
      dihedralAngleHessian(x.col(pv[0]), x.col(pv[1]), x.col(pv[2]), x.col(pv[3]), Hp);
      const double* h = Hp.data();
      for (int q = 0; q < entries.count; ++q) v[entries.slot[q]] += mu * h[entries.local[q]];
    }
    return energy;
  }

  // The upper triangle of G B Gᵀ row by row, G the m × 3 column-major array at g.
  template <int M>
  static void upperOfGBGt(const double* g, const Eigen::Matrix3d& B, double* upper, int m = M) {
    const Eigen::Map<const Eigen::Matrix<double, M, 3, 0, kMaxUnknowns, 3>> G(g, m, 3);
    Eigen::Matrix<double, M, 3, 0, kMaxUnknowns, 3> GB(m, 3);
    GB.noalias() = G.lazyProduct(B);
    int s = 0;
    for (int i = 0; i < m; ++i)
      for (int j = i; j < m; ++j, ++s)
        upper[s] = GB(i, 0) * G(j, 0) + GB(i, 1) * G(j, 1) + GB(i, 2) * G(j, 2);
  }

  double energy(const Points& x, double& magnitude) const override {
    const double e = plateBendingEnergy(plate_, x);
    magnitude += std::abs(e);
    return e;
  }
  void readOut(const Points& x, TriangleReadout& r) const override {
    if (!r.bendingEnergy) return;
    std::vector<double> e(cc_.triangleCount(), 0.0);
    plateBendingEnergy(plate_, x, &e);
    for (size_t t = 0; t < e.size(); ++t) (*r.bendingEnergy)[t] += e[t];
  }

 private:
  const CellComplex& cc_;
  PlateBending plate_;
  std::vector<int> pairVerts_;
  // Each element's unknowns (three per vertex, then its edge unknowns, −1 where prescribed).
  std::vector<int> unknowns_, unknownBegin_;
  std::vector<double> workBefore_;  // the elements' work before element t (t = 0 … T)
  ElementEntries entries_;  // each element's stored entries, by position
  SlotTable pairSlots_;
  // Per-evaluation scratch: each pair's angle and its gradient, each element's slope changes
  // from the angles, the edge unknowns, each element's B Δs.
  mutable std::vector<double> pairTheta_;
  mutable std::vector<Vec12> pairGrad_;
  mutable Eigen::VectorXd phi_;
  mutable std::vector<Eigen::Vector3d> plateY_, angleSlopes_;
};

}  // namespace

std::unique_ptr<EnergyTerm> makeKoiterTerm(const TermContext& c) {
  if (c.material.bending != BendingModel::Koiter) return nullptr;
  return std::make_unique<KoiterTerm>(c);
}

}  // namespace tp
