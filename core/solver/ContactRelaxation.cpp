#include "solver/ContactRelaxation.h"

#include <algorithm>
#include <cmath>

#include "mechanics/Contact.h"

namespace tp {

namespace {

// One contact element's 9 × 9 vertex Hessian, exact or its positive part taken over the 12
// unknowns of (probe, vertices) as ContactTerm does, and its vertex gradient; returns its energy.
double contactElement(const ContactLaw& law, const Probe& probe, const Vec3& a, const Vec3& b,
                      const Vec3& c, bool projected, Vec9* g, Mat9* H) {
  Vec12 g12;
  Mat12 H12;
  const double w = sphereTriangleEnergy(law, probe.center, probe.radius, a, b, c, &g12,
                                        H ? &H12 : nullptr);
  if (g) *g = g12.tail<9>();
  if (H) *H = (projected ? positivePart(H12) : H12).bottomRightCorner<9, 9>();
  return w;
}

}  // namespace

void PatternRows::build(const SparsePattern& P) {
  if (builtFor(P)) return;
  start.assign(P.n + 1, 0);
  for (int j = 0; j < P.n; ++j)
    for (int k = P.colPtr[j]; k < P.colPtr[j + 1]; ++k)
      if (P.rowIdx[k] < j) ++start[P.rowIdx[k] + 1];
  for (int i = 0; i < P.n; ++i) start[i + 1] += start[i];
  col.resize(start[P.n]);
  pos.resize(start[P.n]);
  std::vector<int> next(start.begin(), start.end() - 1);
  for (int j = 0; j < P.n; ++j)  // columns ascending: each row's columns come out sorted
    for (int k = P.colPtr[j]; k < P.colPtr[j + 1]; ++k) {
      const int i = P.rowIdx[k];
      if (i < j) {
        col[next[i]] = j;
        pos[next[i]++] = k;
      }
    }
  pattern = &P;
  nnz = P.nnz();
}

std::vector<int> pressedUnknowns(const Model& model, const Points& x, const PatternRows& rows) {
  const CellComplex& cc = model.complex();
  const DofMap& dofs = model.dofs();
  const int n = dofs.freeCount();
  std::vector<int> out;
  for (int t : model.touchedTriangles(x))
    for (int v : cc.triangles[t])
      for (int k = 0; k < 3; ++k)
        if (const int i = dofs.index(3 * v + k); i >= 0) out.push_back(i);
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  std::vector<int> own;  // the terms' unknowns (after the n positions) in those rows
  for (int i : out)
    for (int e = rows.start[i]; e < rows.start[i + 1]; ++e)
      if (rows.col[e] >= n) own.push_back(rows.col[e]);
  std::sort(own.begin(), own.end());
  own.erase(std::unique(own.begin(), own.end()), own.end());
  out.insert(out.end(), own.begin(), own.end());
  return out;
}

bool LocalTangent::build(const PatternRows& rows, const std::vector<double>& values,
                         std::vector<int> unknowns, bool factor) {
  active_ = false;
  unknowns_ = std::move(unknowns);
  const int m = size();
  if (m == 0 || m > kMaxSize || !rows.pattern) return false;
  const SparsePattern& P = *rows.pattern;
  std::vector<int> local(P.n, -1);
  for (int a = 0; a < m; ++a) local[unknowns_[a]] = a;
  entries_.clear();
  block_.setZero(m, m);
  const auto add = [&](int a, int j, double v) {
    entries_.push_back({a, j, v});
    if (local[j] >= 0) block_(a, local[j]) = v;
  };
  for (int a = 0; a < m; ++a) {
    const int i = unknowns_[a];
    for (int k = P.colPtr[i]; k < P.colPtr[i + 1]; ++k) add(a, P.rowIdx[k], values[k]);  // j ≤ i
    for (int e = rows.start[i]; e < rows.start[i + 1]; ++e) add(a, rows.col[e], values[rows.pos[e]]);
  }
  if (factor) {
    llt_.compute(block_);
    if (llt_.info() != Eigen::Success) return false;
  }
  active_ = true;
  return true;
}

void LocalTangent::subtractProduct(const Eigen::VectorXd& w, Eigen::VectorXd& y) const {
  for (const Entry& e : entries_) y[e.j] -= e.v * w[e.a];
}

void LocalTangent::correct(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  const int m = size();
  Eigen::VectorXd res(m);
  for (int a = 0; a < m; ++a) res[a] = r[unknowns_[a]];
  for (const Entry& e : entries_) res[e.a] -= e.v * z[e.j];
  const Eigen::VectorXd d = llt_.solve(res);
  for (int a = 0; a < m; ++a) z[unknowns_[a]] += d[a];
}

void ContactRelaxation::hold(const Model& model, const Points& x,
                             const std::vector<double>& hessian, bool projected) {
  held_ = false;
  if (!model.probe() || static_cast<int>(hessian.size()) != model.pattern().nnz()) return;
  pattern_ = &model.pattern();
  nnz_ = pattern_->nnz();
  hessian_ = hessian;
  x_ = x;
  probe_ = *model.probe();
  law_ = model.contactLaw();
  projected_ = projected;
  touched_ = model.touchedTriangles(x);
  held_ = true;
}

const std::vector<double>* ContactRelaxation::heldTangent(const Model& model) const {
  if (!held_ || pattern_ != &model.pattern() || nnz_ != model.pattern().nnz() || !model.probe())
    return nullptr;
  const ContactLaw& law = model.contactLaw();
  if (model.probe()->radius != probe_.radius || law.stiffness != law_.stiffness ||
      law.smoothing != law_.smoothing)
    return nullptr;
  return &hessian_;
}

bool ContactRelaxation::relax(const Model& model, const PatternRows& rows, const Points& x,
                              const Eigen::VectorXd& gradient, double tolerance, Points& dx) {
  if (!heldTangent(model) || !rows.builtFor(model.pattern()) || x.cols() != x_.cols())
    return false;
  const Probe probe = *model.probe();
  const CellComplex& cc = model.complex();
  const DofMap& dofs = model.dofs();
  if (!block_.build(rows, hessian_, pressedUnknowns(model, x, rows), false)) return false;
  const int m = block_.size();
  // The local unknowns: first the position components, then the terms' own unknowns (at their
  // optimum, so with a zero gradient; only the positions move the tissue).
  std::vector<int> dof;
  for (int i : block_.unknowns())
    if (i < dofs.freeCount()) dof.push_back(dofs.freeDofs()[i]);
  const int mx = static_cast<int>(dof.size());
  local_.assign(3 * static_cast<size_t>(x.cols()), -1);
  for (int a = 0; a < mx; ++a) local_[dof[a]] = a;
  // The outer triangles with a local vertex: the contact energy that moves with them.
  std::vector<int> near;
  for (int t : model.topology().outerTriangles) {
    const auto& tri = cc.triangles[t];
    for (int v : tri)
      if (local_[3 * v] >= 0 || local_[3 * v + 1] >= 0 || local_[3 * v + 2] >= 0) {
        near.push_back(t);
        break;
      }
  }
  // Adds s × an element's vertex gradient / Hessian into the local ones.
  const auto gather = [&](int t, const Vec9* g, const Mat9* H, double s, Eigen::VectorXd* gl,
                          Eigen::MatrixXd* Hl) {
    const auto& tri = cc.triangles[t];
    int li[9];
    for (int i = 0; i < 9; ++i) li[i] = local_[3 * tri[i / 3] + i % 3];
    for (int i = 0; i < 9; ++i) {
      if (li[i] < 0) continue;
      if (g) (*gl)[li[i]] += s * (*g)[i];
      if (H)
        for (int j = 0; j < 9; ++j)
          if (li[j] >= 0) (*Hl)(li[i], li[j]) += s * (*H)(i, j);
    }
  };
  // The rest of the energy to second order: the held tangent over the local unknowns, less its
  // own contact part.
  Eigen::MatrixXd Ke = block_.block();
  Mat9 H;
  for (int t : touched_) {
    const auto& tri = cc.triangles[t];
    contactElement(law_, probe_, x_.col(tri[0]), x_.col(tri[1]), x_.col(tri[2]), projected_,
                   nullptr, &H);
    gather(t, nullptr, &H, -1.0, nullptr, &Ke);
  }
  // The contact's energy, local gradient and Hessian (its positive part) at x + E dy.
  Points xt = x;
  const ContactLaw& law = model.contactLaw();
  const auto contact = [&](const Eigen::VectorXd& dy, Eigen::VectorXd* gl, Eigen::MatrixXd* Hl) {
    for (int a = 0; a < mx; ++a) xt.data()[dof[a]] = x.data()[dof[a]] + dy[a];
    double w = 0;
    Vec9 g;
    for (int t : near) {
      const auto& tri = cc.triangles[t];
      const double wt = contactElement(law, probe, xt.col(tri[0]), xt.col(tri[1]),
                                       xt.col(tri[2]), true, gl ? &g : nullptr, Hl ? &H : nullptr);
      if (wt == 0.0) continue;
      w += wt;
      gather(t, gl ? &g : nullptr, Hl ? &H : nullptr, 1.0, gl, Hl);
    }
    return w;
  };
  Eigen::VectorXd dy = Eigen::VectorXd::Zero(m), gc = Eigen::VectorXd::Zero(m);
  const double w0 = contact(dy, &gc, nullptr);
  Eigen::VectorXd ge = Eigen::VectorXd::Zero(m);  // the rest's gradient at x
  for (int a = 0; a < mx; ++a) ge[a] = gradient[dof[a]] - gc[a];
  const auto localEnergy = [&](const Eigen::VectorXd& d, double w) {
    return ge.dot(d) + 0.5 * d.dot(Ke * d) + (w - w0);
  };

  // Newton with backtracking on the local energy, the contact's Hessian its positive part.
  double q = 0;
  const double r0 = (ge + gc).norm();
  bool moved = false;
  for (int it = 0; it < 12; ++it) {
    Eigen::VectorXd gl = Eigen::VectorXd::Zero(m);
    Eigen::MatrixXd Hl = Ke;
    contact(dy, &gl, &Hl);
    const Eigen::VectorXd res = ge + Ke * dy + gl;
    if (res.norm() <= std::max(tolerance, 1e-3 * r0)) break;
    Eigen::LLT<Eigen::MatrixXd> llt(Hl);
    if (llt.info() != Eigen::Success) break;
    const Eigen::VectorXd step = -llt.solve(res);
    const double slope = res.dot(step);
    if (!(slope < 0)) break;
    bool accepted = false;
    for (double alpha = 1; alpha > 1e-6; alpha *= 0.5) {
      const Eigen::VectorXd trial = dy + alpha * step;
      const double qt = localEnergy(trial, contact(trial, nullptr, nullptr));
      if (qt <= q + 1e-4 * alpha * slope) {
        dy = trial;
        q = qt;
        accepted = true;
        break;
      }
    }
    if (!accepted) break;
    moved = true;
  }
  dx.setZero(3, x.cols());
  for (int a = 0; a < mx; ++a) dx.data()[dof[a]] = dy[a];
  return moved && dy.allFinite();
}

}  // namespace tp
