#include "mechanics/PlateBending.h"

#include <Eigen/Dense>
#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <cstdint>

#include "mechanics/Bending.h"

namespace tp {

namespace {

// The pair (tA, tB) across edge (a, b), ordered as the hinge model orders it (mesh/Topology.cpp):
// the edge runs as in tA's winding, v = {x0, x1, wing of tA, wing of tB}.
std::array<int, 4> pairVertices(const CellComplex& cc, int a, int b, int tA, int tB) {
  auto opposite = [&](int t) {
    for (int v : cc.triangles[t])
      if (v != a && v != b) return v;
    return -1;
  };
  const auto& tri = cc.triangles[tA];
  int x0 = a, x1 = b;
  for (int k = 0; k < 3; ++k)
    if (tri[k] == b && tri[(k + 1) % 3] == a) std::swap(x0, x1);
  return {x0, x1, opposite(tA), opposite(tB)};
}

// +1 when the directed edge (p, q) runs as in triangle t's stored winding, −1 otherwise.
int orientation(const CellComplex& cc, int t, int p, int q) {
  const auto& tri = cc.triangles[t];
  for (int k = 0; k < 3; ++k)
    if (tri[k] == p) return tri[(k + 1) % 3] == q ? 1 : -1;
  return 1;
}

double wrapAngle(double d) {
  if (d > std::numbers::pi) d -= 2 * std::numbers::pi;
  if (d <= -std::numbers::pi) d += 2 * std::numbers::pi;
  return d;
}

// B of one triangle: W = ½ Δsᵀ B Δs from the Koiter form of ΔS = J⁻ᵀ II(c) J⁻¹ and the bubble
// coefficients c = M⁻¹ (2 h ∘ s), M = [[1,−1,−1],[−1,1,−1],[−1,−1,1]] (the slopes of the bubbles
// at the mid-edges, see the header).
Eigen::Matrix3d morleyMatrix(const Vec3& Q0, const Vec3& Q1, const Vec3& Q2, double D, double nu) {
  const Vec3 normal = (Q1 - Q0).cross(Q2 - Q0);
  const double area = 0.5 * normal.norm();
  const Vec3 e1 = (Q1 - Q0).normalized(), e2 = normal.normalized().cross(e1);
  Eigen::Matrix2d J;
  J << (Q1 - Q0).dot(e1), (Q2 - Q0).dot(e1), 0.0, (Q2 - Q0).dot(e2);
  const Eigen::Matrix2d Jinv = J.inverse();
  std::array<Eigen::Matrix2d, 3> S;
  for (int i = 0; i < 3; ++i) {
    const Eigen::Vector3d c = Eigen::Vector3d::Unit(i);
    Eigen::Matrix2d II;
    II << -2 * c(2), c(0) - c(1) - c(2), c(0) - c(1) - c(2), -2 * c(1);
    S[i] = Jinv.transpose() * II * Jinv;
  }
  Eigen::Matrix3d Q;  // W = ½ cᵀ Q c
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      Q(i, j) = area * D * (nu * S[i].trace() * S[j].trace() + (1 - nu) * (S[i] * S[j]).trace());
  Eigen::Matrix3d M;
  M << 1, -1, -1, -1, 1, -1, -1, -1, 1;
  const Vec3 Qs[3] = {Q0, Q1, Q2};
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();  // 2 h_i: twice the height on edge i
  for (int i = 0; i < 3; ++i) {
    const Vec3 a = Qs[(i + 1) % 3], b = Qs[(i + 2) % 3];
    H(i, i) = 2.0 * (2.0 * area / (b - a).norm());
  }
  const Eigen::Matrix3d C = M.inverse() * H;  // c = C s
  const Eigen::Matrix3d B = C.transpose() * Q * C;
  return 0.5 * (B + B.transpose());
}

}  // namespace

PlateBending buildPlateBending(const CellComplex& cc, const Topology& topo, double D, double nu,
                               JunctionRule rule) {
  PlateBending pb;
  const Points& X = cc.rest;
  auto isLive = [&](int t) {
    const auto& tri = cc.triangles[t];
    return !(cc.fixed[tri[0]] && cc.fixed[tri[1]] && cc.fixed[tri[2]]);
  };
  std::vector<std::array<int, 2>> pairTris;
  auto addPair = [&](int a, int b, int tA, int tB) {
    PlateBending::Pair p;
    p.v = pairVertices(cc, a, b, tA, tB);
    p.restAngle = dihedralAngle(X.col(p.v[0]), X.col(p.v[1]), X.col(p.v[2]), X.col(p.v[3]),
                                nullptr, nullptr);
    pb.pairs.push_back(p);
    pairTris.push_back({tA, tB});
  };
  // Rigid junctions: every wall at the edge is paired with one reference wall R (a rigid one if
  // there is one, the junction is then built in); R's slope at the edge is the junction's own
  // unknown ψ, and each other wall's slope is −(its fold from R) − ψ, so all walls turn together.
  std::vector<int> junctionReference(topo.edges.size(), -1);
  std::vector<std::vector<int>> edgeOfTriangle(cc.triangleCount());
  for (size_t e = 0; e < topo.edges.size(); ++e) {
    const auto& tris = topo.edgeTriangles[e];
    const auto [a, b] = topo.edges[e];
    if (tris.size() == 2) {
      addPair(a, b, tris[0], tris[1]);
    } else if (tris.size() > 2 && rule == JunctionRule::Hinged) {
      std::vector<int> outer;
      for (int t : tris)
        if (cc.isOuterTriangle(t)) outer.push_back(t);
      if (outer.size() == 2) addPair(a, b, outer[0], outer[1]);
    } else if (tris.size() > 2) {
      int ref = tris[0];
      for (int t : tris)
        if (!isLive(t)) ref = t;
      junctionReference[e] = ref;
      for (int t : tris)
        if (t != ref) addPair(a, b, ref, t);
    }
  }
  std::vector<std::vector<int>> trianglePairs(cc.triangleCount());
  for (size_t p = 0; p < pairTris.size(); ++p)
    for (int t : pairTris[p]) trianglePairs[t].push_back(static_cast<int>(p));
  std::vector<std::vector<PlateBending::PairUse>> pairUses(pb.pairs.size());
  std::vector<int> pairUnknown(pb.pairs.size(), -1);
  std::vector<int> junctionUnknown(topo.edges.size(), -1);
  // The rigid junction at edge (a, b), if any: its index into topo.edges.
  std::unordered_map<std::uint64_t, int> edgeIndex;
  if (rule == JunctionRule::Rigid)
    for (size_t e = 0; e < topo.edges.size(); ++e)
      if (junctionReference[e] >= 0)
        edgeIndex[(static_cast<std::uint64_t>(topo.edges[e][0]) << 32) |
                  static_cast<std::uint32_t>(topo.edges[e][1])] = static_cast<int>(e);
  auto rigidJunction = [&](int a, int b) {
    if (a > b) std::swap(a, b);
    const auto it = edgeIndex.find((static_cast<std::uint64_t>(a) << 32) | static_cast<std::uint32_t>(b));
    return it == edgeIndex.end() ? -1 : it->second;
  };

  pb.elements.resize(cc.triangleCount());
  pb.vertexBegin.assign(1, 0);
  for (int t = 0; t < cc.triangleCount(); ++t) {
    PlateBending::Element& el = pb.elements[t];
    const auto& tri = cc.triangles[t];
    auto& verts = pb.elementVertices;  // T's own list is its tail, from pb.vertexBegin[t]
    verts.insert(verts.end(), tri.begin(), tri.end());
    el.live = isLive(t);
    const Vec3 Q0 = X.col(tri[0]), Q1 = X.col(tri[1]), Q2 = X.col(tri[2]);
    const double area = 0.5 * (Q1 - Q0).cross(Q2 - Q0).norm();
    const double scale = std::max({(Q1 - Q0).squaredNorm(), (Q2 - Q0).squaredNorm(),
                                   (Q2 - Q1).squaredNorm()});
    const bool usable = el.live && std::isfinite(area) && area > 1e-10 * scale;
    std::array<bool, 3>& ownSlope = el.ownSlope;
    for (int k = 0; k < 3; ++k) {
      el.refBegin[k] = static_cast<int>(pb.refs.size());
      if (!usable) continue;
      const int ea = tri[(k + 1) % 3], eb = tri[(k + 2) % 3];
      const int junction = rule == JunctionRule::Rigid ? rigidJunction(ea, eb) : -1;
      if (junction >= 0 && junctionReference[junction] == t) {  // R itself: s_R = σ_R ψ
        if (junctionUnknown[junction] < 0) junctionUnknown[junction] = pb.edgeUnknowns++;
        el.edgeUnknown[k] = junctionUnknown[junction];
        int sigma = 1;
        for (int p : trianglePairs[t])
          if (pairTris[p][0] == t) {
            const auto& v = pb.pairs[p].v;
            if ((v[0] == ea && v[1] == eb) || (v[0] == eb && v[1] == ea))
              sigma = orientation(cc, t, v[0], v[1]);
          }
        el.edgeSign[k] = sigma;
        continue;
      }
      int pair = -1;
      for (int p : trianglePairs[t]) {
        const auto& v = pb.pairs[p].v;
        if ((v[0] == ea && v[1] == eb) || (v[0] == eb && v[1] == ea)) pair = p;
      }
      if (pair < 0) {  // a free, supported or hinged edge: its slope is T's alone (condensed below)
        ownSlope[k] = true;
        continue;
      }
      const auto& v = pb.pairs[pair].v;
      const bool asA = pairTris[pair][0] == t;
      const int other = asA ? pairTris[pair][1] : pairTris[pair][0];
      // The fold, measured along the normal the pair gives T, turned to T's stored winding.
      const int sigma = asA ? orientation(cc, t, v[0], v[1]) : orientation(cc, t, v[1], v[0]);
      PlateBending::Ref r;
      r.pair = pair;
      if (junction >= 0) {
        // Another wall at a rigid junction: s_T = σ_T (−Δθ_RT − ψ), ψ absent when R is rigid.
        r.coeff = -1.0 * sigma;
        if (isLive(junctionReference[junction])) {
          if (junctionUnknown[junction] < 0) junctionUnknown[junction] = pb.edgeUnknowns++;
          el.edgeUnknown[k] = junctionUnknown[junction];
          el.edgeSign[k] = -sigma;
        }
      } else if (isLive(other)) {
        r.coeff = -0.5 * sigma;
        if (pairUnknown[pair] < 0) pairUnknown[pair] = pb.edgeUnknowns++;
        el.edgeUnknown[k] = pairUnknown[pair];
        el.edgeSign[k] = asA ? sigma : -sigma;
      } else {
        r.coeff = -1.0 * sigma;  // built in: the whole fold is T's
      }
      for (int i = 0; i < 4; ++i) {
        const auto first = verts.begin() + pb.vertexBegin[t];
        auto it = std::find(first, verts.end(), v[i]);
        r.local[i] = static_cast<int>(it - first);
        if (it == verts.end()) verts.push_back(v[i]);
      }
      pairUses[pair].push_back({t, k, r.coeff});
      pb.refs.push_back(r);
    }
    el.refBegin[3] = static_cast<int>(pb.refs.size());
    pb.vertexBegin.push_back(static_cast<int>(verts.size()));
    pb.maxArity = std::max(pb.maxArity, pb.vertexBegin[t + 1] - pb.vertexBegin[t]);
    if (!usable) continue;
    el.B = morleyMatrix(Q0, Q1, Q2, D, nu);
    // A slope that is T's alone appears in no other energy: minimise it out here (exactly), so
    // only the slopes two walls share are global unknowns. B ← B_kk − B_ko B_oo⁻¹ B_ok.
    std::vector<int> own, kept;
    for (int k = 0; k < 3; ++k) (ownSlope[k] ? own : kept).push_back(k);
    if (!own.empty()) {
      Eigen::Matrix3d Bc = Eigen::Matrix3d::Zero();
      if (!kept.empty()) {
        const int no = static_cast<int>(own.size()), nk = static_cast<int>(kept.size());
        Eigen::MatrixXd Boo(no, no), Bok(no, nk), Bkk(nk, nk);
        for (int i = 0; i < no; ++i)
          for (int j = 0; j < no; ++j) Boo(i, j) = el.B(own[i], own[j]);
        for (int i = 0; i < no; ++i)
          for (int j = 0; j < nk; ++j) Bok(i, j) = el.B(own[i], kept[j]);
        for (int i = 0; i < nk; ++i)
          for (int j = 0; j < nk; ++j) Bkk(i, j) = el.B(kept[i], kept[j]);
        const Eigen::MatrixXd S = Bkk - Bok.transpose() * Boo.ldlt().solve(Bok);
        for (int i = 0; i < nk; ++i)
          for (int j = 0; j < nk; ++j) Bc(kept[i], kept[j]) = 0.5 * (S(i, j) + S(j, i));
      }
      el.B = Bc;
    }
  }

  pb.useBegin.assign(1, 0);
  for (const auto& uses : pairUses) {
    pb.pairUses.insert(pb.pairUses.end(), uses.begin(), uses.end());
    pb.useBegin.push_back(static_cast<int>(pb.pairUses.size()));
  }

  // A = Σ S_Tᵀ B_T S_T over the edge unknowns (SPD: every unknown sits in a live triangle), in
  // blocks: its connected components (union–find over its entries), the largest first, each
  // dealt to the block with the fewest unknowns so far.
  const int U = pb.edgeUnknowns;
  std::vector<int> root(U);
  for (int u = 0; u < U; ++u) root[u] = u;
  const auto find = [&](int u) {
    while (root[u] != u) u = root[u] = root[root[u]];
    return u;
  };
  for (const auto& el : pb.elements)
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j)
        if (el.edgeUnknown[i] >= 0 && el.edgeUnknown[j] >= 0 && el.B(i, j) != 0.0)
          root[find(el.edgeUnknown[i])] = find(el.edgeUnknown[j]);
  std::vector<int> componentSize(U, 0);
  for (int u = 0; u < U; ++u) ++componentSize[find(u)];
  std::vector<int> components;
  for (int u = 0; u < U; ++u)
    if (root[u] == u) components.push_back(u);
  std::stable_sort(components.begin(), components.end(),
                   [&](int a, int b) { return componentSize[a] > componentSize[b]; });
  constexpr int kBlocks = 8;  // enough to balance two to four threads
  const int blockCount = std::min<int>(kBlocks, static_cast<int>(components.size()));
  std::vector<int> blockOfComponent(U, -1), blockSize(blockCount, 0);
  for (int c : components) {
    const int b =
        static_cast<int>(std::min_element(blockSize.begin(), blockSize.end()) - blockSize.begin());
    blockOfComponent[c] = b;
    blockSize[b] += componentSize[c];
  }
  auto blocks = std::make_shared<std::vector<PlateBending::EdgeBlock>>(blockCount);
  std::vector<int> blockOf(U), localOf(U);
  for (int u = 0; u < U; ++u) {
    const int b = blockOfComponent[find(u)];
    blockOf[u] = b;
    localOf[u] = static_cast<int>((*blocks)[b].unknowns.size());
    (*blocks)[b].unknowns.push_back(u);
  }
  std::vector<std::vector<Eigen::Triplet<double>>> trips(blockCount);
  for (size_t t = 0; t < pb.elements.size(); ++t) {
    const auto& el = pb.elements[t];
    for (int i = 0; i < 3; ++i) {
      const int ui = el.edgeUnknown[i];
      if (ui < 0) continue;
      auto& block = (*blocks)[blockOf[ui]];
      block.uses.push_back({static_cast<int>(t), i, localOf[ui]});
      for (int j = 0; j < 3; ++j)
        if (el.edgeUnknown[j] >= 0)
          trips[blockOf[ui]].emplace_back(localOf[ui], localOf[el.edgeUnknown[j]],
                                          el.edgeSign[i] * el.B(i, j) * el.edgeSign[j]);
    }
  }
  for (int b = 0; b < blockCount; ++b) {
    auto& block = (*blocks)[b];
    const int n = static_cast<int>(block.unknowns.size());
    Eigen::SparseMatrix<double> A(n, n);
    A.setFromTriplets(trips[b].begin(), trips[b].end());
    block.solver.compute(A);
    if (block.solver.info() != Eigen::Success || !(block.solver.vectorD().minCoeff() > 0))
      throw std::runtime_error("plate bending: the mid-edge unknowns are not determined (a "
                               "degenerate triangle in a wall)");
  }
  pb.edgeBlocks = blocks;
  return pb;
}

Eigen::Vector3d plateAngleSlopes(const PlateBending& pb, int element,
                                 const std::vector<double>& theta) {
  const auto& el = pb.elements[element];
  Eigen::Vector3d ds = Eigen::Vector3d::Zero();
  for (int k = 0; k < 3; ++k)
    for (int r = el.refBegin[k]; r < el.refBegin[k + 1]; ++r) {
      const auto& ref = pb.refs[r];
      ds(k) += ref.coeff * wrapAngle(theta[ref.pair] - pb.pairs[ref.pair].restAngle);
    }
  return ds;
}

void plateEdgeRotationsOfBlock(const PlateBending& pb, int b,
                               const std::vector<Eigen::Vector3d>& angleSlopes,
                               Eigen::VectorXd& phi) {
  const auto& block = (*pb.edgeBlocks)[b];
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(block.unknowns.size()));
  for (const auto& use : block.uses) {
    const auto& el = pb.elements[use.element];
    rhs(use.local) -= el.edgeSign[use.edge] * el.B.row(use.edge).dot(angleSlopes[use.element]);
  }
  const Eigen::VectorXd local = block.solver.solve(rhs);
  for (size_t i = 0; i < block.unknowns.size(); ++i) phi(block.unknowns[i]) = local(i);
}

Eigen::VectorXd plateEdgeRotations(const PlateBending& pb,
                                   const std::vector<Eigen::Vector3d>& angleSlopes) {
  Eigen::VectorXd phi = Eigen::VectorXd::Zero(pb.edgeUnknowns);
  for (int b = 0; b < static_cast<int>(pb.edgeBlocks->size()); ++b)
    plateEdgeRotationsOfBlock(pb, b, angleSlopes, phi);
  return phi;
}

Eigen::VectorXd plateEdgeRotations(const PlateBending& pb, const std::vector<double>& theta) {
  std::vector<Eigen::Vector3d> slopes(pb.elements.size());
  for (size_t t = 0; t < slopes.size(); ++t)
    slopes[t] = plateAngleSlopes(pb, static_cast<int>(t), theta);
  return plateEdgeRotations(pb, slopes);
}

Eigen::Vector3d plateSlopeChanges(const PlateBending& pb, int element,
                                  const Eigen::Vector3d& angleSlopes, const Eigen::VectorXd& phi) {
  const auto& el = pb.elements[element];
  Eigen::Vector3d ds = angleSlopes;
  for (int k = 0; k < 3; ++k)
    if (el.edgeUnknown[k] >= 0) ds(k) += el.edgeSign[k] * phi(el.edgeUnknown[k]);
  return ds;
}

double plateElementEnergy(const PlateBending& pb, int element, const std::vector<double>& theta,
                          const Eigen::VectorXd& phi, Eigen::Vector3d* dsOut) {
  const Eigen::Vector3d ds =
      plateSlopeChanges(pb, element, plateAngleSlopes(pb, element, theta), phi);
  if (dsOut) *dsOut = ds;
  return 0.5 * ds.dot(pb.elements[element].B * ds);
}

double plateBendingEnergy(const PlateBending& pb, const Points& x, std::vector<double>* perTriangle) {
  std::vector<double> theta(pb.pairs.size());
  for (size_t p = 0; p < pb.pairs.size(); ++p) {
    const auto& v = pb.pairs[p].v;
    theta[p] = dihedralAngle(x.col(v[0]), x.col(v[1]), x.col(v[2]), x.col(v[3]), nullptr, nullptr);
  }
  const Eigen::VectorXd phi = plateEdgeRotations(pb, theta);
  double total = 0;
  if (perTriangle) perTriangle->assign(pb.elements.size(), 0.0);
  for (size_t t = 0; t < pb.elements.size(); ++t) {
    const double w = plateElementEnergy(pb, static_cast<int>(t), theta, phi);
    total += w;
    if (perTriangle) (*perTriangle)[t] = w;
  }
  return total;
}

}  // namespace tp
