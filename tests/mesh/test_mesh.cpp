// Mesh pieces with no direct test before issue 10: the polygon triangulation behind every wall
// and the topology (edges, hinges, outer surface) behind bending and contact.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "mesh/CellComplex.h"
#include "mesh/Topology.h"
#include "tissue/Shapes.h"

using namespace tp;
using std::numbers::pi;

namespace {

Vec3 col(const Points& p, int i) { return p.col(i); }

// Area vector (½ (b − a) × (c − a)) of a triangle.
Vec3 areaVector(const Points& p, const Eigen::Vector3i& t) {
  return 0.5 * (col(p, t[1]) - col(p, t[0])).cross(col(p, t[2]) - col(p, t[0]));
}

double smallestAngleDeg(const Points& p, const Eigen::Vector3i& t) {
  double least = 180;
  for (int k = 0; k < 3; ++k) {
    const Vec3 a = col(p, t[k]), b = col(p, t[(k + 1) % 3]), c = col(p, t[(k + 2) % 3]);
    const double cosine = (b - a).normalized().dot((c - a).normalized());
    least = std::min(least, std::acos(std::clamp(cosine, -1.0, 1.0)) * 180 / pi);
  }
  return least;
}

// Checks a triangulation of a simple polygon with outward normal n and area A: n − 2 triangles
// of the polygon's vertices, each wound like the polygon (a triangle outside a non-convex
// polygon would be wound the other way), areas summing to A.
void expectTriangulates(const Points& p, const std::vector<int>& polygon,
                        const std::vector<Eigen::Vector3i>& tris, const Vec3& n, double A) {
  ASSERT_EQ(tris.size(), polygon.size() - 2);
  const std::set<int> corners(polygon.begin(), polygon.end());
  double total = 0;
  for (const auto& t : tris) {
    for (int k = 0; k < 3; ++k) EXPECT_TRUE(corners.count(t[k])) << t.transpose();
    const double signedArea = areaVector(p, t).dot(n);
    EXPECT_GT(signedArea, 1e-9) << "triangle " << t.transpose() << " is flipped or flat";
    total += signedArea;
  }
  EXPECT_NEAR(total, A, 1e-12 * A);
}

}  // namespace

// A regular hexagon of side s (area 3√3/2 s²), flat and then turned out of its plane: four
// triangles, the polygon's winding, and the best smallest angle (30°: every triangulation of a
// regular hexagon has a 30° angle; a fan of slivers would not appear for a convex polygon).
TEST(TriangulatePolygon, RegularHexagonInAnyPlane) {
  const double s = 2.0;
  Points p(3, 6);
  for (int i = 0; i < 6; ++i) p.col(i) = Vec3(s * std::cos(i * pi / 3), s * std::sin(i * pi / 3), 0);
  const std::vector<int> polygon{0, 1, 2, 3, 4, 5};
  const double area = 3 * std::sqrt(3.0) / 2 * s * s;
  const Eigen::Matrix3d turn =
      (Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized())).toRotationMatrix();
  for (bool turned : {false, true}) {
    const Points q = turned ? Points(turn * p) : p;
    const Vec3 n = turned ? Vec3(turn * Vec3::UnitZ()) : Vec3::UnitZ();
    const auto tris = triangulatePolygon(q, polygon);
    expectTriangulates(q, polygon, tris, n, area);
    for (const auto& t : tris) EXPECT_GE(smallestAngleDeg(q, t), 30 - 1e-9);
  }
}

// A non-convex L of three unit squares (area 3), given from the reflex corner and in reverse:
// every triangle inside (wound like the polygon), whatever vertex the list starts at.
TEST(TriangulatePolygon, NonConvexPolygonStaysInside) {
  Points p(3, 6);
  p << 0, 2, 2, 1, 1, 0,  //
      0, 0, 1, 1, 2, 2,   //
      0, 0, 0, 0, 0, 0;
  for (int start = 0; start < 6; ++start) {
    std::vector<int> polygon;
    for (int i = 0; i < 6; ++i) polygon.push_back((start + i) % 6);
    expectTriangulates(p, polygon, triangulatePolygon(p, polygon), Vec3::UnitZ(), 3.0);
    const std::vector<int> reversed(polygon.rbegin(), polygon.rend());
    expectTriangulates(p, reversed, triangulatePolygon(p, reversed), -Vec3::UnitZ(), 3.0);
  }
}

TEST(TriangulatePolygon, RefusesFewerThanThreeVertices) {
  Points p = Points::Zero(3, 2);
  p(0, 1) = 1;
  EXPECT_THROW(triangulatePolygon(p, {0, 1}), std::exception);
}

// One cube cell: a closed surface of 8 vertices, 12 triangles and 18 edges (Euler: 8 − 18 + 12
// = 2), every edge between exactly two triangles and carrying one hinge, every triangle outer.
TEST(Topology, OneCubeCellIsAClosedSurface) {
  const CellComplex cc = boxTissue(1, 1, 1, 1.0);
  ASSERT_EQ(cc.vertexCount(), 8);
  ASSERT_EQ(cc.triangleCount(), 12);
  const Topology topo = buildTopology(cc);
  EXPECT_EQ(topo.edges.size(), 18u);
  EXPECT_EQ(topo.hinges.size(), 18u);
  EXPECT_EQ(topo.outerTriangles.size(), 12u);
  for (const auto& tris : topo.edgeTriangles) EXPECT_EQ(tris.size(), 2u);
}

// Two cubes sharing a wall: the shared wall's four boundary edges are junctions of three
// triangles (two outer, one inner) and carry one hinge, between the two outer triangles; its
// triangles are not outer. Each hinge's vertices are its two triangles' (the shared edge (x0, x1)
// in A = (x0, x1, x2) and B = (x1, x0, x3)), and every vertex knows its triangles.
TEST(Topology, JunctionEdgesHingeOnlyTheOuterSheet) {
  const CellComplex cc = boxTissue(2, 1, 1, 1.0);
  ASSERT_EQ(cc.vertexCount(), 12);
  ASSERT_EQ(cc.triangleCount(), 22);
  const Topology topo = buildTopology(cc);
  EXPECT_EQ(topo.outerTriangles.size(), 20u);
  for (int t : topo.outerTriangles) EXPECT_TRUE(cc.isOuterTriangle(t));
  int junctions = 0;
  for (size_t e = 0; e < topo.edges.size(); ++e) {
    const size_t n = topo.edgeTriangles[e].size();
    EXPECT_TRUE(n == 2 || n == 3) << n;
    if (n == 3) ++junctions;
  }
  EXPECT_EQ(junctions, 4);
  // The outer surface is a sphere (V − E + F = 2: 12 − E + 20, so 30 edges), and the inner wall
  // adds its diagonal.
  EXPECT_EQ(topo.edges.size(), 31u);
  EXPECT_EQ(topo.hinges.size(), topo.edges.size());
  for (const Hinge& h : topo.hinges) {
    const auto sameSet = [&](int t, std::array<int, 3> v) {
      std::set<int> a{cc.triangles[t][0], cc.triangles[t][1], cc.triangles[t][2]};
      return a == std::set<int>(v.begin(), v.end());
    };
    EXPECT_TRUE(sameSet(h.triA, {h.v[0], h.v[1], h.v[2]}));
    EXPECT_TRUE(sameSet(h.triB, {h.v[1], h.v[0], h.v[3]}));
    const bool junction = [&] {
      for (size_t e = 0; e < topo.edges.size(); ++e)
        if (std::set<int>{topo.edges[e][0], topo.edges[e][1]} == std::set<int>{h.v[0], h.v[1]})
          return topo.edgeTriangles[e].size() == 3;
      return false;
    }();
    if (junction) {
      EXPECT_TRUE(cc.isOuterTriangle(h.triA));
      EXPECT_TRUE(cc.isOuterTriangle(h.triB));
    }
  }
  ASSERT_EQ(topo.vertexTriangles.size(), 12u);
  for (int v = 0; v < 12; ++v)
    for (int t : topo.vertexTriangles[v])
      EXPECT_TRUE(cc.triangles[t][0] == v || cc.triangles[t][1] == v || cc.triangles[t][2] == v);
}
