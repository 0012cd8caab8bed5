// SnapshotBuffers: array sizes, per-triangle colours, normals, cells and flags, outlines and
// clamped points; the probe's sphere; automatic colour ranges.
#include <QTest>

#include <cmath>

#include "SnapshotBuffers.h"
#include "TestMain.h"
#include "tissue/Shapes.h"

using namespace tp::gui;

namespace {

Snapshot boxSnapshot(const tp::CellComplex& cc) {
  Snapshot s;
  s.geometry = makeTissueGeometry(cc, 1, "box", meanCellSize(cc));
  for (Eigen::Index i = 0; i < cc.rest.size(); ++i) s.positions.push_back(float(cc.rest.data()[i]));
  for (auto& f : s.fields) f.assign(cc.triangleCount(), 0.0f);
  // Von Mises = the triangle's index, so colours can be predicted.
  for (int t = 0; t < cc.triangleCount(); ++t) s.fields[int(Field::VonMises)][t] = float(t);
  return s;
}

Eigen::Vector3f colourOf(const SnapshotBuffers& b, int vertex) {
  const float* v = b.triangleVertices().data() + vertex * SnapshotBuffers::kTriangleStride;
  return {v[SnapshotBuffers::kColorOffset], v[SnapshotBuffers::kColorOffset + 1],
          v[SnapshotBuffers::kColorOffset + 2]};
}

}  // namespace

class BuffersTest : public QObject {
  Q_OBJECT

 private slots:
  void outlinesAreTheWallBoundaries() {
    // Two cubes sharing a face: 12 + 12 − 4 = 20 distinct edges; no square's diagonal.
    const tp::CellComplex cc = tp::boxTissue(2, 1, 1, 5.0);
    const auto edges = wallOutlineEdges(cc);
    QCOMPARE(int(edges.size()), 2 * 20);
    for (size_t i = 0; i < edges.size(); i += 2) {
      const Eigen::Vector3d d = cc.rest.col(edges[i]) - cc.rest.col(edges[i + 1]);
      QVERIFY(std::abs(d.norm() - 5.0) < 1e-12);  // cube edges, not diagonals (7.07)
    }
    // Outer edges first: all 20 edges of two cubes side by side lie on the outer surface, the
    // shared square's 4 included; inner edges only exist where a wall is inner all round.
    int outer = -1;
    QCOMPARE(wallOutlineEdges(cc, &outer), edges);
    QCOMPARE(outer, 20);
    const tp::CellComplex row = tp::boxTissue(3, 3, 3, 5.0);
    const auto all = wallOutlineEdges(row, &outer);
    const int E = int(all.size()) / 2;
    QVERIFY(outer > 0 && outer < E);
    // An edge listed as inner touches no outer wall: its two vertices are not both on the box.
    const auto onBox = [&](int v) {
      const Eigen::Vector3d p = row.rest.col(v);
      return (p.array().abs() < 1e-9).any() || ((p.array() - 15).abs() < 1e-9).any();
    };
    for (int e = outer; e < E; ++e)
      QVERIFY(!(onBox(all[2 * e]) && onBox(all[2 * e + 1])));
    for (int e = 0; e < outer; ++e) QVERIFY(onBox(all[2 * e]) && onBox(all[2 * e + 1]));
  }

  void sizesColoursAndAttributes() {
    const tp::CellComplex cc = tp::boxTissue(2, 1, 1, 5.0);
    const Snapshot s = boxSnapshot(cc);
    const int T = cc.triangleCount();
    ColorMap map;
    map.setRange(0, T - 1);
    SnapshotBuffers b;
    b.build(s, Field::VonMises, map);
    QCOMPARE(b.triangleVertexCount(), 3 * T);
    QCOMPARE(int(b.triangleVertices().size()), 3 * T * SnapshotBuffers::kTriangleStride);
    QCOMPARE(b.lineVertexCount(), 40);
    int clamped = 0;
    for (auto f : cc.fixed) clamped += f;
    QCOMPARE(b.clampedPointCount(), clamped);
    QVERIFY((b.bounds().max() - Eigen::Vector3d(10, 5, 5)).norm() < 1e-6);

    // Outer triangles first (in their order), then the inner ones: without a section plane the
    // renderer draws only the first outerTriangleVertexCount() vertices.
    std::vector<int> order;
    for (int t = 0; t < T; ++t)
      if (cc.isOuterTriangle(t)) order.push_back(t);
    QCOMPARE(b.outerTriangleVertexCount(), 3 * int(order.size()));
    QVERIFY(int(order.size()) < T);  // the shared face is inner
    for (int t = 0; t < T; ++t)
      if (!cc.isOuterTriangle(t)) order.push_back(t);
    for (int i = 0; i < T; ++i) {
      const int t = order[i];
      const Eigen::Vector3f expected = map.color(t);
      for (int k = 0; k < 3; ++k) QVERIFY((colourOf(b, 3 * i + k) - expected).norm() < 1e-6f);
      const float* v = b.triangleVertices().data() + 3 * i * SnapshotBuffers::kTriangleStride;
      // Position = the triangle's first corner; a unit normal; the wall's cells; the flags.
      const auto& tri = cc.triangles[t];
      QVERIFY(std::abs(v[0] - cc.rest(0, tri[0])) < 1e-6f);
      QVERIFY(std::abs(Eigen::Vector3f(v[3], v[4], v[5]).norm() - 1) < 1e-6f);
      const auto& wall = cc.walls[cc.triangleWall[t]];
      QCOMPARE(int(v[SnapshotBuffers::kCellsOffset]), wall.cell);
      QCOMPARE(int(v[SnapshotBuffers::kCellsOffset + 1]), wall.neighbor);
      const int flags = int(v[SnapshotBuffers::kFlagsOffset]);
      const bool base = cc.fixed[tri[0]] && cc.fixed[tri[1]] && cc.fixed[tri[2]];
      QCOMPARE(bool(flags & SnapshotBuffers::kClamped), base);
      QCOMPARE(bool(flags & SnapshotBuffers::kOuter), cc.isOuterTriangle(t));
    }
    // The ends of the map at the ends of the range.
    const auto at = [&](int t) {
      return int(std::find(order.begin(), order.end(), t) - order.begin());
    };
    QVERIFY((colourOf(b, 3 * at(0)) - map.colorAt(0)).norm() < 1e-6f);
    QVERIFY((colourOf(b, 3 * at(T - 1)) - map.colorAt(1)).norm() < 1e-6f);
  }

  void shadingIsSmoothInsideAWallAndCrispOnItsOutline() {
    // A sphere of one wall: every vertex is inside it, so every corner's normal is the mean of
    // the triangles around it, within 3° of the sphere's radial direction, where the
    // triangles' own normals are up to 9° off and more (a curved wall drawn smooth).
    const tp::CellComplex sphere = tp::octaSphere(5.0, 3);
    const Snapshot s = boxSnapshot(sphere);
    for (int w : s.geometry->vertexWall) QCOMPARE(w, 0);
    SnapshotBuffers b;
    b.build(s, Field::VonMises, ColorMap{});
    double worstCorner = 1, worstFlat = 1;
    for (int i = 0; i < b.triangleVertexCount(); ++i) {
      const float* v = b.triangleVertices().data() + i * SnapshotBuffers::kTriangleStride;
      const Eigen::Vector3f x(v[0], v[1], v[2]), n(v[3], v[4], v[5]);
      QVERIFY(std::abs(n.norm() - 1) < 1e-5f);
      worstCorner = std::min(worstCorner, double(n.dot(x.normalized())));
      if (i % 3 == 0) {
        const float* w = v + SnapshotBuffers::kTriangleStride;
        const float* u = w + SnapshotBuffers::kTriangleStride;
        const Eigen::Vector3f flat = (Eigen::Vector3f(w[0], w[1], w[2]) - x)
                                         .cross(Eigen::Vector3f(u[0], u[1], u[2]) - x)
                                         .normalized();
        worstFlat = std::min(worstFlat, double(flat.dot(x.normalized())));
      }
    }
    // Measured: corners within 2.8° of radial, triangles up to 10.0° off.
    QVERIFY2(worstCorner > std::cos(3.0 * M_PI / 180), qPrintable(QString::number(worstCorner)));
    QVERIFY2(worstFlat < std::cos(9.0 * M_PI / 180), qPrintable(QString::number(worstFlat)));

    // Two cubes: every vertex is on an outline (walls meet there), so every corner keeps its
    // triangle's own normal and the cells keep their edges.
    const tp::CellComplex box = tp::boxTissue(2, 1, 1, 5.0);
    const Snapshot boxes = boxSnapshot(box);
    for (int w : boxes.geometry->vertexWall) QCOMPARE(w, -1);
    b.build(boxes, Field::VonMises, ColorMap{});
    for (int i = 0; i < b.triangleVertexCount(); i += 3) {
      const float* v = b.triangleVertices().data() + i * SnapshotBuffers::kTriangleStride;
      const Eigen::Vector3f n(v[3], v[4], v[5]);
      for (int k = 1; k < 3; ++k) {
        const float* w = v + k * SnapshotBuffers::kTriangleStride;
        QVERIFY((Eigen::Vector3f(w[3], w[4], w[5]) - n).norm() < 1e-6f);
      }
      QVERIFY(std::abs(std::abs(n.x()) + std::abs(n.y()) + std::abs(n.z()) - 1) < 1e-6f);  // axis
    }
  }

  void principalDirectionsAreSegmentsThroughTheCentroids() {
    // σ₁ along x everywhere, twice as large on the first triangle: every segment lies along x
    // through its triangle's centroid, 0.8 √area long at the scale's σ₁ (the 99.5th percentile,
    // here 10: the one outlier beyond it is capped, not allowed to shrink all others); outer
    // triangles first.
    const tp::CellComplex cc = tp::boxTissue(2, 2, 2, 5.0);
    Snapshot s = boxSnapshot(cc);
    const int T = cc.triangleCount();
    s.principalAxes.assign(3 * T, 0.0f);
    for (int t = 0; t < T; ++t) s.principalAxes[3 * t] = t == 0 ? 20.0f : 10.0f;
    SnapshotBuffers b;
    b.build(s, Field::VonMises, ColorMap{});
    QCOMPARE(b.glyphVertexCount(), 2 * T);
    int outer = 0;
    for (int t = 0; t < T; ++t) outer += cc.isOuterTriangle(t);
    QCOMPARE(b.outerGlyphVertexCount(), 2 * outer);
    std::vector<int> order;
    for (int pass = 0; pass < 2; ++pass)
      for (int t = 0; t < T; ++t)
        if (cc.isOuterTriangle(t) == (pass == 0)) order.push_back(t);
    for (int i = 0; i < T; ++i) {
      const int t = order[i];
      const float* g = b.glyphVertices().data() + 6 * i;
      const Eigen::Vector3f p(g[0], g[1], g[2]), q(g[3], g[4], g[5]);
      const auto& tri = cc.triangles[t];
      const Eigen::Vector3d a = cc.rest.col(tri[0]), bb = cc.rest.col(tri[1]),
                            c = cc.rest.col(tri[2]);
      const Eigen::Vector3f centroid = ((a + bb + c) / 3).cast<float>();
      const float area = float(0.5 * (bb - a).cross(c - a).norm());
      QVERIFY(((p + q) / 2 - centroid).norm() < 1e-5f);
      QVERIFY(std::abs(p.y() - q.y()) < 1e-6f && std::abs(p.z() - q.z()) < 1e-6f);
      // All triangles of these cubes have one area: 10 is the largest past the top 0.5 %.
      QVERIFY2(std::abs((q - p).norm() - 0.8f * std::sqrt(area)) < 1e-4f,
               qPrintable(QString::number((q - p).norm())));
    }
    // No stress (a tissue at rest): no glyphs.
    s.principalAxes.clear();
    b.build(s, Field::VonMises, ColorMap{});
    QCOMPARE(b.glyphVertexCount(), 0);
  }

  void theContactPatchIsOutlinedByItsBoundaryEdges() {
    // A cube (each face two triangles): the patch of the top face's two triangles is outlined by
    // the square's four sides, never its diagonal; a single triangle by its three sides; the
    // top and a side face together by the six sides of the two squares but the shared one.
    const tp::CellComplex cc = tp::boxTissue(1, 1, 1, 5.0);
    Snapshot s = boxSnapshot(cc);
    auto onFace = [&](int t, int axis, double value) {
      for (int k = 0; k < 3; ++k)
        if (std::abs(cc.rest(axis, cc.triangles[t][k]) - value) > 1e-9) return false;
      return true;
    };
    std::vector<int> top, side;
    for (int t = 0; t < cc.triangleCount(); ++t) {
      if (onFace(t, 2, 5.0)) top.push_back(t);
      if (onFace(t, 0, 0.0)) side.push_back(t);
    }
    QCOMPARE(int(top.size()), 2);
    QCOMPARE(int(side.size()), 2);
    SnapshotBuffers b;
    auto sides = [&](const std::vector<int>& patch) {
      s.contactTriangles = patch;
      b.build(s, Field::VonMises, ColorMap{});
      std::vector<double> lengths;
      const auto& v = b.contactVertices();
      for (int i = 0; i + 5 < int(v.size()); i += 6)
        lengths.push_back((Eigen::Vector3f(v[i], v[i + 1], v[i + 2]) -
                           Eigen::Vector3f(v[i + 3], v[i + 4], v[i + 5]))
                              .norm());
      return lengths;
    };
    const auto square = sides(top);
    QCOMPARE(int(square.size()), 4);
    for (double l : square) QVERIFY(std::abs(l - 5.0) < 1e-5);
    QCOMPARE(int(sides({top[0]}).size()), 3);
    std::vector<int> both = top;
    both.insert(both.end(), side.begin(), side.end());
    const auto two = sides(both);
    QCOMPARE(int(two.size()), 6);
    for (double l : two) QVERIFY(std::abs(l - 5.0) < 1e-5);
    QCOMPARE(int(sides({}).size()), 0);
    QCOMPARE(b.contactVertexCount(), 0);
  }

  void anotherFieldAnotherColour() {
    const tp::CellComplex cc = tp::boxTissue(1, 1, 1, 5.0);
    Snapshot s = boxSnapshot(cc);
    s.fields[int(Field::Displacement)].assign(cc.triangleCount(), 2.0f);
    ColorMap map;
    map.setRange(0, 2);
    SnapshotBuffers b;
    b.build(s, Field::Displacement, map);
    for (int v = 0; v < b.triangleVertexCount(); ++v)
      QVERIFY((colourOf(b, v) - map.colorAt(1)).norm() < 1e-6f);
  }

  void emptySnapshotGivesEmptyArrays() {
    SnapshotBuffers b;
    b.build(Snapshot{}, Field::VonMises, ColorMap{});
    QCOMPARE(b.triangleVertexCount(), 0);
    QCOMPARE(b.lineVertexCount(), 0);
  }

  void probeSphereIsAClosedOutwardUnitSphere() {
    for (int level : {0, 2}) {
      const std::vector<float> m = unitSphereMesh(level);
      QCOMPARE(int(m.size()), 20 * (1 << (2 * level)) * 3 * 6);
      for (size_t i = 0; i < m.size(); i += 18) {
        Eigen::Vector3f a(m[i], m[i + 1], m[i + 2]), b(m[i + 6], m[i + 7], m[i + 8]),
            c(m[i + 12], m[i + 13], m[i + 14]);
        QVERIFY(std::abs(a.norm() - 1) < 1e-6f);
        QVERIFY((b - a).cross(c - a).dot(a + b + c) > 0);  // counter-clockwise from outside
      }
    }
  }

  void autoRanges() {
    const tp::CellComplex cc = tp::boxTissue(1, 1, 1, 5.0);
    Snapshot s = boxSnapshot(cc);
    auto& f = s.fields[int(Field::PrincipalMax)];
    f.assign(f.size(), 1.0f);
    f[0] = -2.0f;
    f[1] = 5.0f;
    f[2] = std::nanf("");
    const AutoRange r = autoRange(s, Field::PrincipalMax, false);
    QCOMPARE(r.lo, -2.0);  // 12 triangles: none left out
    QCOMPARE(r.hi, 5.0);
    const AutoRange d = autoRange(s, Field::PrincipalMax, true);  // zero in the middle
    QCOMPARE(d.lo, -5.0);
    QCOMPARE(d.hi, 5.0);
  }

  void autoRangeIgnoresSliversButNotTheProbesSignal() {
    // 5,000 triangles between 10 and 20 MPa and four slivers at 75: a stress keeps its colours
    // for the 5,000 (the slivers take the end colour and are reported as the data's extreme).
    Snapshot s;
    auto& vm = s.fields[int(Field::VonMises)];
    for (int i = 0; i < 5000; ++i) vm.push_back(10.0f + 10.0f * float(i) / 4999.0f);
    for (int i = 0; i < 4; ++i) vm.push_back(75.0f);
    const AutoRange r = autoRange(s, Field::VonMises, false);
    QVERIFY(r.hi <= 20.0 && r.hi > 19.9);
    QVERIFY(r.lo >= 10.0 && r.lo < 10.1);
    QCOMPARE(r.dataHi, 75.0);
    QVERIFY(r.clippedHigh());
    QVERIFY(!r.clippedLow() || r.dataLo < r.lo);
    // A change from the turgid state keeps its extremes: there the few triangles are the probe.
    auto& change = s.fields[int(Field::VonMisesChange)];
    change.assign(5004, 0.0f);
    change[7] = 3.0f;
    change[8] = -1.0f;
    const AutoRange c = autoRange(s, Field::VonMisesChange, true);
    QCOMPARE(c.lo, -3.0);
    QCOMPARE(c.hi, 3.0);
    QVERIFY(!c.clippedHigh() && !c.clippedLow());
    // Numerical noise (no pressure, no probe) is not stretched over the whole colour bar.
    for (float& v : vm) v = 1.5e-12f;
    const AutoRange n = autoRange(s, Field::VonMises, false);
    QCOMPARE(n.lo, 0.0);
    QCOMPARE(n.hi, kNoiseFloor);
    change.assign(5004, -6e-11f);
    const AutoRange d = autoRange(s, Field::VonMisesChange, true);
    QCOMPARE(d.lo, -kNoiseFloor);
    QCOMPARE(d.hi, kNoiseFloor);
  }
};

TP_GUI_TEST(BuffersTest)
#include "test_buffers.moc"
