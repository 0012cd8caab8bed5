// Picking: a ray through a known triangle hits it, a ray outside misses, the nearest hit wins,
// the BVH agrees with brute force, refits follow moved vertices, and hover names the right cell.
#include <QElapsedTimer>
#include <QTest>

#include <random>

#include "Picking.h"
#include "Snapshot.h"
#include "TestMain.h"
#include "io/Paths.h"
#include "io/Ply.h"
#include "tissue/Shapes.h"

using namespace tp::gui;

namespace {

std::vector<float> floats(const tp::Points& x) {
  std::vector<float> out(x.size());
  for (Eigen::Index i = 0; i < x.size(); ++i) out[i] = float(x.data()[i]);
  return out;
}

// Three unit right triangles stacked at z = 0, 1, 2 and one beside them at x ∈ [5, 6].
struct Stack {
  std::vector<std::uint32_t> tris = {0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11};
  std::vector<float> pos = {0, 0, 0, 1, 0, 0, 0, 1, 0,  //
                            0, 0, 1, 1, 0, 1, 0, 1, 1,  //
                            0, 0, 2, 1, 0, 2, 0, 1, 2,  //
                            5, 0, 0, 6, 0, 0, 5, 1, 0};
};

Ray down(double x, double y) {
  return {Eigen::Vector3d(x, y, 10), Eigen::Vector3d(0, 0, -1)};
}

std::optional<Hit> bruteForce(const std::vector<std::uint32_t>& tris, const std::vector<float>& x,
                              const Ray& ray) {
  // One triangle per picker: the reference answer without the tree.
  std::optional<Hit> best;
  for (size_t t = 0; t < tris.size() / 3; ++t) {
    Picker one;
    one.build({tris[3 * t], tris[3 * t + 1], tris[3 * t + 2]}, x);
    if (auto h = one.pick(ray); h && (!best || h->distance < best->distance)) {
      best = h;
      best->triangle = int(t);
    }
  }
  return best;
}

}  // namespace

class PickingTest : public QObject {
  Q_OBJECT

 private slots:
  void rayThroughATriangleHitsIt() {
    Stack s;
    Picker p;
    p.build(s.tris, s.pos);
    const auto h = p.pick(down(5.25, 0.25));
    QVERIFY(h);
    QCOMPARE(h->triangle, 3);
    QVERIFY((h->point - Eigen::Vector3d(5.25, 0.25, 0)).norm() < 1e-9);
    QVERIFY(std::abs(h->barycentric.sum() - 1) < 1e-12);
    QVERIFY((h->barycentric - Eigen::Vector3d(0.5, 0.25, 0.25)).norm() < 1e-9);
    QVERIFY(std::abs(h->distance - 10) < 1e-9);
    QVERIFY(h->frontFacing);  // the normal is +z, the ray comes from above
  }

  void raysOutsideMiss() {
    Stack s;
    Picker p;
    p.build(s.tris, s.pos);
    QVERIFY(!p.pick(down(0.8, 0.8)));  // beyond the hypotenuse
    QVERIFY(!p.pick(down(3, 0.5)));    // between the stacks
    QVERIFY(!p.pick({Eigen::Vector3d(0.2, 0.2, -5), Eigen::Vector3d(0, 0, -1)}));  // pointing away
  }

  void theNearestHitIsChosen() {
    Stack s;
    Picker p;
    p.build(s.tris, s.pos);
    QCOMPARE(p.pick(down(0.2, 0.2))->triangle, 2);  // from above: z = 2
    const Ray up{Eigen::Vector3d(0.2, 0.2, -10), Eigen::Vector3d(0, 0, 1)};
    QCOMPARE(p.pick(up)->triangle, 0);  // from below: z = 0
    QVERIFY(!p.pick(up)->frontFacing);
  }

  void filterAndSectionPlaneAreHonoured() {
    Stack s;
    Picker p;
    p.build(s.tris, s.pos);
    QCOMPARE(p.pick(down(0.2, 0.2), [](int t) { return t != 2; })->triangle, 1);
    ClipPlane keepBelow{Eigen::Vector3d(0, 0, -1), 1.5};  // keeps z ≤ 1.5
    QCOMPARE(p.pick(down(0.2, 0.2), {}, keepBelow)->triangle, 1);
  }

  void refitFollowsMovedVertices() {
    Stack s;
    Picker p;
    p.build(s.tris, s.pos);
    for (size_t i = 0; i < s.pos.size(); i += 3) s.pos[i] += 100;  // everything moves in x
    p.update(s.pos);
    QVERIFY(!p.pick(down(0.2, 0.2)));
    QCOMPARE(p.pick(down(100.2, 0.2))->triangle, 2);
  }

  void treeAgreesWithBruteForceOnATissue() {
    const tp::CellComplex cc = tp::boxTissue(3, 2, 2, 5.0);
    const auto g = makeTissueGeometry(cc, 1, "box", 5.0);
    const auto x = floats(cc.rest);
    Picker p;
    p.build(g->triangles, x);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> u(-5, 20);
    int hits = 0;
    for (int i = 0; i < 300; ++i) {
      const Eigen::Vector3d from(u(rng), u(rng), 40);
      const Eigen::Vector3d to(u(rng), u(rng), u(rng) * 0.5);
      const Ray ray{from, (to - from).normalized()};
      const auto a = p.pick(ray), b = bruteForce(g->triangles, x, ray);
      QCOMPARE(bool(a), bool(b));
      if (a) {
        ++hits;
        QVERIFY(std::abs(a->distance - b->distance) < 1e-9);
      }
    }
    QVERIFY(hits > 50);
  }

  void hoverNamesTheCellOnTheViewersSide() {
    // Two cubic cells side by side in x: the wall between them at x = 5.
    const tp::CellComplex cc = tp::boxTissue(2, 1, 1, 5.0);
    const auto g = makeTissueGeometry(cc, 1, "box", 5.0);
    Picker p;
    p.build(g->triangles, floats(cc.rest));
    // From above: an outer triangle of the cell under it.
    const auto top = p.pick(down(2.0, 3.1));
    QVERIFY(top && g->outer[top->triangle]);
    const int left = cellUnderCursor(*g, *top);
    const auto top2 = p.pick(down(7.1, 1.3));
    const int right = cellUnderCursor(*g, *top2);
    QVERIFY(left >= 0 && right >= 0 && left != right);
    // Through the section (only the inner wall is accepted): seen from the left, the left cell.
    auto inner = [&](int t) { return !g->outer[t]; };
    const auto fromLeft = p.pick({Eigen::Vector3d(2, 1.3, 3.1), Eigen::Vector3d(1, 0, 0)}, inner);
    QVERIFY(fromLeft);
    QCOMPARE(cellUnderCursor(*g, *fromLeft), left);
    const auto fromRight = p.pick({Eigen::Vector3d(8, 1.3, 3.1), Eigen::Vector3d(-1, 0, 0)}, inner);
    QCOMPARE(cellUnderCursor(*g, *fromRight), right);
  }

  void pickingTheDefaultMeristemIsFast() {
    const tp::CellComplex cc = tp::readPly(tp::defaultTissuePath());
    const auto g = makeTissueGeometry(cc, 1, "default", 0);
    const auto x = floats(cc.rest);
    QElapsedTimer timer;
    timer.start();
    Picker p;
    p.build(g->triangles, x);
    const double buildMs = timer.nsecsElapsed() / 1e6;
    timer.restart();
    p.update(x);
    const double refitMs = timer.nsecsElapsed() / 1e6;
    std::mt19937 rng(3);
    std::uniform_real_distribution<double> u(-45, 45);
    int hits = 0;
    timer.restart();
    const int n = 2000;
    for (int i = 0; i < n; ++i) {
      const Ray ray{Eigen::Vector3d(u(rng), u(rng), 100),
                    Eigen::Vector3d(0.1, -0.05, -1).normalized()};
      hits += bool(p.pick(ray));
    }
    const double pickMs = timer.nsecsElapsed() / 1e6 / n;
    qInfo("default meristem (%d triangles): build %.2f ms, refit %.2f ms, %.4f ms per pick",
          g->triangleCount(), buildMs, refitMs, pickMs);
    QVERIFY(hits > n / 4);
    QVERIFY2(pickMs < 5.0, "picking must stay well under a frame");
    QVERIFY(refitMs < 20.0);
  }
};

TP_GUI_TEST(PickingTest)
#include "test_picking.moc"
