#pragma once
// Koiter (Kirchhoff–Love) plate bending of the walls, both invariants with the wall's ν:
//   W = ∫ (D/2) [ ν (tr ΔS)² + (1 − ν) tr(ΔS²) ] dA,   D = E h³ / (12 (1 − ν²)),
// the same as (h³/24)[(Eν/(1−ν²)) (tr ΔS)² + (E/(1+ν)) tr(ΔS²)], ΔS the change of the shape
// operator from the rest state. Units: positions µm, D µN·µm, energies pJ.
//
// Discretisation: the Morley triangle (L. S. D. Morley, "The constant-moment plate-bending element",
// J. Strain Anal. 6, 1971), written for large rotations in the manner of the mid-edge shape
// operators of discrete shells (Grinspun et al., "Computing discrete shape operators on general
// meshes", 2006; Chen et al., "Physical simulation of environmentally induced thin shell
// deformation", 2018). Over each triangle T the change of the surface is the quadratic
// g = Σ_i c_i λ_j λ_k (the edge bubbles, zero at T's vertices) whose outward slope at the midpoint
// of edge i, relative to T's plane, is s_i = (c_i − c_j − c_k)/(2 h_i) (h_i T's height on edge i).
// The Hessian of g in barycentric parameters is II = [[−2c₂, c₀−c₁−c₂], [c₀−c₁−c₂, −2c₁]], and
// ΔS = J⁻ᵀ II J⁻¹ with J = [X₁−X₀, X₂−X₀]: for each triangle W_T = ½ Δsᵀ B Δs with B fixed by the
// rest geometry and (D, ν). The slopes are the mid-edge normals: across an edge shared by T and N,
// the two slopes split the fold of the edge, s_T = −Δθ/2 + φ, s_N = −Δθ/2 − φ (θ the dihedral
// angle, measured along each triangle's own normal), so the surface's normal is continuous at the
// mid-edge (Morley's continuity); φ, the tilt of the mid-edge normal from the bisector, is one
// unknown per edge. On an edge with no partner in the wall (a free or supported boundary, or a
// junction under the hinged rule) the slope is T's own unknown: no moment is carried across it,
// the natural condition of a free or simply supported edge; as it enters no other energy it is
// minimised out of B once, at rest (exact, a Schur complement of the 3×3 form). Next to a clamped triangle
// (all its vertices fixed: rigid) the whole fold is T's, s_T = −Δθ (a built-in edge).
//
// The edge unknowns enter W quadratically with a constant matrix, W = ½ Σ_T (P_T Δθ + S_T φ)ᵀ
// B_T (P_T Δθ + S_T φ), so for given positions they are eliminated exactly, φ*(x) =
// −A⁻¹ Σ_T S_Tᵀ B_T P_T Δθ(x), A = Σ_T S_Tᵀ B_T S_T factorised once; the energy is a function of
// the positions alone. Its tangent is the Schur complement of the sparse matrix in (x, φ), so the
// model's tangent matrix carries the edge unknowns after the positions (Model::pattern()): a
// Newton step solves that sparse system and uses its position part, which is exactly the Newton
// step of the reduced energy. Exactly invariant under rigid motions (only dihedral angles enter),
// exact for quadratic deflections on any mesh (the patch test), convergent on irregular meshes.
//
// Junctions (an edge of three or more walls): hinged — the walls rotate freely about the junction
// (no moment is carried from one wall into another); as in the hinge model the two outer-surface
// walls at a junction still bend as one sheet (the epidermis is continuous). Reason: the published
// model has no bending coupling between walls at a junction, and the middle lamella lets walls
// pivot. Rigid — the angles between all walls at the junction are kept: one wall R is the
// reference (a clamped one if there is one), its slope at the edge is the junction's unknown ψ,
// and every other wall T takes s_T = −Δθ_RT − ψ (its fold from R, and the same turn), so the
// walls turn together like a welded frame; a two-wall edge is the sheet case above.

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <array>
#include <memory>
#include <vector>

#include "mechanics/Material.h"
#include "mechanics/Math.h"
#include "mesh/CellComplex.h"
#include "mesh/Topology.h"

namespace tp {

/// The rest data of the plate-bending term of a whole complex.
struct PlateBending {
  /// A pair of triangles whose dihedral angle enters the energy (same vertex order as Hinge).
  struct Pair {
    std::array<int, 4> v{};
    double restAngle = 0;
  };
  /// Δs_k of a triangle's edge k gets coeff · (θ_pair − θ̄_pair).
  struct Ref {
    int pair = -1;
    double coeff = 0;
    std::array<int, 4> local{};  // the pair's vertices as indices into the element's vertex list
  };
  struct Element {
    Eigen::Matrix3d B = Eigen::Matrix3d::Zero();  // W = ½ Δsᵀ B Δs (µN·µm)
    std::array<int, 4> refBegin{};                 // refs of edge k: [refBegin[k], refBegin[k+1])
    std::array<int, 3> edgeUnknown{-1, -1, -1};    // φ of edge k (−1: none)
    std::array<double, 3> edgeSign{};              // Δs_k gets edgeSign[k] · φ
    std::array<bool, 3> ownSlope{};                // slope k is T's alone, minimised out of B
    bool live = false;                             // not rigid (some vertex free)
  };
  struct PairUse {
    int element = -1, edge = -1;
    double coeff = 0;
  };

  std::vector<Pair> pairs;
  std::vector<Element> elements;  // one per triangle, in triangle order
  std::vector<Ref> refs;
  // Element t's vertices (its triangle's three, then the wings; Ref::local indexes them):
  // elementVertices[vertexBegin[t] .. vertexBegin[t + 1]).
  std::vector<int> elementVertices, vertexBegin;
  // The elements that use pair p: pairUses[useBegin[p] .. useBegin[p + 1]).
  std::vector<PairUse> pairUses;
  std::vector<int> useBegin;
  int edgeUnknowns = 0;                        // number of φ
  /// A = Σ S_Tᵀ B_T S_T couples only the edge unknowns of one wall (or of the walls a rigid
  /// junction welds together): its connected components, dealt into blocks of about equal size,
  /// each factorised on its own, so that threads can solve the blocks side by side.
  struct EdgeBlock {
    struct Use {
      int element = -1, edge = -1, local = -1;  // element's edge k feeds the block's row `local`
    };
    std::vector<int> unknowns;  // the block's φ, in its local order
    std::vector<Use> uses;
    Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver;
  };
  /// The blocks of A, factorised (shared by the copies of a model's rest data).
  std::shared_ptr<const std::vector<EdgeBlock>> edgeBlocks;
  int maxArity = 3;  // largest element vertex count (3 + wings)
};

/// Builds the rest data: rest angles, the per-triangle quadratic forms (rigidity D, ratio ν).
PlateBending buildPlateBending(const CellComplex& cc, const Topology& topo, double D, double nu,
                               JunctionRule rule);

/// The part of element `element`'s slope changes Δs that comes from the pairs' angles θ (rad),
/// before the edge unknowns.
Eigen::Vector3d plateAngleSlopes(const PlateBending& pb, int element,
                                 const std::vector<double>& theta);

/// The edge unknowns that minimise the energy for the pairs' current angles θ (rad).
Eigen::VectorXd plateEdgeRotations(const PlateBending& pb, const std::vector<double>& theta);
/// The same from every element's angle part of Δs (plateAngleSlopes).
Eigen::VectorXd plateEdgeRotations(const PlateBending& pb,
                                   const std::vector<Eigen::Vector3d>& angleSlopes);

/// The edge unknowns of block b (PlateBending::edgeBlocks) from every element's angle part of Δs,
/// written into phi (sized edgeUnknowns); blocks are independent, so threads may share them out.
void plateEdgeRotationsOfBlock(const PlateBending& pb, int b,
                               const std::vector<Eigen::Vector3d>& angleSlopes,
                               Eigen::VectorXd& phi);

/// An element's slope changes Δs: its angle part plus its edge unknowns' turns.
Eigen::Vector3d plateSlopeChanges(const PlateBending& pb, int element,
                                  const Eigen::Vector3d& angleSlopes, const Eigen::VectorXd& phi);

/// Energy of one element for the pairs' angles θ and the edge unknowns φ; if ds is given, the
/// element's slope changes Δs are written to it.
double plateElementEnergy(const PlateBending& pb, int element, const std::vector<double>& theta,
                          const Eigen::VectorXd& phi, Eigen::Vector3d* ds = nullptr);

/// Total plate-bending energy (pJ) at positions x, and optionally the energy of every triangle.
double plateBendingEnergy(const PlateBending& pb, const Points& x,
                          std::vector<double>* perTriangle = nullptr);

}  // namespace tp
