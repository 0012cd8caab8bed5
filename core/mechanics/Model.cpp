#include "mechanics/Model.h"

#include <Eigen/Dense>
#include <algorithm>
#include <limits>
#include <cmath>
#include <stdexcept>

#include "mechanics/Pressure.h"

#include <omp.h>

namespace tp {

namespace {

// Adds one element's gradient and Hessian into the global arrays (the only assembly routine).
template <int M>
inline void scatter(const int* verts, const int* slots, const Eigen::Matrix<double, M, 1>& g,
                    const Eigen::Matrix<double, M, M>* H, double* grad, double* values) {
  for (int i = 0; i < M; ++i) grad[3 * verts[i / 3] + i % 3] += g[i];
  if (!H) return;
  for (int i = 0; i < M; ++i)
    for (int j = 0; j < M; ++j) {
      const int s = slots[i * M + j];
      if (s >= 0) values[s] += (*H)(i, j);
    }
}

std::vector<std::uint8_t> dofsFromVertices(const std::vector<std::uint8_t>& fixed) {
  std::vector<std::uint8_t> d(3 * fixed.size());
  for (size_t v = 0; v < fixed.size(); ++v) d[3 * v] = d[3 * v + 1] = d[3 * v + 2] = fixed[v];
  return d;
}

}  // namespace

Model::Model(std::shared_ptr<const CellComplex> cc, const Material& material)
    : cc_(std::move(cc)), topo_(buildTopology(*cc_)), material_(material) {
  material_.validate();
  const CellComplex& c = *cc_;
  const Points& X = c.rest;
  membraneRest_.reserve(c.triangleCount());
  for (const auto& t : c.triangles) membraneRest_.push_back(membraneRest(X.col(t[0]), X.col(t[1]), X.col(t[2])));
  const double D = material_.bendingRigidity();
  for (const auto& h : topo_.hinges) {
    const auto& v = h.v;
    hingeRest_.push_back(hingeRest(X.col(v[0]), X.col(v[1]), X.col(v[2]), X.col(v[3]), D));
    linearRest_.push_back(linearBendingRest(X.col(v[0]), X.col(v[1]), X.col(v[2]), X.col(v[3]), D));
  }
  if (material_.bending == BendingModel::Koiter) {
    plate_ = buildPlateBending(c, topo_, D, material_.poissonRatio, material_.junctions);
    if (plate_.maxArity > kMaxPlateArity)  // each edge has one pair at most (PlateBending.cpp)
      throw std::logic_error("Koiter bending: an element with more than one wing per edge");
    for (const auto& pr : plate_.pairs) pairVerts_.insert(pairVerts_.end(), pr.v.begin(), pr.v.end());
  }
  for (const auto& r : membraneRest_)
    membraneMagnitude_ += 2.0 * (material_.mu() + material_.lambdaPlaneStress()) * material_.thickness * r.area;
  double sum = 0;
  for (const auto& e : topo_.edges) sum += (X.col(e[0]) - X.col(e[1])).norm();
  meanEdge_ = topo_.edges.empty() ? 1.0 : sum / topo_.edges.size();

  triangleVerts_.reserve(3 * c.triangleCount());
  for (const auto& t : c.triangles) triangleVerts_.insert(triangleVerts_.end(), {t[0], t[1], t[2]});
  hingeVerts_.reserve(4 * topo_.hinges.size());
  for (const auto& h : topo_.hinges) hingeVerts_.insert(hingeVerts_.end(), h.v.begin(), h.v.end());

  cellPressure_.assign(c.cellCount(), 0.0);
  contact_.stiffness = 1e3 * material_.youngModulus * material_.thickness;
  contact_.smoothing = 1e-3 * meanEdge_;
  setFixedDofs(dofsFromVertices(c.fixed));
}

void Model::setFixedDofs(const std::vector<std::uint8_t>& fixedDof) {
  if (static_cast<int>(fixedDof.size()) != 3 * cc_->vertexCount())
    throw std::invalid_argument("setFixedDofs: expected 3 flags per vertex");
  dofs_ = DofMap(fixedDof);
  if (material_.bending != BendingModel::Koiter) {
    std::vector<std::pair<int, std::span<const int>>> sets{{3, triangleVerts_}};
    if (material_.bending != BendingModel::None) sets.emplace_back(4, hingeVerts_);
    pattern_ = buildPattern(dofs_, cc_->vertexCount(), sets);
    triangleSlots_ = SlotTable(pattern_, dofs_, 3, triangleVerts_);
    if (material_.bending != BendingModel::None)
      hingeSlots_ = SlotTable(pattern_, dofs_, 4, hingeVerts_);
    return;
  }
  // Koiter: the edge unknowns follow the free position components.
  const int nFree = dofs_.freeCount();
  const int T = cc_->triangleCount();
  std::vector<int> triangleUnknowns(9 * T);
  for (int t = 0; t < T; ++t)
    for (int i = 0; i < 9; ++i) triangleUnknowns[9 * t + i] = dofs_.index(3 * triangleVerts_[3 * t + i / 3] + i % 3);
  plateUnknowns_.clear();
  plateUnknownBegin_.assign(1, 0);
  for (int t = 0; t < T; ++t) {
    const auto& el = plate_.elements[t];
    if (el.refBegin[3] > el.refBegin[0] || el.edgeUnknown[0] >= 0 || el.edgeUnknown[1] >= 0 ||
        el.edgeUnknown[2] >= 0) {
      for (int v : el.vertices)
        for (int k = 0; k < 3; ++k) plateUnknowns_.push_back(dofs_.index(3 * v + k));
      for (int k = 0; k < 3; ++k)
        if (el.edgeUnknown[k] >= 0) plateUnknowns_.push_back(nFree + el.edgeUnknown[k]);
    }
    plateUnknownBegin_.push_back(static_cast<int>(plateUnknowns_.size()));
  }
  std::vector<std::span<const int>> lists;
  for (int t = 0; t < T; ++t) lists.emplace_back(&triangleUnknowns[9 * t], 9);
  for (int t = 0; t < T; ++t)
    if (plateUnknownBegin_[t + 1] > plateUnknownBegin_[t])
      lists.emplace_back(plateUnknowns_.data() + plateUnknownBegin_[t],
                         plateUnknownBegin_[t + 1] - plateUnknownBegin_[t]);
  pattern_ = buildPatternFromUnknowns(nFree + plate_.edgeUnknowns, lists);
  triangleSlots_ = SlotTable(pattern_, dofs_, 3, triangleVerts_);
  pairSlots_ = SlotTable(pattern_, dofs_, 4, pairVerts_);  // a pair lies inside its elements
  plateSlots_.clear();
  plateSlotBegin_.assign(1, 0);
  for (int t = 0; t < T; ++t) {
    const int* u = plateUnknowns_.data() + plateUnknownBegin_[t];
    const int m = plateUnknownBegin_[t + 1] - plateUnknownBegin_[t];
    for (int i = 0; i < m; ++i)
      for (int j = i; j < m; ++j) {
        if (u[i] < 0 || u[j] < 0) {
          plateSlots_.push_back(-1);
          continue;
        }
        const int pos = pattern_.find(std::min(u[i], u[j]), std::max(u[i], u[j]));
        if (pos < 0) throw std::logic_error("Koiter element entry missing from the pattern");
        plateSlots_.push_back(pos);
      }
    plateSlotBegin_.push_back(static_cast<int>(plateSlots_.size()));
  }
}

void Model::setCellPressures(std::vector<double> pressures) {
  if (static_cast<int>(pressures.size()) != cc_->cellCount())
    throw std::invalid_argument("setCellPressures: expected one pressure per cell");
  for (double p : pressures)
    if (!std::isfinite(p)) throw std::invalid_argument("setCellPressures: non-finite pressure");
  cellPressure_ = std::move(pressures);
  rebuildPressureLoads();
}

void Model::setUniformPressure(double p) {
  setCellPressures(std::vector<double>(cc_->cellCount(), p));
}

void Model::rebuildPressureLoads() {
  pressureLoads_.clear();
  const CellComplex& c = *cc_;
  for (int t = 0; t < c.triangleCount(); ++t) {
    const Wall& w = c.walls[c.triangleWall[t]];
    const double pin = w.cell >= 0 ? cellPressure_[w.cell] : 0.0;
    const double pout = w.neighbor >= 0 ? cellPressure_[w.neighbor] : 0.0;
    if (pin != pout) pressureLoads_.emplace_back(t, pin - pout);
  }
}

void Model::setProbe(const Probe& probe) {
  if (!(probe.radius > 0) || !probe.center.allFinite())
    throw std::invalid_argument("probe radius must be positive and its centre finite");
  probe_ = probe;
}

template <class Fn>
void Model::forContactTriangles(const Points& x, Fn&& fn) const {
  if (!probe_) return;
  const Vec3 p = probe_->center;
  const double r = probe_->radius;
  for (int t : topo_.outerTriangles) {
    const auto& tri = cc_->triangles[t];
    const Vec3 a = x.col(tri[0]), b = x.col(tri[1]), c = x.col(tri[2]);
    const Vec3 lo = a.cwiseMin(b).cwiseMin(c).array() - r;
    const Vec3 hi = a.cwiseMax(b).cwiseMax(c).array() + r;
    if ((p.array() < lo.array()).any() || (p.array() > hi.array()).any()) continue;
    fn(t, a, b, c);
  }
}

double Model::probeDistance(const Points& x) const {
  if (!probe_) return std::numeric_limits<double>::infinity();
  double d2 = std::numeric_limits<double>::infinity();
  for (int t : topo_.outerTriangles) {
    const auto& tri = cc_->triangles[t];
    d2 = std::min(d2, pointTriangleDistance2(probe_->center, x.col(tri[0]), x.col(tri[1]),
                                             x.col(tri[2]), nullptr, nullptr, nullptr));
  }
  return std::sqrt(d2);
}

double Model::contactStepBound(const Points& x, const Points& dx, const Vec3& dp) const {
  if (!probe_) return 1.0;
  const double clearance = contactClearance();
  const Vec3& p = probe_->center;
  double bound = 1.0;
  for (int t : topo_.outerTriangles) {
    const auto& tri = cc_->triangles[t];
    double speed = 0;  // the largest vertex displacement relative to the probe over the step
    for (int k = 0; k < 3; ++k) speed = std::max(speed, (dx.col(tri[k]) - dp).norm());
    auto distanceAt = [&](double a) {
      return std::sqrt(pointTriangleDistance2(p + a * dp, x.col(tri[0]) + a * dx.col(tri[0]),
                                              x.col(tri[1]) + a * dx.col(tri[1]),
                                              x.col(tri[2]) + a * dx.col(tri[2]), nullptr,
                                              nullptr, nullptr));
    };
    double d = distanceAt(0.0);
    if (!(d > clearance)) return 0.0;
    if (d - speed * bound >= clearance) continue;  // cannot come within the clearance
    // Advance while the bound guarantees the clearance; stop once within 1 % of it (the
    // distance can then close at most 1 % of the clearance before the next check).
    double a = 0;
    for (int it = 0; it < 50 && a < bound; ++it) {
      const double gap = d - clearance;
      if (gap <= 0.01 * clearance) break;
      a = std::min(bound, a + gap / speed);
      d = distanceAt(a);
      if (!(d > clearance)) {  // round-off at the clearance: step back inside the guarantee
        a = std::max(0.0, a - 0.01 * clearance / speed);
        break;
      }
    }
    bound = std::min(bound, a);
  }
  return bound;
}

double Model::energy(const Points& x, EnergyParts* parts) const {
  EnergyParts e;
  const CellComplex& c = *cc_;
  const double mu = material_.mu(), lam = material_.lambdaPlaneStress(), h = material_.thickness;
  for (int t = 0; t < c.triangleCount(); ++t) {
    const auto& tri = c.triangles[t];
    e.membrane += membraneEnergy(membraneRest_[t], x.col(tri[0]), x.col(tri[1]), x.col(tri[2]), mu,
                                 lam, h, nullptr, nullptr);
  }
  e.magnitude += membraneMagnitude_;
  if (material_.bending == BendingModel::Koiter)
    e.bending = plateBendingEnergy(plate_, x);
  else if (material_.bending != BendingModel::None)
    for (size_t k = 0; k < topo_.hinges.size(); ++k) {
      const auto& v = topo_.hinges[k].v;
      e.bending += material_.bending == BendingModel::Hinge
                       ? hingeEnergy(hingeRest_[k], x.col(v[0]), x.col(v[1]), x.col(v[2]),
                                     x.col(v[3]), nullptr, nullptr)
                       : linearBendingEnergy(linearRest_[k], x.col(v[0]), x.col(v[1]),
                                             x.col(v[2]), x.col(v[3]), nullptr, nullptr);
    }
  for (const auto& [t, dp] : pressureLoads_) {
    const auto& tri = c.triangles[t];
    const double w = pressureEnergy(dp, x.col(tri[0]), x.col(tri[1]), x.col(tri[2]), nullptr, nullptr);
    e.pressure += w;
    e.magnitude += std::abs(w);
  }
  forContactTriangles(x, [&](int, const Vec3& a, const Vec3& b, const Vec3& cc) {
    e.contact += sphereTriangleEnergy(contact_, probe_->center, probe_->radius, a, b, cc, nullptr,
                                      nullptr);
  });
  for (const auto& [v, f] : pointForces_) {
    e.external -= f.dot(x.col(v));
    e.magnitude += std::abs(f.dot(x.col(v)));
  }
  e.magnitude += std::abs(e.bending) + std::abs(e.contact);
  if (parts) *parts = e;
  return e.total();
}

void Model::evaluate(const Points& x, Evaluation& out, bool withHessian) const {
  const CellComplex& c = *cc_;
  const int V = c.vertexCount();
  out.energy = EnergyParts{};
  out.gradient.setZero(3 * V);
  out.loadGradient.setZero(3 * V);
  out.probeGradient.setZero();
  out.probeHessian.setZero();
  out.probeCoupling.setZero(3 * V, 3);
  out.contactTriangles = 0;
  if (withHessian) out.hessian.assign(pattern_.nnz(), 0.0);
  out.hasHessian = withHessian;
  out.contactProjected = withHessian && projectContact_;
  double* grad = out.gradient.data();
  double* load = out.loadGradient.data();
  double* vals = withHessian ? out.hessian.data() : nullptr;

  const double mu = material_.mu(), lam = material_.lambdaPlaneStress(), h = material_.thickness;
  // Membrane and bending elements in parallel: each thread scatters into its own gradient and
  // value arrays (thread 0 straight into the output), summed afterwards. Static scheduling keeps
  // the result the same from run to run for a given number of threads.
  const int threads = omp_get_max_threads();
  if (static_cast<int>(threadGrad_.size()) < threads) {
    threadGrad_.resize(threads);
    threadVals_.resize(threads);
  }
  double membrane = 0, bending = 0;
  const int T = c.triangleCount();
  const bool koiter = material_.bending == BendingModel::Koiter;
  const int H = material_.bending == BendingModel::None || koiter
                    ? 0 : static_cast<int>(topo_.hinges.size());
  const int P = koiter ? static_cast<int>(plate_.pairs.size()) : 0;
  if (koiter) {
    pairTheta_.resize(P);
    pairGrad_.resize(P);
    plateY_.assign(T, Eigen::Vector3d::Zero());
  }
#pragma omp parallel num_threads(threads) reduction(+ : membrane, bending)
  {
    const int tid = omp_get_thread_num();
    double* g = grad;
    double* v = vals;
    if (tid > 0) {
      threadGrad_[tid].assign(3 * V, 0.0);
      g = threadGrad_[tid].data();
      if (withHessian) {
        threadVals_[tid].assign(pattern_.nnz(), 0.0);
        v = threadVals_[tid].data();
      }
    }
    Vec9 g9;
    Mat9 H9;
#pragma omp for schedule(static) nowait
    for (int t = 0; t < T; ++t) {
      const auto& tri = c.triangles[t];
      membrane += membraneEnergy(membraneRest_[t], x.col(tri[0]), x.col(tri[1]), x.col(tri[2]),
                                 mu, lam, h, &g9, withHessian ? &H9 : nullptr);
      scatter<9>(&triangleVerts_[3 * t], triangleSlots_.element(t), g9,
                 withHessian ? &H9 : nullptr, g, v);
    }
    Vec12 g12;
    Mat12 H12;
#pragma omp for schedule(static) nowait
    for (int k = 0; k < H; ++k) {
      const auto& hv = topo_.hinges[k].v;
      bending += material_.bending == BendingModel::Hinge
                     ? hingeEnergy(hingeRest_[k], x.col(hv[0]), x.col(hv[1]), x.col(hv[2]),
                                   x.col(hv[3]), &g12, withHessian ? &H12 : nullptr)
                     : linearBendingEnergy(linearRest_[k], x.col(hv[0]), x.col(hv[1]),
                                           x.col(hv[2]), x.col(hv[3]), &g12,
                                           withHessian ? &H12 : nullptr);
      scatter<12>(&hingeVerts_[4 * k], hingeSlots_.element(k), g12, withHessian ? &H12 : nullptr,
                  g, v);
    }
    if (koiter) bending += evaluatePlate(x, g, v, withHessian);
  }
  for (int tid = 1; tid < threads; ++tid) {
    if (threadGrad_[tid].empty()) continue;
    for (int i = 0; i < 3 * V; ++i) grad[i] += threadGrad_[tid][i];
    if (withHessian)
      for (int i = 0; i < pattern_.nnz(); ++i) vals[i] += threadVals_[tid][i];
  }
  out.energy.membrane = membrane;
  out.energy.bending = bending;
  Vec9 g9;
  Mat9 H9;
  Vec12 g12;
  Mat12 H12;
  for (const auto& [t, dp] : pressureLoads_) {
    const auto& tri = c.triangles[t];
    const double w = pressureEnergy(dp, x.col(tri[0]), x.col(tri[1]), x.col(tri[2]), &g9,
                                    withHessian ? &H9 : nullptr);
    out.energy.pressure += w;
    out.energy.magnitude += std::abs(w);
    scatter<9>(&triangleVerts_[3 * t], triangleSlots_.element(t), g9, withHessian ? &H9 : nullptr,
               grad, vals);
    for (int i = 0; i < 9; ++i) load[3 * tri[i / 3] + i % 3] += g9[i];
  }
  forContactTriangles(x, [&](int t, const Vec3& a, const Vec3& b, const Vec3& cpos) {
    const double w = sphereTriangleEnergy(contact_, probe_->center, probe_->radius, a, b, cpos,
                                          &g12, withHessian ? &H12 : nullptr);
    if (w == 0.0 && g12.isZero()) return;
    if (withHessian && projectContact_) {
      // The sphere's curvature makes the contact Hessian indefinite (−φ'/(2d) ∇²D); keep its
      // positive part, as contact codes do for barrier terms, so it never spoils the tangent.
      Eigen::SelfAdjointEigenSolver<Mat12> es(H12);
      H12 = es.eigenvectors() * es.eigenvalues().cwiseMax(0.0).asDiagonal() *
            es.eigenvectors().transpose();
    }
    ++out.contactTriangles;
    out.energy.contact += w;
    const Vec9 gx = g12.tail<9>();
    const Mat9 Hx = H12.bottomRightCorner<9, 9>();
    scatter<9>(&triangleVerts_[3 * t], triangleSlots_.element(t), gx, withHessian ? &Hx : nullptr,
               grad, vals);
    const auto& tri = c.triangles[t];
    for (int i = 0; i < 9; ++i) load[3 * tri[i / 3] + i % 3] += gx[i];
    out.probeGradient += g12.head<3>();
    if (withHessian) {
      out.probeHessian += H12.topLeftCorner<3, 3>();
      for (int i = 0; i < 9; ++i) out.probeCoupling.row(3 * tri[i / 3] + i % 3) += H12.block<1, 3>(3 + i, 0);
    }
  });
  for (const auto& [v, f] : pointForces_) {
    out.energy.external -= f.dot(x.col(v));
    out.energy.magnitude += std::abs(f.dot(x.col(v)));
    out.gradient.segment<3>(3 * v) -= f;
    out.loadGradient.segment<3>(3 * v) -= f;
  }
  out.energy.magnitude += membraneMagnitude_ + std::abs(out.energy.bending) +
                          std::abs(out.energy.contact);
}

// Koiter bending in four passes inside the caller's parallel region (every thread calls it):
// (1) each pair's dihedral angle and its gradient; (2) the edge unknowns that minimise the energy
// for those angles (one solve with the factorised A, mechanics/PlateBending.h); (3) each element's
// energy ½ ΔsᵀBΔs, its gradient Σ_k y_k ∇s_k (y = B Δs; the edge unknowns' part is zero at the
// minimum) and the matrix Gᵀ B G over its positions and edge unknowns, G = ∂Δs/∂(x, φ); (4) the
// curvature part, each pair's Σ (coeff · y_k) ∇²θ gathered from the elements that use it.
// Returns this thread's share of the energy.
double Model::evaluatePlate(const Points& x, double* g, double* v, bool withHessian) const {
  const int P = static_cast<int>(plate_.pairs.size());
#pragma omp for schedule(static)
  for (int p = 0; p < P; ++p) {
    const auto& pv = plate_.pairs[p].v;
    pairTheta_[p] = dihedralAngle(x.col(pv[0]), x.col(pv[1]), x.col(pv[2]), x.col(pv[3]),
                                  &pairGrad_[p], nullptr);
  }
#pragma omp single
  platePhi_ = plateEdgeRotations(plate_, pairTheta_);
  double energy = 0;
  constexpr int kMax = 3 * kMaxPlateArity + 3;
  using LocalGrads = Eigen::Matrix<double, Eigen::Dynamic, 3, 0, kMax, 3>;
  const int T = static_cast<int>(plate_.elements.size());
#pragma omp for schedule(static)
  for (int t = 0; t < T; ++t) {
    const int begin = plateUnknownBegin_[t], m = plateUnknownBegin_[t + 1] - begin;
    if (m == 0) continue;
    const auto& el = plate_.elements[t];
    Eigen::Vector3d ds;
    energy += plateElementEnergy(plate_, t, pairTheta_, platePhi_, &ds);
    const Eigen::Vector3d y = el.B * ds;
    plateY_[t] = y;
    const int mx = 3 * static_cast<int>(el.vertices.size());
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
    for (int i = 0; i < mx; ++i) g[3 * el.vertices[i / 3] + i % 3] += ge[i];
    if (!withHessian) continue;
    // G B Gᵀ, upper triangle only, straight into the values (no small-matrix product kernels).
    LocalGrads GB(m, 3);
    GB.noalias() = G.lazyProduct(el.B);
    const int* slots = plateSlots_.data() + plateSlotBegin_[t];
    int s = 0;
    for (int i = 0; i < m; ++i)
      for (int j = i; j < m; ++j, ++s)
        if (slots[s] >= 0)
          v[slots[s]] += GB(i, 0) * G(j, 0) + GB(i, 1) * G(j, 1) + GB(i, 2) * G(j, 2);
  }
  if (!withHessian) return energy;
#pragma omp for schedule(static) nowait
  for (int p = 0; p < P; ++p) {
    double mu = 0;
    for (const auto& u : plate_.pairUses[p]) mu += u.coeff * plateY_[u.element](u.edge);
    if (mu == 0.0) continue;
    const auto& pv = plate_.pairs[p].v;
    Vec12 gp;
    Mat12 Hp;
    dihedralAngle(x.col(pv[0]), x.col(pv[1]), x.col(pv[2]), x.col(pv[3]), &gp, &Hp);
    const int* slots = pairSlots_.element(p);
    for (int i = 0; i < 12; ++i)
      for (int j = 0; j < 12; ++j) {
        const int sl = slots[i * 12 + j];
        if (sl >= 0) v[sl] += mu * Hp(i, j);
      }
  }
  return energy;
}

std::vector<MembraneStress> Model::triangleStresses(const Points& x) const {
  const CellComplex& c = *cc_;
  std::vector<MembraneStress> s(c.triangleCount());
  const double mu = material_.mu(), lam = material_.lambdaPlaneStress();
  for (int t = 0; t < c.triangleCount(); ++t) {
    const auto& tri = c.triangles[t];
    s[t] = membraneStress(membraneRest_[t], x.col(tri[0]), x.col(tri[1]), x.col(tri[2]), mu, lam);
  }
  return s;
}

std::vector<double> Model::triangleBendingEnergy(const Points& x) const {
  std::vector<double> e(cc_->triangleCount(), 0.0);
  if (material_.bending == BendingModel::None) return e;
  if (material_.bending == BendingModel::Koiter) {
    plateBendingEnergy(plate_, x, &e);
    return e;
  }
  for (size_t k = 0; k < topo_.hinges.size(); ++k) {
    const auto& hg = topo_.hinges[k];
    const auto& v = hg.v;
    const double w = material_.bending == BendingModel::Hinge
                         ? hingeEnergy(hingeRest_[k], x.col(v[0]), x.col(v[1]), x.col(v[2]),
                                       x.col(v[3]), nullptr, nullptr)
                         : linearBendingEnergy(linearRest_[k], x.col(v[0]), x.col(v[1]),
                                               x.col(v[2]), x.col(v[3]), nullptr, nullptr);
    e[hg.triA] += 0.5 * w;
    e[hg.triB] += 0.5 * w;
  }
  return e;
}

}  // namespace tp
