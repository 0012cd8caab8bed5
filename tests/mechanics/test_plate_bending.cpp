// Koiter plate bending (mechanics/PlateBending.h): patch tests, Poisson coupling, and the plate
// closed forms of Timoshenko & Woinowsky-Krieger ("Theory of plates and shells", 1959, §§16–19
// for circular plates) on structured and irregular (Delaunay of random points) meshes, each on a
// sequence of meshes with the mesh-convergence argument of test_closed_form.cpp.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "mechanics/Model.h"
#include "mechanics/Bending.h"
#include "mechanics/PlateBending.h"
#include "mesh/Topology.h"
#include "solver/Newton.h"
#include "tissue/Shapes.h"

using namespace tp;
using std::numbers::pi;

namespace {

Material plate(double E, double nu, double h) {
  Material m;
  m.youngModulus = E;
  m.poissonRatio = nu;
  m.thickness = h;
  m.bending = BendingModel::Koiter;
  return m;
}

// The plate energy density of a constant curvature K (2×2): (D/2)[ν (tr K)² + (1 − ν) tr K²].
double koiterDensity(const Material& mat, const Eigen::Matrix2d& K) {
  const double nu = mat.poissonRatio;
  return 0.5 * mat.bendingRigidity() * (nu * K.trace() * K.trace() + (1 - nu) * (K * K).trace());
}

// Patch test of the Morley triangle: the flat rest mesh bent into w = ε ½ xᵀKx, with every edge
// unknown set from the exact mid-edge slopes, gives every inner triangle the energy density of K
// exactly (up to the O(ε²) geometric nonlinearity), and the unknowns two triangles share come out
// the same from both (the sign conventions agree); the energy minimised over the unknowns is no
// larger.
void expectPatchTest(const CellComplex& cc, const char* what) {
  const Topology topo = buildTopology(cc);
  for (double nu : {0.0, 0.3, 0.49}) {
    const Material mat = plate(100, nu, 0.1);
    const PlateBending pb = buildPlateBending(cc, topo, mat.bendingRigidity(), nu, JunctionRule::Hinged);
    const double eps = 1e-4;
    const std::vector<Eigen::Matrix2d> curvatures{
        Eigen::Matrix2d::Identity(), Eigen::Vector2d(1, 0).asDiagonal(),
        (Eigen::Matrix2d() << 0, 1, 1, 0).finished(),
        (Eigen::Matrix2d() << 0.3, -0.7, -0.7, -1.1).finished()};
    for (const auto& K : curvatures) {
      Points x = cc.rest;
      for (int v = 0; v < cc.vertexCount(); ++v) {
        const Eigen::Vector2d p = cc.rest.col(v).head<2>();
        x(2, v) = eps * 0.5 * p.dot(K * p);
      }
      std::vector<double> theta(pb.pairs.size());
      for (size_t p = 0; p < pb.pairs.size(); ++p) {
        const auto& v = pb.pairs[p].v;
        theta[p] = dihedralAngle(x.col(v[0]), x.col(v[1]), x.col(v[2]), x.col(v[3]), nullptr, nullptr);
      }
      // The exact outward slope at each mid-edge relative to the triangle's plane, along its
      // normal, and the unknown that gives it.
      Eigen::VectorXd phi = Eigen::VectorXd::Constant(pb.edgeUnknowns, std::nan(""));
      double mismatch = 0;
      for (int t = 0; t < cc.triangleCount(); ++t) {
        const auto& el = pb.elements[t];
        const auto& tri = cc.triangles[t];
        Eigen::Vector2d P[3];
        double w[3];
        for (int i = 0; i < 3; ++i) {
          P[i] = cc.rest.col(tri[i]).head<2>();
          w[i] = x(2, tri[i]);
        }
        Eigen::Matrix2d E;
        E << (P[1] - P[0]).transpose(), (P[2] - P[0]).transpose();
        const Eigen::Vector2d gradLin = E.inverse() * Eigen::Vector2d(w[1] - w[0], w[2] - w[0]);
        const double up = ((cc.rest.col(tri[1]) - cc.rest.col(tri[0]))
                               .cross(cc.rest.col(tri[2]) - cc.rest.col(tri[0])))
                              .z() > 0 ? 1.0 : -1.0;
        for (int k = 0; k < 3; ++k) {
          if (el.edgeUnknown[k] < 0) continue;
          const Eigen::Vector2d a = P[(k + 1) % 3], b = P[(k + 2) % 3], mid = 0.5 * (a + b);
          Eigen::Vector2d nOut(b.y() - a.y(), a.x() - b.x());
          nOut.normalize();
          if (nOut.dot(P[k] - mid) > 0) nOut = -nOut;
          const double exact = up * (eps * (K * mid) - gradLin).dot(nOut);
          double fromRefs = 0;
          for (int r = el.refBegin[k]; r < el.refBegin[k + 1]; ++r)
            fromRefs += pb.refs[r].coeff * (theta[pb.refs[r].pair] - pb.pairs[pb.refs[r].pair].restAngle);
          const double need = (exact - fromRefs) / el.edgeSign[k];
          double& slot = phi(el.edgeUnknown[k]);
          if (std::isnan(slot))
            slot = need;
          else
            mismatch = std::max(mismatch, std::abs(slot - need) / (std::abs(need) + eps));
        }
      }
      EXPECT_LT(mismatch, 1e-4) << what << ": two triangles disagree on a shared mid-edge slope";
      const std::vector<double> area = triangleAreas(cc, cc.rest);
      const double density = koiterDensity(mat, eps * K);
      double worst = 0, exactTotal = 0;
      for (int t = 0; t < cc.triangleCount(); ++t) {
        const auto& el = pb.elements[t];
        if (!el.live) continue;
        const double e = plateElementEnergy(pb, t, theta, phi);
        exactTotal += e;
        // A boundary triangle's own slope is minimised out: its energy can only be lower.
        if (el.ownSlope[0] || el.ownSlope[1] || el.ownSlope[2])
          EXPECT_LE(e, area[t] * density * (1 + 1e-3)) << what;
        else
          worst = std::max(worst, std::abs(e / (area[t] * density) - 1));
      }
      EXPECT_LT(worst, 1e-3) << what << " nu " << nu << " K " << K;
      EXPECT_LE(plateBendingEnergy(pb, x), exactTotal * (1 + 1e-9)) << what;
    }
  }
}

}  // namespace

CellComplex rectangle(double L, double b, int nx, int ny);

TEST(PlateBending, PatchTestConstantCurvatureOnRectangleMesh) {
  expectPatchTest(rectangle(10, 6, 20, 12), "rectangle");
}

TEST(PlateBending, PatchTestConstantCurvatureOnStructuredMesh) {
  CellComplex cc = latticeDisc(5, 10);
  std::fill(cc.fixed.begin(), cc.fixed.end(), 0);  // no rigid triangles: every edge is a plate edge
  expectPatchTest(cc, "lattice");
}

TEST(PlateBending, PatchTestConstantCurvatureOnIrregularMesh) {
  // Delaunay of random points: angles far from 60°, valences 4 to 8.
  CellComplex cc = delaunayDisc(5, 0.5, 7);
  std::fill(cc.fixed.begin(), cc.fixed.end(), 0);
  expectPatchTest(cc, "delaunay");
}

TEST(PlateBending, RigidMotionOfABentStateKeepsItsEnergy) {
  auto cc = std::make_shared<CellComplex>(delaunayDisc(3, 0.4, 3));
  Model m(cc, plate(100, 0.3, 0.1));
  Points x = cc->rest;
  for (int v = 0; v < cc->vertexCount(); ++v)
    x(2, v) = 0.05 * std::sin(x(0, v)) * std::cos(0.7 * x(1, v));
  const double w = m.energy(x);
  ASSERT_GT(w, 0.0);
  const Eigen::Matrix3d R = Eigen::AngleAxisd(2.1, Vec3(-1, 2, 0.5).normalized()).toRotationMatrix();
  const Points y = (R * x).colwise() + Vec3(1, 2, -3);
  EXPECT_NEAR(m.energy(y), w, 1e-10 * w);
}

namespace {

enum class Edge { Clamped, Simple };
enum class Load { Point, Pressure };

// Centre deflection of a circular plate (radius a) under a central point force F or a uniform
// pressure q, Timoshenko & Woinowsky-Krieger §§16–19:
//   clamped:  F a²/(16πD),               q a⁴/(64D)
//   simple:   F a²(3+ν)/(16π(1+ν)D),     q a⁴(5+ν)/(64(1+ν)D)
double plateCentreDeflection(Edge edge, Load load, double a, double D, double nu, double magnitude) {
  const double f = edge == Edge::Clamped ? 1.0 : load == Load::Point ? (3 + nu) / (1 + nu)
                                                                      : (5 + nu) / (1 + nu);
  return load == Load::Point ? f * magnitude * a * a / (16 * pi * D)
                             : f * magnitude * std::pow(a, 4) / (64 * D);
}

// Solves the plate on one mesh and returns the relative error of the centre deflection.
double plateError(const CellComplex& base, Edge edge, Load load, double nu, bool print,
                  const char* meshName, int level) {
  const double a = 10, E = 100, h = 0.1;
  const Material mat = plate(E, nu, h);
  const double D = mat.bendingRigidity();
  const double delta = 1e-3 * h;  // linear regime
  const double unit = plateCentreDeflection(edge, load, a, D, nu, 1.0);
  auto cc = std::make_shared<CellComplex>(base);
  Model m(cc, mat);
  if (load == Load::Point)
    m.setPointForces({{0, Vec3(0, 0, -delta / unit)}});
  else
    m.setUniformPressure(-delta / unit);  // the cell is below: suction pulls the plate down
  Points x = cc->rest;
  StaticSolver solver(m);
  const SolveReport rep = solver.solve(x);
  EXPECT_TRUE(rep.converged) << rep.message;
  const double d = -x(2, 0);
  if (print)
    std::printf("  %-8s %-8s %-8s nu %.2f mesh %d: error %+.3f%%\n", meshName,
                edge == Edge::Clamped ? "clamped" : "simple", load == Load::Point ? "point" : "pressure",
                nu, level, 100 * (d / delta - 1));
  return d / delta - 1;
}

// The finest of three meshes within 2 %, and the error shrinking or already within its scatter.
void expectPlateConverges(const std::vector<double>& e, const std::string& what) {
  ASSERT_EQ(e.size(), 3u);
  EXPECT_LT(std::abs(e[2]), 0.02) << what << ": finest mesh error " << 100 * e[2] << "%";
  EXPECT_LT(std::abs(e[2]), std::abs(e[0]) + 0.005) << what << ": not converging";
}

// latticeDisc, with a simply supported edge on the circle itself: triangles with a vertex
// outside r = a are dropped (the lattice disc keeps fixed vertices out to a spacing beyond the rim,
// which would hold the slope there).
CellComplex structuredDisc(double a, int n, double clamp, int cell) {
  CellComplex full = latticeDisc(a, n, clamp, cell);
  if (clamp > 0) return full;
  std::vector<Eigen::Vector3i> tris;
  for (const auto& t : full.triangles) {
    bool inside = true;
    for (int k = 0; k < 3; ++k) inside &= full.rest.col(t[k]).norm() <= a * (1 + 1e-9);
    if (inside) tris.push_back(t);
  }
  CellComplex cc;
  cc.rest = full.rest;
  cc.fixed = full.fixed;
  cc.cellLabels = full.cellLabels;
  cc.addWall(tris, cell, -1);
  return cc;
}

void runPlates(bool irregular) {
  for (Edge edge : {Edge::Simple, Edge::Clamped})
    for (Load load : {Load::Point, Load::Pressure})
      for (double nu : {0.0, 0.3, 0.49}) {
        std::vector<double> e;
        int level = 0;
        for (int n : {12, 24, 48}) {
          const double a = 10, spacing = a / n;
          // A clamped edge: the vertices out to 3 spacings beyond r = a are fixed (built in).
          const double clamp = edge == Edge::Clamped ? 3 * spacing : 0.0;
          const int cell = load == Load::Pressure ? 0 : -1;
          const CellComplex cc = irregular ? delaunayDisc(a, spacing, 11 + n, clamp, cell)
                                           : structuredDisc(a, n, clamp, cell);
          e.push_back(plateError(cc, edge, load, nu, true, irregular ? "delaunay" : "lattice", ++level));
        }
        expectPlateConverges(e, std::string(irregular ? "delaunay " : "lattice ") +
                                    (edge == Edge::Clamped ? "clamped " : "simple ") +
                                    (load == Load::Point ? "point " : "pressure ") +
                                    "nu " + std::to_string(nu));
      }
}

}  // namespace

TEST(PlateBending, CircularPlatesOnStructuredMeshes) { runPlates(false); }

TEST(PlateBending, CircularPlatesOnIrregularMeshes) { runPlates(true); }

// A rectangle [0, L] × [−b/2, b/2] of nx × ny cells, each split by a diagonal that alternates
// from cell to cell; a sheet.
CellComplex rectangle(double L, double b, int nx, int ny) {
  CellComplex cc;
  cc.rest.resize(3, (nx + 1) * (ny + 1));
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i)
      cc.rest.col(j * (nx + 1) + i) = Vec3(L * i / nx, b * (double(j) / ny - 0.5), 0);
  cc.fixed.assign(cc.rest.cols(), 0);
  std::vector<Eigen::Vector3i> tris;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const int a = j * (nx + 1) + i, c = a + 1, d = a + nx + 1, e = d + 1;
      if ((i + j) % 2 == 0) {
        tris.emplace_back(a, c, e);
        tris.emplace_back(a, e, d);
      } else {
        tris.emplace_back(a, c, d);
        tris.emplace_back(c, e, d);
      }
    }
  cc.addWall(tris, -1, -1);
  return cc;
}

// Cantilever strip with free long edges, built in at x = 0 and loaded at its free end by F:
// tip deflection F L³ / (3 E I), I = b h³/12 — the beam formula, i.e. D(1 − ν²) b for the
// rigidity: a narrow strip (b² ≪ R h) bends with its anticlastic curvature −ν κ free. A plate
// model without the Poisson coupling would give D b instead (10 % stiffer at ν = 0.3).
TEST(PlateBending, CantileverStripWithFreeEdges) {
  const double L = 20, b = 1, E = 100, h = 0.1, nu = 0.3;
  const Material mat = plate(E, nu, h);
  std::vector<double> errors;
  for (int ny : {2, 4, 8}) {
    const int nx = 20 * ny;
    auto cc = std::make_shared<CellComplex>(rectangle(L, b, nx, ny));
    const double dx = L / nx;
    for (int v = 0; v < cc->vertexCount(); ++v) cc->fixed[v] = cc->rest(0, v) < 1.5 * dx;  // two columns
    const double Lfree = L - dx;  // built in along the second column
    const double EI = E * b * h * h * h / 12;
    const double delta = 1e-3 * h, F = delta * 3 * EI / std::pow(Lfree, 3);
    std::vector<std::pair<int, Vec3>> forces;
    for (int j = 0; j <= ny; ++j) {
      const double w = (j == 0 || j == ny) ? 0.5 / ny : 1.0 / ny;
      forces.push_back({j * (nx + 1) + nx, Vec3(0, 0, -F * w)});
    }
    Model m(cc, mat);
    m.setPointForces(forces);
    Points x = cc->rest;
    StaticSolver solver(m);
    ASSERT_TRUE(solver.solve(x).converged);
    double tip = 0;
    for (int j = 0; j <= ny; ++j) tip -= x(2, j * (nx + 1) + nx) / (ny + 1);
    std::printf("  cantilever ny %d: tip %.6g, beam formula %.6g, error %+.3f%%\n", ny, tip, delta,
                100 * (tip / delta - 1));
    errors.push_back(tip / delta - 1);
  }
  EXPECT_LT(std::abs(errors.back()), 0.02);
  EXPECT_LT(std::abs(errors.back()), std::abs(errors.front()) + 0.005);
}

// A free plate under end moments M (pure bending): κ_x = M / (E I) along, and the anticlastic
// curvature κ_y = −ν κ_x across (the exact solution of the free plate, no boundary layer).
TEST(PlateBending, PureBendingGivesAnticlasticCurvature) {
  const double L = 10, b = 4, E = 100, h = 0.1;
  for (double nu : {0.0, 0.3, 0.49}) {
    const Material mat = plate(E, nu, h);
    const int nx = 60, ny = 24;
    auto cc = std::make_shared<CellComplex>(rectangle(L, b, nx, ny));
    const double dx = L / nx;
    const double EI = E * b * h * h * h / 12;
    const double kappa = 1e-5;  // linear regime
    const double M = kappa * EI, f = M / dx;  // a couple of ±f at the two end columns
    std::vector<std::pair<int, Vec3>> forces;
    for (int j = 0; j <= ny; ++j) {
      const double w = (j == 0 || j == ny) ? 0.5 / ny : 1.0 / ny;
      const int row = j * (nx + 1);
      forces.push_back({row, Vec3(0, 0, f * w)});
      forces.push_back({row + 1, Vec3(0, 0, -f * w)});
      forces.push_back({row + nx, Vec3(0, 0, f * w)});
      forces.push_back({row + nx - 1, Vec3(0, 0, -f * w)});
    }
    Model m(cc, mat);
    m.setPointForces(forces);
    // Statically determinate support: no reactions under self-equilibrated loads.
    const int A = (ny / 2) * (nx + 1) + nx / 2, B = A + 1, C = A + (ny / 4) * (nx + 1);
    std::vector<std::uint8_t> fixed(3 * cc->vertexCount(), 0);
    fixed[3 * A] = fixed[3 * A + 1] = fixed[3 * A + 2] = 1;
    fixed[3 * B + 1] = fixed[3 * B + 2] = 1;
    fixed[3 * C + 2] = 1;
    m.setFixedDofs(fixed);
    Points x = cc->rest;
    StaticSolver solver(m);
    ASSERT_TRUE(solver.solve(x).converged);
    // Least-squares fit of w = c0 + c1 x + c2 y + ½κx x² + κxy x y + ½κy y² over the middle half.
    Eigen::MatrixXd Afit(0, 6);
    Eigen::VectorXd rhs(0);
    std::vector<Eigen::Matrix<double, 6, 1>> rows;
    std::vector<double> values;
    for (int v = 0; v < cc->vertexCount(); ++v) {
      const double X = cc->rest(0, v) - L / 2, Y = cc->rest(1, v);
      if (std::abs(X) > L / 4) continue;
      Eigen::Matrix<double, 6, 1> r;
      r << 1, X, Y, 0.5 * X * X, X * Y, 0.5 * Y * Y;
      rows.push_back(r);
      values.push_back(x(2, v));
    }
    Afit.resize(rows.size(), 6);
    rhs.resize(rows.size());
    for (size_t i = 0; i < rows.size(); ++i) {
      Afit.row(i) = rows[i].transpose();
      rhs(i) = values[i];
    }
    const Eigen::VectorXd c = Afit.colPivHouseholderQr().solve(rhs);
    const double kx = c(3), ky = c(5);  // the end couples lift both ends: w'' > 0
    std::printf("  pure bending nu %.2f: kx/(M/EI) %.5f, ky/kx %.5f (−ν = %.2f)\n", nu, kx / kappa,
                ky / kx, -nu);
    EXPECT_NEAR(kx / kappa, 1.0, 0.02) << "nu " << nu;
    EXPECT_NEAR(ky / kx, -nu, 0.02 * std::max(nu, 0.05)) << "nu " << nu;
  }
}
