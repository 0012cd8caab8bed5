// Colour maps: end colours, clamping, NaN, luminance (monotone for viridis, peaked for the
// diverging map) and tick values.
#include <QTest>

#include <cmath>

#include "ColorMap.h"
#include "TestMain.h"

using namespace tp::gui;

namespace {

bool near(const Eigen::Vector3f& a, const Eigen::Vector3f& b) {
  return (a - b).norm() < 1e-5f;
}
Eigen::Vector3f rgb(int r, int g, int b) {
  return Eigen::Vector3f(r, g, b) / 255.0f;
}

bool niceStep(double step) {
  const double m = step / std::pow(10.0, std::floor(std::log10(step) + 1e-12));
  for (double n : {1.0, 2.0, 5.0, 10.0})
    if (std::abs(m - n) < 1e-9) return true;
  return false;
}

}  // namespace

class ColorMapTest : public QObject {
  Q_OBJECT

 private slots:
  void endColours() {
    ColorMap v(ColorMap::Kind::Viridis);
    v.setRange(2, 4);
    QVERIFY(near(v.color(2), rgb(68, 1, 84)));     // viridis' dark purple
    QVERIFY(near(v.color(4), rgb(253, 231, 37)));  // viridis' yellow
    QVERIFY(near(v.color(-100), v.color(2)));      // clamped below
    QVERIFY(near(v.color(100), v.color(4)));       // and above
    QVERIFY(near(v.color(std::nan("")), Eigen::Vector3f::Constant(0.5f)));
    ColorMap d(ColorMap::Kind::CoolWarm);
    d.setRange(-1, 1);
    QVERIFY(near(d.color(-1), rgb(59, 76, 192)));
    QVERIFY(near(d.color(1), rgb(180, 4, 38)));
    const Eigen::Vector3f mid = d.color(0);
    QVERIFY(std::abs(mid.x() - mid.y()) < 1e-6 && std::abs(mid.y() - mid.z()) < 1e-6);  // grey
  }

  void viridisLuminanceRises() {
    ColorMap v(ColorMap::Kind::Viridis);
    double last = -1;
    for (int i = 0; i <= 512; ++i) {
      const double l = relativeLuminance(v.colorAt(i / 512.0));
      QVERIFY2(l > last, qPrintable(QString("luminance falls at t = %1").arg(i / 512.0)));
      last = l;
    }
  }

  void divergingLuminancePeaksInTheMiddle() {
    ColorMap d(ColorMap::Kind::CoolWarm);
    const double mid = relativeLuminance(d.colorAt(0.5));
    for (double t : {0.0, 0.1, 0.3, 0.45, 0.55, 0.7, 0.9, 1.0})
      QVERIFY(relativeLuminance(d.colorAt(t)) < mid);
  }

  void emptyRangeIsWidened() {
    ColorMap v;
    v.setRange(0, 0);
    QVERIFY(v.hi() > v.lo());
    v.setRange(5, 5);
    QVERIFY(v.hi() > 5 && v.lo() == 5);
    QVERIFY(near(v.color(5), v.colorAt(0)));
  }

  void ticks_data() {
    QTest::addColumn<double>("lo");
    QTest::addColumn<double>("hi");
    QTest::addColumn<int>("maxTicks");
    QTest::addColumn<QVector<double>>("expected");
    QTest::newRow("0..1") << 0.0 << 1.0 << 6 << QVector<double>{0, 0.2, 0.4, 0.6, 0.8, 1.0};
    QTest::newRow("0..1.2") << 0.0 << 1.2 << 6 << QVector<double>{0, 0.5, 1.0};
    QTest::newRow("0..7.3") << 0.0 << 7.3 << 6 << QVector<double>{0, 2, 4, 6};
    QTest::newRow("-3..3") << -3.0 << 3.0 << 6 << QVector<double>{-2, 0, 2};
    QTest::newRow("12.3..12.9") << 12.3 << 12.9 << 7
                                << QVector<double>{12.3, 12.4, 12.5, 12.6, 12.7, 12.8, 12.9};
    QTest::newRow("MPa") << 0.013 << 27.4 << 6 << QVector<double>{5, 10, 15, 20, 25};
  }
  void ticks() {
    QFETCH(double, lo);
    QFETCH(double, hi);
    QFETCH(int, maxTicks);
    QFETCH(QVector<double>, expected);
    ColorMap m;
    m.setRange(lo, hi);
    const std::vector<double> t = m.ticks(maxTicks);
    QVERIFY(niceStep(m.tickStep(maxTicks)));
    QVERIFY(int(t.size()) <= maxTicks);
    for (double v : t) QVERIFY(v >= lo - 1e-9 && v <= hi + 1e-9);
    QCOMPARE(int(t.size()), int(expected.size()));
    for (int i = 0; i < expected.size(); ++i)
      QVERIFY2(std::abs(t[i] - expected[i]) < 1e-9,
               qPrintable(QString("tick %1: %2 instead of %3").arg(i).arg(t[i]).arg(expected[i])));
  }

  void tickLabels() {
    QCOMPARE(ColorMap::formatTick(0.25, 0.05), std::string("0.25"));
    QCOMPARE(ColorMap::formatTick(0.2, 0.2), std::string("0.2"));
    QCOMPARE(ColorMap::formatTick(12, 5), std::string("12"));
    QCOMPARE(ColorMap::formatTick(0, 0.5), std::string("0.0"));
    QCOMPARE(ColorMap::formatTick(2.5e-5, 5e-6), std::string("2.5e-05"));
  }
};

TP_GUI_TEST(ColorMapTest)
#include "test_colormap.moc"
