#pragma once
// One term of the tissue's potential energy (a wall's membrane or bending energy, turgor, the
// probe's contact, point loads), and what Model gives it to assemble into.
//
// A new term is one class implementing EnergyTerm in mechanics/terms/ and one line in
// mechanics/terms/Registry.cpp: Model builds the registered terms for the material it is given,
// builds the tangent's pattern from the couplings they declare, and sums their values, gradients
// and Hessians. Options of an evaluation (the Hessian or not, the contact's positive part) are
// arguments (EvalOptions), never model state. tests/mechanics/test_terms.cpp checks every
// registered term against finite differences.
// Units: positions µm, pressures and moduli MPa, forces µN, energies pJ.

#include <memory>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "mechanics/Assembly.h"
#include "mechanics/Material.h"
#include "mechanics/Math.h"
#include "mechanics/Membrane.h"
#include "mesh/CellComplex.h"
#include "mesh/Topology.h"

namespace tp {

struct Evaluation;

/// Where a term's energy is reported (EnergyParts).
enum class EnergyPart { Membrane, Bending, Pressure, Contact, External };

/// Options of one evaluation.
struct EvalOptions {
  bool hessian = false;         // compute the tangent's values too
  bool projectContact = false;  // replace each contact element's Hessian by its positive part
  int onlyTerm = -1;            // ≥ 0: evaluate that term of Model::terms() alone (tests, read-outs)
};

/// What a term sees when it is built: the tissue, its topology, the wall material.
struct TermContext {
  const CellComplex& complex;
  const Topology& topology;
  const Material& material;
  double meanEdge;  // typical rest edge length (µm)
};

/// The tangent's layout, shared by every term once the clamps are known (Model::setFixedDofs).
struct MeshLayout {
  const CellComplex* complex = nullptr;
  const DofMap* dofs = nullptr;
  const SparsePattern* pattern = nullptr;
  std::vector<int> triangleVerts;  // flattened, three per triangle
  SlotTable triangleSlots;         // every triangle's 9×9 block (the pattern always holds them)
};

/// The couplings a term adds to the tangent's pattern.
struct Couplings {
  /// (arity, flattened vertex lists): elements coupling every component of their vertices.
  std::vector<std::pair<int, std::span<const int>>> vertexElements;
  /// Lists of unknowns (free position indices, then the term's own unknowns; −1 skipped).
  std::vector<std::span<const int>> unknownElements;
};

/// Where one evaluation of a term goes.
struct TermSink {
  double* gradient = nullptr;  // 3V, ∂W/∂x (all components)
  double* hessian = nullptr;   // values over the pattern, or null when no Hessian is wanted
  Evaluation* out = nullptr;   // serial terms only: load gradient, probe derivatives, counts
};

/// Per-triangle read-outs for colouring and export; each term fills what it knows.
struct TriangleReadout {
  std::vector<MembraneStress>* stress = nullptr;  // in-plane stress (membrane terms)
  std::vector<double>* bendingEnergy = nullptr;   // pJ per triangle (bending terms add)
};

class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;
  virtual std::string name() const = 0;
  virtual EnergyPart part() const = 0;
  /// A load (pressure, contact, point forces): its gradient is also summed into
  /// Evaluation::loadGradient, the scale of the residual's tolerance.
  virtual bool isLoad() const { return false; }

  /// Unknowns of the term's own after the free positions (Koiter's edge unknowns), numbered from
  /// `first` in couplings() and bind().
  virtual int ownUnknowns() const { return 0; }
  virtual void couplings(const MeshLayout&, int /*first*/, Couplings&) {}
  /// Called when the pattern is (re)built: look up where the term's entries go.
  virtual void bind(const MeshLayout&, int /*first*/) {}

  /// Threaded terms are evaluated by every thread of Model's parallel region, each with its own
  /// sink, and share the work with `#pragma omp for` (all threads call them in the same order);
  /// they return that thread's share of the energy. Serial terms are called once, after.
  virtual bool threaded() const { return false; }
  /// Energy, gradient (and Hessian values when o.hessian) added into the sink.
  virtual double evaluate(const Points& x, const EvalOptions& o, TermSink& sink) const = 0;
  /// Energy only; adds to `magnitude` the size of what cancels inside it (round-off scale).
  virtual double energy(const Points& x, double& magnitude) const = 0;
  /// For threaded terms, whose evaluate() sees a share: the magnitude of a total value.
  virtual double magnitudeOf(double total) const { return std::abs(total); }

  virtual void readOut(const Points&, TriangleReadout&) const {}
};

/// A registered term: built for a tissue and material, or null when it does not apply (a
/// bending model other than the material's).
struct TermRegistration {
  const char* name;
  std::unique_ptr<EnergyTerm> (*make)(const TermContext&);
};
/// Every term Model knows, in evaluation order (mechanics/terms/Registry.cpp).
const std::vector<TermRegistration>& registeredTerms();

/// Adds one element's gradient and Hessian (local order: its vertices' x, y, z, the Hessian
/// column-major) into the global arrays, the Hessian through its slot entries.
template <int M>
inline void scatterElement(const int* verts, const SlotTable::Entries& entries,
                           const Eigen::Matrix<double, M, 1>& g,
                           const Eigen::Matrix<double, M, M>* H, double* grad, double* values) {
  for (int i = 0; i < M; ++i) grad[3 * verts[i / 3] + i % 3] += g[i];
  if (!H || !values) return;
  const double* h = H->data();
  for (int q = 0; q < entries.count; ++q) values[entries.slot[q]] += h[entries.local[q]];
}

}  // namespace tp
