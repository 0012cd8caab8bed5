// Preparation without the worker: the material point moved between states, refinement around
// the site, and errors for impossible parameters.
#include <QTest>

#include "Preparation.h"
#include "Snapshot.h"
#include "TestMain.h"
#include "tissue/Shapes.h"

using namespace tp::gui;

class PreparationTest : public QObject {
  Q_OBJECT

 private slots:
  void transferKeepsBarycentricCoordinates() {
    const tp::CellComplex cc = tp::boxTissue(1, 1, 1, 5.0);
    tp::Points moved = cc.rest;
    moved.row(2) *= 2.0;  // stretch in z
    moved.row(0).array() += 1.0;
    for (int t = 0; t < cc.triangleCount(); ++t) {
      const auto& tri = cc.triangles[t];
      const Eigen::Vector3d w(0.2, 0.3, 0.5);
      const Eigen::Vector3d p =
          w[0] * cc.rest.col(tri[0]) + w[1] * cc.rest.col(tri[1]) + w[2] * cc.rest.col(tri[2]);
      const Eigen::Vector3d expected =
          w[0] * moved.col(tri[0]) + w[1] * moved.col(tri[1]) + w[2] * moved.col(tri[2]);
      QVERIFY((transferPoint(cc, t, cc.rest, moved, p) - expected).norm() < 1e-12);
    }
  }

  void refinedAroundTheSite() {
    auto base = std::make_shared<const tp::CellComplex>(tp::boxTissue(3, 3, 2, 5.0));
    PreparationRequest r;
    r.params.youngModulus = 50;
    r.params.pressure = 0.2;
    r.params.refineLevel = 1;
    r.site = Eigen::Vector3d(2.0, 2.0, 12.0);
    std::vector<std::string> said;
    const PreparedIndentation p = prepareIndentation(
        base, meanCellSize(*base), r, [&](const std::string& s) { said.push_back(s); });
    QVERIFY(p.indentation && p.indentation->prepared());
    QVERIFY(p.complex != base);
    QVERIFY(p.complex->triangleCount() > base->triangleCount());
    QCOMPARE(&p.indentation->model(), p.model.get());
    const Eigen::Vector3d site = p.indentation->placement().site;
    QVERIFY(std::abs(site.x() - 2.0) < 0.2 && std::abs(site.y() - 2.0) < 0.2);
    QVERIFY(said.size() >= 3);  // find the site, refine, solve
  }

  void impossibleParametersAreRefused() {
    auto base = std::make_shared<const tp::CellComplex>(tp::boxTissue(1, 1, 1, 5.0));
    PreparationRequest r;
    r.params.poissonRatio = 0.7;
    QVERIFY_THROWS_EXCEPTION(std::invalid_argument, prepareIndentation(base, 5.0, r));
  }
};

TP_GUI_TEST(PreparationTest)
#include "test_preparation.moc"
