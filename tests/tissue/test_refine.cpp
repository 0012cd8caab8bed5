// Refinement near the probe: conforming, well shaped, local; the force–depth curve converges with
// the level; a coarse mesh lets a probe through between its vertices where a refined one does not.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>

#include "experiment/Indentation.h"
#include "mechanics/Contact.h"
#include "mesh/Quality.h"
#include "tissue/Meristem.h"
#include "tissue/Refine.h"
#include "tissue/Shapes.h"

using namespace tp;

namespace {

double maxEdge(const CellComplex& cc, int t) {
  double m = 0;
  for (int k = 0; k < 3; ++k)
    m = std::max(m, (cc.rest.col(cc.triangles[t][k]) - cc.rest.col(cc.triangles[t][(k + 1) % 3])).norm());
  return m;
}

CellComplex smallMeristem() {
  MeristemParams p;
  p.cells = 60;
  p.shape.radius = 15;
  p.shape.capHeight = 12;
  p.shape.stemHeight = 4;
  return generateMeristem(p);
}

}  // namespace

TEST(Refine, ConformingLocalAndWellShaped) {
  const CellComplex base = generateMeristem(MeristemParams{});
  const MeshQuality q0 = measureQuality(base);
  const Vec3 centre(0, 0, 41.5);
  const double radius = 6;
  for (int levels = 1; levels <= 3; ++levels) {
    RefineReport rep;
    const CellComplex cc = refineNear(base, centre, radius, levels, &rep);
    const ValidityReport v = checkValidity(cc);  // a hanging node would leave a cell open
    ASSERT_TRUE(v.ok()) << "level " << levels << ": " << v.summary();
    EXPECT_EQ(v.openCells, 0);
    // Flat subdivision keeps every cell's volume.
    const auto vol0 = cellVolumes(base, base.rest), vol1 = cellVolumes(cc, cc.rest);
    for (size_t c = 0; c < vol0.size(); ++c) EXPECT_NEAR(vol1[c], vol0[c], 1e-9 * vol0[c]);
    // Local: new vertices only near the centre; the old ones untouched.
    for (int i = 0; i < base.vertexCount(); ++i) EXPECT_EQ(cc.rest.col(i), base.rest.col(i));
    for (int i = base.vertexCount(); i < cc.vertexCount(); ++i)
      EXPECT_LT((cc.rest.col(i) - centre).norm(), radius + 2 * q0.meanEdge * 3);
    // Fine near the centre: every triangle within half the radius is 2^levels times smaller.
    double coarsestMax = 0;
    for (int t = 0; t < base.triangleCount(); ++t) coarsestMax = std::max(coarsestMax, maxEdge(base, t));
    for (int t = 0; t < cc.triangleCount(); ++t) {
      const auto& tri = cc.triangles[t];
      const Vec3 c = (cc.rest.col(tri[0]) + cc.rest.col(tri[1]) + cc.rest.col(tri[2])) / 3;
      if ((c - centre).norm() < 0.5 * radius) {
        EXPECT_LE(maxEdge(cc, t), coarsestMax / std::pow(2.0, levels) * 1.0001);
      }
    }
    // Well shaped: red children keep their parent's angles, green halves keep at least half.
    EXPECT_GE(rep.minAngleDeg, 0.5 * q0.minAngleDeg - 1e-9);
    EXPECT_GT(rep.redTriangles, 0);
    std::printf("  level %d: %d vertices (+%d), %d triangles, %d red splits, %d green closures, "
                "min angle %.2f deg (unrefined %.2f)\n",
                levels, cc.vertexCount(), rep.addedVertices, cc.triangleCount(), rep.redTriangles,
                rep.greenTriangles, rep.minAngleDeg, q0.minAngleDeg);
  }
}

TEST(Refine, JunctionEdgesSplitForEveryWall) {
  // Box cells: every edge of the block is shared by up to four walls; refining across them must
  // keep all cells closed.
  const CellComplex base = boxTissue(2, 2, 2, 1.0);
  const CellComplex cc = refineNear(base, Vec3(1, 1, 1), 0.3, 3);
  const ValidityReport v = checkValidity(cc);
  EXPECT_TRUE(v.ok()) << v.summary();
  EXPECT_GT(cc.triangleCount(), base.triangleCount());
  // Midpoints of clamped base edges are clamped, others free.
  for (int i = 0; i < cc.vertexCount(); ++i) EXPECT_EQ(cc.fixed[i] != 0, cc.rest(2, i) == 0.0);
}

TEST(Refine, LevelZeroIsTheIdentityAndBadInputIsRefused) {
  const CellComplex base = boxTissue(1, 1, 1, 1.0);
  const CellComplex same = refineNear(base, Vec3(0.5, 0.5, 1), 0.2, 0);
  EXPECT_EQ(same.triangleCount(), base.triangleCount());
  EXPECT_THROW(refineNear(base, Vec3(0, 0, 0), -1, 1), std::invalid_argument);
  EXPECT_THROW(refineNear(base, Vec3(0, 0, 0), 1, -1), std::invalid_argument);
}

TEST(Refine, ForceDepthCurveConvergesWithTheLevel) {
  const CellComplex base = smallMeristem();
  Material mat;
  IndentationSettings s;
  s.probeRadius = 0.5;
  s.maxDepth = 0.2;
  s.steps = 4;
  // Site: the top of the turgid unrefined tissue; refinement around its rest position.
  auto coarse = std::make_shared<CellComplex>(base);
  Model m0(coarse, mat);
  m0.setUniformPressure(0.8);
  Indentation i0(m0, s);
  ASSERT_TRUE(i0.prepare().converged);
  const Vec3 at = restPositionOf(m0, i0.turgidState(), i0.placement().site, i0.placement().triangle);
  s.site = i0.placement().site;
  std::vector<double> force;
  for (int level = 0; level <= 4; ++level) {
    auto cc = std::make_shared<CellComplex>(refineNear(base, at, 5.0, level));
    Model m(cc, mat);
    m.setUniformPressure(0.8);
    Indentation ind(m, s);
    ASSERT_TRUE(ind.prepare().converged) << "level " << level;
    const auto curve = ind.run();
    ASSERT_TRUE(curve.back().converged) << "level " << level << ": " << ind.lastMessage();
    force.push_back(curve.back().force);
    std::printf("  level %d: %5d vertices, force at %.2f um = %.4f uN\n", level,
                cc->vertexCount(), curve.back().depth, curve.back().force);
  }
  // Coarse meshes are far too stiff; the changes shrink and the last two levels agree.
  const double first = std::abs(force[1] - force[0]), last = std::abs(force[4] - force[3]);
  EXPECT_LT(last, 0.1 * first);
  EXPECT_LT(last, 0.1 * force[4]);
  for (int l = 1; l <= 4; ++l) EXPECT_LT(force[l], force[0]);
}

TEST(Refine, CoarseMeshLetsAVertexProbeThroughRefinedDoesNot) {
  // The study's observation, with contact checked at vertices only as in the published model:
  // a probe pushed into the middle of a coarse wall holds none of its vertices, so a vertex
  // contact would let it through, while on the refined mesh vertices lie in its way. Contact
  // against triangles holds the probe on both meshes.
  const CellComplex base = smallMeristem();
  Material mat;
  IndentationSettings s;
  s.probeRadius = 0.5;
  s.maxDepth = 0.2;
  s.steps = 2;
  auto coarse = std::make_shared<CellComplex>(base);
  Model m0(coarse, mat);
  m0.setUniformPressure(0.8);
  Indentation i0(m0, s);
  ASSERT_TRUE(i0.prepare().converged);
  const ProbePlacement pl = i0.placement();
  const Vec3 at = restPositionOf(m0, i0.turgidState(), pl.site, pl.triangle);
  for (int level : {0, 3}) {
    auto cc = std::make_shared<CellComplex>(refineNear(base, at, 5.0, level));
    Model m(cc, mat);
    m.setUniformPressure(0.8);
    IndentationSettings si = s;
    si.site = pl.site;
    Indentation ind(m, si);
    ASSERT_TRUE(ind.prepare().converged);
    // Vertices of the turgid surface in the probe's way down to the final depth.
    const Vec3 c0 = ind.placement().contactCenter, axis = ind.placement().axis;
    int inWay = 0;
    for (int v = 0; v < cc->vertexCount(); ++v) {
      const Vec3 d = ind.turgidState().col(v) - c0;
      const double along = std::clamp(d.dot(axis), 0.0, s.maxDepth);
      if ((d - along * axis).norm() < s.probeRadius) ++inWay;
    }
    const auto curve = ind.run();
    std::printf("  level %d: %d vertices in the probe's way to %.1f um; triangle contact: %.3f uN\n",
                level, inWay, s.maxDepth, curve.back().force);
    if (level == 0) EXPECT_EQ(inWay, 0);
    else EXPECT_GT(inWay, 0);
    ASSERT_TRUE(curve.back().converged);
    EXPECT_GT(curve.back().force, 0.0);
  }
}

namespace {

double longestEdge(const CellComplex& cc, int t) { return maxEdge(cc, t); }

double distanceToTriangle(const CellComplex& cc, int t, const Vec3& p) {
  const auto& tri = cc.triangles[t];
  return std::sqrt(pointTriangleDistance2(p, cc.rest.col(tri[0]), cc.rest.col(tri[1]),
                                          cc.rest.col(tri[2]), nullptr, nullptr, nullptr));
}

// A refinement at the top of the generated meristem: 0.25 µm under a 1 µm probe, graded out.
// The walls each edge (a vertex pair) belongs to; junction edges have three or more.
std::map<std::pair<int, int>, std::vector<int>> wallsOfEdges(const CellComplex& cc) {
  std::map<std::pair<int, int>, std::vector<int>> walls;
  for (int t = 0; t < cc.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k) {
      auto& w = walls[std::minmax(cc.triangles[t][k], cc.triangles[t][(k + 1) % 3])];
      if (std::find(w.begin(), w.end(), cc.triangleWall[t]) == w.end())
        w.push_back(cc.triangleWall[t]);
    }
  return walls;
}

GradedRefinement atTheTop() {
  GradedRefinement g;
  g.center = Vec3(0, 0, 41.5);
  g.finest = 0.25;
  g.innerRadius = 1.0;
  g.grading = 1.5;
  g.outerRadius = 8.0;
  return g;
}

}  // namespace

TEST(GradedRefinement, MeetsTheTargetSizeConformingAndGraded) {
  const CellComplex base = generateMeristem(MeristemParams{});
  const MeshQuality q0 = measureQuality(base);
  const GradedRefinement g = atTheTop();
  const RefinedComplex r = refineGraded(base, g);
  const CellComplex& cc = r.complex;
  const ValidityReport v = checkValidity(cc);  // a hanging node would leave a cell open
  ASSERT_TRUE(v.ok()) << v.summary();
  // Flat subdivision keeps every cell's volume; the base vertices stay first and unmoved.
  const auto vol0 = cellVolumes(base, base.rest), vol1 = cellVolumes(cc, cc.rest);
  for (size_t c = 0; c < vol0.size(); ++c) EXPECT_NEAR(vol1[c], vol0[c], 1e-9 * vol0[c]);
  for (int i = 0; i < base.vertexCount(); ++i) EXPECT_EQ(cc.rest.col(i), base.rest.col(i));
  // The target: within the outer radius every triangle is at most targetSize(d) long (d its
  // distance from the centre); the smallest ones under the probe are `finest`.
  double smallest = 1e9;
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const double d = distanceToTriangle(cc, t, g.center);
    if (d <= g.outerRadius) {
      EXPECT_LE(longestEdge(cc, t), g.targetSize(d) * (1 + 1e-12));
    }
    smallest = std::min(smallest, longestEdge(cc, t));
  }
  EXPECT_LE(smallest, g.finest);
  EXPECT_GT(smallest, 0.2 * g.finest);
  // Graded: triangles sharing an edge differ by at most one level (a factor ~2 in size, up to
  // the base mesh's own disparity at a base edge, and the green halves).
  std::map<std::pair<int, int>, std::vector<int>> byEdge;
  for (int t = 0; t < cc.triangleCount(); ++t)
    for (int k = 0; k < 3; ++k)
      byEdge[std::minmax(cc.triangles[t][k], cc.triangles[t][(k + 1) % 3])].push_back(t);
  int worse = 0;
  for (const auto& [e, ts] : byEdge)
    for (size_t i = 1; i < ts.size(); ++i) {
      const int a = ts[0], b = ts[i];
      if (r.baseTriangle[a] != r.baseTriangle[b]) continue;  // compare within a base triangle
      const double ratio = longestEdge(cc, a) / longestEdge(cc, b);
      if (ratio > 4.0 || ratio < 0.25) ++worse;
    }
  EXPECT_EQ(worse, 0);
  // Well shaped: no sliver worse than half the base mesh's smallest angle (green halves).
  EXPECT_GE(r.report.minAngleDeg, 0.5 * q0.minAngleDeg - 1e-9);
  // Whole walls: every triangle of a wall that reaches within the outer radius meets the
  // target, however far it is.
  std::vector<char> zone(cc.wallCount(), 0);
  for (int t = 0; t < cc.triangleCount(); ++t)
    if (distanceToTriangle(cc, t, g.center) <= g.outerRadius) zone[cc.triangleWall[t]] = 1;
  int beyond = 0;
  for (int t = 0; t < cc.triangleCount(); ++t) {
    if (!zone[cc.triangleWall[t]]) continue;
    const double d = distanceToTriangle(cc, t, g.center);
    EXPECT_LE(longestEdge(cc, t), g.targetSize(d) * (1 + 1e-12));
    beyond += d > g.outerRadius;
  }
  EXPECT_GT(beyond, 0);  // the zone's walls reach past the radius
  std::printf("  graded: %d vertices (+%d), %d triangles, %d passes, min angle %.2f deg (base "
              "%.2f)\n",
              cc.vertexCount(), r.report.addedVertices, cc.triangleCount(), r.report.levels,
              r.report.minAngleDeg, q0.minAngleDeg);
}

// The band along the junctions (siteRefinement's, for the bending boundary layer under turgor):
// every triangle of the zone with a corner on an edge shared by three or more walls within the
// outer radius is at most junctionSize long; the walls' middles keep the
// coarser target, and nothing outside the outer radius is refined for the band.
TEST(GradedRefinement, BandAlongTheJunctionsNearTheCentre) {
  const CellComplex base = generateMeristem(MeristemParams{});
  GradedRefinement g = atTheTop();
  const RefinedComplex plain = refineGraded(base, g);
  g.junctionSize = 0.3;
  const RefinedComplex r = refineGraded(base, g);
  const CellComplex& cc = r.complex;
  const ValidityReport v = checkValidity(cc);
  ASSERT_TRUE(v.ok()) << v.summary();
  // Junction edges of the refined tissue (they lie on the base's: bisection keeps them edges).
  std::vector<char> onJunction(cc.vertexCount(), 0);
  for (const auto& [e, w] : wallsOfEdges(cc))
    if (w.size() >= 3) onJunction[e.first] = onJunction[e.second] = 1;
  int inBand = 0, middlesCoarser = 0, bandBeyond = 0;
  for (int t = 0; t < cc.triangleCount(); ++t) {
    const double d = distanceToTriangle(cc, t, g.center);
    bool touches = false, touchesWithin = false;
    for (int k = 0; k < 3; ++k) {
      const int i = cc.triangles[t][k];
      touches |= onJunction[i] != 0;
      touchesWithin |= onJunction[i] && (cc.rest.col(i) - g.center).norm() <= g.outerRadius;
    }
    if (d <= g.outerRadius && touchesWithin && g.targetSize(d) > g.junctionSize) {
      ++inBand;
      EXPECT_LE(longestEdge(cc, t), g.junctionSize * (1 + 1e-12)) << "triangle " << t;
    }
    if (d <= g.outerRadius && !touches && longestEdge(cc, t) > 2 * g.junctionSize) ++middlesCoarser;
    if (d > g.outerRadius + 1.0 && touches && longestEdge(cc, t) <= g.junctionSize) ++bandBeyond;
  }
  EXPECT_GT(inBand, 100);
  EXPECT_GT(middlesCoarser, 100);  // a band, not the whole zone at the band's size
  // Beyond the radius the band's triangles are only the closure's few (one level per edge).
  EXPECT_LT(bandBeyond, inBand / 10);
  EXPECT_GT(cc.vertexCount(), plain.complex.vertexCount());
  std::printf("  junction band: %d vertices against %d without, %d band triangles\n",
              cc.vertexCount(), plain.complex.vertexCount(), inBand);
}

TEST(GradedRefinement, TheBandFollowsOnlyTheJunctionsWithinItsRadius) {
  // The base's junction edges (shared by three or more walls) near the top: those coming within
  // the band's radius (A) and those within the zone but beyond it (B). The band refines along A's
  // whole length within the zone and leaves B's triangles as the zone's sizes make them.
  const CellComplex base = generateMeristem(MeristemParams{});
  GradedRefinement g = atTheTop();
  g.junctionSize = 0.3;
  g.junctionRadius = 4.0;
  const RefinedComplex r = refineGraded(base, g);
  const CellComplex& cc = r.complex;
  ASSERT_TRUE(checkValidity(cc).ok());
  const auto segment = [](const Vec3& x, const Vec3& p, const Vec3& q) {
    const Vec3 d = q - p;
    const double t = std::clamp((x - p).dot(d) / d.squaredNorm(), 0.0, 1.0);
    return (x - (p + t * d)).norm();
  };
  struct Junction {
    Vec3 p, q;
    std::vector<int> walls;
  };
  std::vector<Junction> a, b;
  for (const auto& [e, w] : wallsOfEdges(base)) {
    if (w.size() < 3) continue;
    const Vec3 p = base.rest.col(e.first), q = base.rest.col(e.second);
    const double d = segment(g.center, p, q);
    if (d <= g.junctionRadius)
      a.push_back({p, q, w});
    else if (d <= g.outerRadius)
      b.push_back({p, q, w});
  }
  ASSERT_GT(a.size(), 5u);
  ASSERT_GT(b.size(), 5u);
  // The distance of a triangle's corners from the junctions in a set (of its own wall's only).
  const auto nearest = [&](const CellComplex& m, const std::vector<Junction>& set, int t,
                           bool ownWall) {
    double d = 1e300;
    for (const Junction& j : set)
      if (!ownWall || std::find(j.walls.begin(), j.walls.end(), m.triangleWall[t]) != j.walls.end())
        for (int k = 0; k < 3; ++k)
          d = std::min(d, segment(m.rest.col(m.triangles[t][k]), j.p, j.q));
    return d;
  };
  // Triangles along A (own wall) must be banded; along B, away from A, they are banded only
  // when the band reaches the whole zone (the refinement without a band radius).
  g.junctionRadius = 0;
  const RefinedComplex wholeZone = refineGraded(base, g);
  const CellComplex& whole = wholeZone.complex;
  const auto count = [&](const CellComplex& m) {
    int onA = 0, onB = 0, banded = 0;
    for (int t = 0; t < m.triangleCount(); ++t) {
      const double d = distanceToTriangle(m, t, g.center);
      if (d > g.outerRadius || g.targetSize(d) <= 2 * g.junctionSize) continue;
      if (nearest(m, a, t, true) < 1e-9) {
        ++onA;
        EXPECT_LE(longestEdge(m, t), g.junctionSize * (1 + 1e-12)) << "triangle " << t;
      } else if (nearest(m, b, t, true) < 1e-9 && nearest(m, a, t, false) > g.targetSize(d)) {
        ++onB;
        if (longestEdge(m, t) <= g.junctionSize) ++banded;
      }
    }
    return std::array<int, 3>{onA, onB, banded};
  };
  const auto [onA, onB, bandedB] = count(cc);
  const auto [onAWhole, onBWhole, bandedBWhole] = count(whole);
  EXPECT_GT(onA, 100);
  EXPECT_GT(onBWhole, 100);
  EXPECT_GT(bandedBWhole, 0.9 * onBWhole);  // B is banded when the band has no radius of its own
  EXPECT_LT(bandedB, onB / 10 + 1);         // and otherwise only the closure's few triangles
  EXPECT_LT(cc.vertexCount(), whole.vertexCount());
  std::printf(
      "  band radius 4: %d triangles along its junctions, %d of %d banded beyond; "
      "without a radius %d of %d; %d against %d vertices\n",
      onA, bandedB, onB, bandedBWhole, onBWhole, cc.vertexCount(), whole.vertexCount());
}

TEST(GradedRefinement, ProlongationAndTransferAreExactForAffineFields) {
  const CellComplex base = smallMeristem();
  GradedRefinement g;
  g.center = Vec3(0, 0, 16);
  g.finest = 0.5;
  g.innerRadius = 1;
  g.grading = 1;
  g.outerRadius = 5;
  const RefinedComplex a = refineGraded(base, g);
  g.finest = 0.25;
  g.grading = 2;
  const RefinedComplex b = refineGraded(base, g);
  ASSERT_GT(b.complex.vertexCount(), a.complex.vertexCount());
  // The refinement puts each new vertex at the midpoint of its parents.
  EXPECT_LT((prolongate(base.rest, a.parents) - a.complex.rest).cwiseAbs().maxCoeff(), 1e-12);
  // An affine deformation of the rest state is carried from one refinement to another exactly
  // (linear interpolation reproduces affine fields), both ways and from the base.
  Eigen::Matrix3d A;
  A << 1.1, 0.2, -0.1, 0.05, 0.9, 0.3, -0.2, 0.1, 1.2;
  const Vec3 shift(1, -2, 0.5);
  auto affine = [&](const Points& X) -> Points { return (A * X).colwise() + shift; };
  const RefinedComplex self = unrefined(base);
  for (const auto& [from, to] : {std::pair{&a, &b}, std::pair{&b, &a}, std::pair{&self, &b}}) {
    const Points moved = transferPositions(base, *from, affine(from->complex.rest), *to);
    EXPECT_LT((moved - affine(to->complex.rest)).cwiseAbs().maxCoeff(), 1e-9);
  }
  // Not affine: the base vertices, which every refinement shares, keep their positions (to
  // round-off in the barycentric weights).
  Points wavy = a.complex.rest;
  for (int v = 0; v < wavy.cols(); ++v) wavy(2, v) += std::sin(wavy(0, v));
  const Points onB = transferPositions(base, a, wavy, b);
  for (int v = 0; v < base.vertexCount(); ++v)
    EXPECT_LT((onB.col(v) - wavy.col(v)).norm(), 1e-12 * (1 + wavy.col(v).norm()));
}

TEST(GradedRefinement, RefineWallsHalvesEveryTriangleOfTheWallsFlagged) {
  const CellComplex base = boxTissue(2, 2, 1, 2.0);
  std::vector<char> walls(base.wallCount(), 0);
  walls[0] = walls[3] = 1;
  const RefinedComplex r = refineWalls(base, walls, 2);
  ASSERT_TRUE(checkValidity(r.complex).ok());
  std::vector<int> count(base.wallCount(), 0), baseCount(base.wallCount(), 0);
  for (int w : r.complex.triangleWall) ++count[w];
  for (int w : base.triangleWall) ++baseCount[w];
  for (int w = 0; w < base.wallCount(); ++w)
    if (walls[w]) {
      EXPECT_EQ(count[w], 16 * baseCount[w]) << "wall " << w;  // two halvings
    }
  EXPECT_THROW(refineWalls(base, std::vector<char>(3, 1), 1), std::invalid_argument);
}
