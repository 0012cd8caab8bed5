// The force-depth plot: a curve's unloading branch is drawn apart from its loading branch
// (dotted, from the deepest loading point, no second legend entry), and each curve keeps its
// colour when another is removed; the legend sits in a corner the curves leave free.
#include <QListWidget>
#include <QTest>
#include <cmath>

#include <qcustomplot.h>

#include "PlotPanel.h"
#include "TestMain.h"

using namespace tp::gui;

namespace {

NamedCurve curve(const char* name, int colour, bool unload) {
  NamedCurve c;
  c.name = name;
  c.colour = colour;
  for (double d : {0.0, 0.1, 0.2, 0.3}) c.points.push_back(tp::CurvePoint{d, 10 * d, 1, 0.0, true, false});
  if (unload)
    for (double d : {0.2, 0.1, 0.0}) c.points.push_back(tp::CurvePoint{d, 5 * d, 1, 0.0, true, true});
  return c;
}

}  // namespace

class PlotTest : public QObject {
  Q_OBJECT

 private slots:
  void unloadingIsItsOwnDottedBranch() {
    PlotPanel panel;
    panel.setCurves({curve("a", 0, true)}, 5.0);
    QCustomPlot* plot = panel.plot();
    QCOMPARE(plot->graphCount(), 2);
    QCOMPARE(plot->legend->itemCount(), 1);
    QCOMPARE(plot->graph(0)->data()->size(), 4);
    QCOMPARE(plot->graph(1)->data()->size(), 4);  // from the deepest loading point, then three
    QCOMPARE(plot->graph(1)->pen().style(), Qt::DotLine);
    QCOMPARE(plot->graph(1)->pen().color(), plot->graph(0)->pen().color());
    // Unloading at 0.1 µm reads 0.5 µN, loading 1 µN: not merged into one curve by depth.
    const auto it = plot->graph(1)->data()->findBegin(0.1, false);
    QCOMPARE(it->key, 0.1);
    QCOMPARE(it->value, 0.5);
  }

  void legendEntriesAreShortAndTheListKeepsTheSite() {
    PlotPanel panel;
    NamedCurve c = curve("a", 0, false);
    c.name = "site 2 (13.8, -29.8, 32.3) µm · E 100 MPa, p 0.8 MPa, r 1 µm · drag";
    panel.setCurves({c}, 5.0);
    QCOMPARE(panel.plot()->graph(0)->name(),
             QString("site 2 · E 100 MPa, p 0.8 MPa, r 1 µm · drag · error not estimated"));
    auto* list = panel.findChild<QListWidget*>("curveList");
    QVERIFY(list);
    QVERIFY(list->item(0)->text().startsWith("site 2 (13.8, -29.8, 32.3) µm"));
    QCOMPARE(list->textElideMode(), Qt::ElideRight);
  }

  // A rising curve leaves the top left free; one that rises at once and levels off fills the
  // top of the axes, and the legend goes to the bottom right, where it hides no point.
  void theLegendGoesWhereTheCurvesLeaveRoom() {
    PlotPanel panel;
    panel.resize(900, 420);
    QCustomPlot* plot = panel.plot();
    auto corner = [&] {
      plot->replot(QCustomPlot::rpImmediateRefresh);  // lays the axes out; the legend follows
      QCPLayoutInset* inset = plot->axisRect()->insetLayout();
      return inset->insetAlignment(inset->elements(false).indexOf(plot->legend));
    };
    panel.setCurves({curve("rising", 0, false)}, 5.0);
    QCOMPARE(corner(), Qt::AlignTop | Qt::AlignLeft);
    NamedCurve level = curve("levels off", 1, false);
    level.points.clear();
    for (int k = 0; k <= 60; ++k) {
      const double d = 0.005 * k;
      level.points.push_back(tp::CurvePoint{d, 3 * (1 - std::exp(-d / 0.01)), 1, 0.0, true, false});
    }
    panel.setCurves({level}, 5.0);
    QCOMPARE(corner(), Qt::AlignBottom | Qt::AlignRight);
    // Back to the rising curve alone: back to the top left.
    panel.setCurves({curve("rising", 0, false)}, 5.0);
    QCOMPARE(corner(), Qt::AlignTop | Qt::AlignLeft);
  }

  void coloursFollowTheCurveNotItsPlace() {
    PlotPanel panel;
    panel.setCurves({curve("a", 0, false), curve("b", 1, false), curve("c", 2, false)}, 5.0);
    const QColor third = panel.plot()->graph(2)->pen().color();
    panel.setCurves({curve("a", 0, false), curve("c", 2, false)}, 5.0);  // b removed
    QCOMPARE(panel.curveCount(), 2);
    QCOMPARE(panel.plot()->graph(1)->pen().color(), third);
  }
};

TP_GUI_TEST(PlotTest)
#include "test_plot.moc"
