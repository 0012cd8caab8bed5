#pragma once
// The total potential energy of a tissue: membrane + bending + turgor + probe contact + point
// loads, with value, gradient and sparse Hessian over the free unknowns.
// Units: µm, MPa, µN, pJ. Positions are a 3×V matrix (one column per vertex).

#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include "mechanics/Assembly.h"
#include "mechanics/EnergyTerm.h"
#include "mechanics/Material.h"
#include "mechanics/terms/ContactTerm.h"
#include "mesh/CellComplex.h"
#include "mesh/Topology.h"

namespace tp {

class PressureTerm;
class PointForceTerm;

struct EnergyParts {
  double membrane = 0, bending = 0, pressure = 0, contact = 0, external = 0;
  /// Sum of the magnitudes that cancel inside the total (e.g. μ·I₁·h·A₀ per triangle, |p V| per
  /// pressure term): the total is only known to about 1e-15 of this (round-off scale).
  double magnitude = 0;
  double total() const { return membrane + bending + pressure + contact + external; }
  double& operator[](EnergyPart part);
};

/// One evaluation of the model at positions x.
struct Evaluation {
  EnergyParts energy;
  Eigen::VectorXd gradient;      // 3V, ∂W/∂x (all components, clamped ones included)
  Eigen::VectorXd loadGradient;  // 3V, the part due to loads (pressure, contact, point forces)
  std::vector<double> hessian;   // values over Model::pattern() (free unknowns, upper triangle)
  bool hasHessian = false;       // hessian (and the probe's second derivatives) were computed
  bool contactProjected = false; // ... with each contact element's positive part only
  // Probe: derivatives with respect to the sphere's centre p.
  Vec3 probeGradient = Vec3::Zero();  // ∂W/∂p: the force the probe exerts on the tissue (µN)
  Mat3 probeHessian = Mat3::Zero();   // ∂²W/∂p²
  Eigen::MatrixX3d probeCoupling;     // 3V × 3, ∂²W/∂x∂p
  int contactTriangles = 0;           // triangles touched by the probe
};

/// The sum of the registered energy terms (mechanics/EnergyTerm.h, mechanics/terms/Registry.cpp)
/// that apply to the material, over one tissue.
class Model {
 public:
  Model(std::shared_ptr<const CellComplex> cc, const Material& material);
  ~Model();
  Model(const Model&) = delete;
  Model& operator=(const Model&) = delete;

  const CellComplex& complex() const { return *cc_; }
  std::shared_ptr<const CellComplex> complexPtr() const { return cc_; }
  const Topology& topology() const { return topo_; }
  const Material& material() const { return material_; }
  /// The terms summed, in evaluation order.
  const std::vector<std::unique_ptr<EnergyTerm>>& terms() const { return terms_; }

  /// Turgor pressure (MPa) of every cell, or one value for all cells.
  void setCellPressures(std::vector<double> pressures);
  void setUniformPressure(double p);
  const std::vector<double>& cellPressures() const;

  /// Clamped position components (3V flags); by default those of the complex's clamped vertices.
  void setFixedDofs(const std::vector<std::uint8_t>& fixedDof);
  const DofMap& dofs() const { return dofs_; }
  /// The tangent matrix's pattern: the free position components (dofs().freeCount(), in the
  /// order of dofs().freeDofs()), then the terms' own unknowns (the edge unknowns of Koiter
  /// bending, eliminated from the energy, see mechanics/PlateBending.h). A Newton step solves
  /// with the whole matrix, a zero right-hand side for the terms' unknowns, and keeps the
  /// position part.
  const SparsePattern& pattern() const { return pattern_; }
  /// The node of each of the pattern's unknowns for the fill-reducing ordering
  /// (CholmodSolver::analyze): a free position component's vertex, and for each of the terms'
  /// own unknowns a node of its own (numbered from vertexCount()).
  std::vector<int> orderingNodes() const;

  /// Point loads (µN) on vertices: W = −Σ f·x.
  void setPointForces(std::vector<std::pair<int, Vec3>> forces);

  void setProbe(const Probe& probe) { contact_->setProbe(probe); }
  /// The contact term's index in terms() (for EvalOptions::onlyTerm).
  int contactTerm() const { return contactIndex_; }
  void clearProbe() { contact_->clearProbe(); }
  const std::optional<Probe>& probe() const { return contact_->probe(); }
  void setContactLaw(const ContactLaw& law) { contact_->setLaw(law); }
  const ContactLaw& contactLaw() const { return contact_->law(); }

  /// Contact that cannot be lost: the probe's centre must stay at least this far (µm, half the
  /// probe's radius) from every outer triangle. The contact energy is a penalty on the unsigned
  /// distance, so a centre that crossed a wall would be pushed on through it; a state that keeps
  /// the clearance cannot have tunnelled, and solvers keep it at every step (contactStepBound).
  double contactClearance() const { return contact_->clearance(); }
  /// The smallest distance (µm) from the probe's centre to an outer triangle at positions x
  /// (infinity without a probe).
  double probeDistance(const Points& x) const { return contact_->probeDistance(x); }
  /// The contact patch at positions x: the outer triangles the probe presses (closer to its
  /// centre than its radius, so the contact energy acts on them), ascending; empty without a probe.
  std::vector<int> touchedTriangles(const Points& x) const { return contact_->touched(x); }
  /// The largest α in [0, 1] for which moving the vertices by α·dx and the probe's centre by
  /// α·dp keeps the clearance all along the way, by conservative advancement: the distance from a
  /// point to a triangle shrinks at most as fast as the largest relative speed of its vertices
  /// (Mirtich, "Impulse-based dynamic simulation", 1996, §2.4; the bound IPC's additive CCD uses).
  /// 0 when x itself is within the clearance.
  double contactStepBound(const Points& x, const Points& dx, const Vec3& dp) const {
    return contact_->stepBound(x, dx, dp);
  }

  /// The energy at x (every term, or options.onlyTerm), by parts.
  double energy(const Points& x, EnergyParts* parts = nullptr, int onlyTerm = -1) const;
  /// Energy, gradient, load gradient, the probe's derivatives, and with options.hessian the
  /// tangent's values over pattern().
  void evaluate(const Points& x, Evaluation& out, const EvalOptions& options) const;
  /// The exact tangent (no projection) when withHessian.
  void evaluate(const Points& x, Evaluation& out, bool withHessian) const {
    evaluate(x, out, EvalOptions{.hessian = withHessian});
  }

  /// Membrane stress of every triangle at positions x.
  std::vector<MembraneStress> triangleStresses(const Points& x) const;
  /// Bending energy per triangle (pJ): its own plate energy (Koiter), or half of each of its
  /// hinges (hinge, linear).
  std::vector<double> triangleBendingEnergy(const Points& x) const;

  /// Typical edge length of the rest mesh (µm).
  double meanEdgeLength() const { return meanEdge_; }

 private:
  std::shared_ptr<const CellComplex> cc_;
  Topology topo_;
  Material material_;
  double meanEdge_ = 1.0;
  std::vector<std::unique_ptr<EnergyTerm>> terms_;
  std::vector<int> firstUnknown_;  // per term: the index of its first own unknown
  PressureTerm* pressure_ = nullptr;
  ContactTerm* contact_ = nullptr;
  int contactIndex_ = -1;
  PointForceTerm* forces_ = nullptr;
  // Per-thread accumulators of evaluate() (reused; a Model is evaluated by one caller at a time).
  mutable std::vector<std::vector<double>> threadGrad_, threadVals_;
  DofMap dofs_;
  SparsePattern pattern_;
  MeshLayout layout_;
};

}  // namespace tp
