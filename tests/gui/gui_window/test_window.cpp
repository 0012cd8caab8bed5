// The real window with OpenGL (run under a virtual X server): a small generated meristem is
// loaded, a site is clicked where the top of the tissue projects, the probe is dragged in with
// synthetic mouse events, curves are run and cancelled with the keyboard, files are exported and
// read back, a session is saved and reopened, a bad file is refused with a message, and a
// screenshot of the whole window is written and checked for content.
#include <QAction>
#include <QApplication>
#include <QCheckBox>
#include <QComboBox>
#include <QDir>
#include <QDockWidget>
#include <QDoubleSpinBox>
#include <QElapsedTimer>
#include <QFile>
#include <QLabel>
#include <QListWidget>
#include <QMenuBar>
#include <QMessageBox>
#include <QMimeData>
#include <QProgressBar>
#include <QPushButton>
#include <QRegularExpression>
#include <QScreen>
#include <QSet>
#include <QSettings>
#include <QSignalSpy>
#include <QTemporaryDir>
#include <QTest>
#include <QTextBrowser>
#include <QTimer>

#include <qcustomplot.h>
#include <omp.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <tuple>

#include "Autosave.h"
#include "ContactPointDialog.h"
#include "DisplayPanel.h"
#include "FileActions.h"
#include "MainWindow.h"
#include "MapPanel.h"
#include "MapRunner.h"
#include "ParameterPanel.h"
#include "PlotPanel.h"
#include "RecentFiles.h"
#include "SessionFile.h"
#include "SimulationController.h"
#include "TestMain.h"
#include "TissueView.h"
#include "experiment/Experiment.h"
#include "experiment/Fit.h"
#include "experiment/Quantities.h"
#include "io/CurveCsv.h"
#include "io/JpkCurve.h"
#include "io/TextFile.h"
#include "io/TissueFiles.h"
#include "io/Paths.h"
#include "io/Ply.h"
#include "tissue/Meristem.h"

using namespace tp::gui;

namespace {

int distinctColours(const QImage& image) {
  QSet<QRgb> colours;
  const QImage img = image.convertToFormat(QImage::Format_RGB32);
  for (int y = 0; y < img.height(); y += 2)
    for (int x = 0; x < img.width(); x += 2) colours.insert(img.pixel(x, y));
  return colours.size();
}

// The fraction of pixels whose colour differs by more than `threshold` (sum of the three
// channels' differences, 0–765): 0 counts any difference.
double changedFraction(const QImage& a, const QImage& b, int threshold = 0) {
  if (a.size() != b.size()) return 1.0;
  const QImage x = a.convertToFormat(QImage::Format_RGB32),
               y = b.convertToFormat(QImage::Format_RGB32);
  long changed = 0;
  for (int r = 0; r < x.height(); ++r)
    for (int c = 0; c < x.width(); ++c) {
      const QRgb p = x.pixel(c, r), q = y.pixel(c, r);
      changed += std::abs(qRed(p) - qRed(q)) + std::abs(qGreen(p) - qGreen(q)) +
                     std::abs(qBlue(p) - qBlue(q)) >
                 threshold;
    }
  return double(changed) / (double(x.width()) * x.height());
}

void sendMouse(QWidget* w, QEvent::Type type, const QPoint& p, Qt::MouseButton button,
               Qt::MouseButtons buttons, Qt::KeyboardModifiers mods = {}) {
  QMouseEvent e(type, QPointF(p), QPointF(w->mapToGlobal(p)), button, buttons, mods);
  QApplication::sendEvent(w, &e);
}

// The highest point of the free outer surface: the centroid of the highest outer triangle.
Eigen::Vector3d topOfTissue(const Snapshot& s) {
  const TissueGeometry& g = *s.geometry;
  Eigen::Vector3d best(0, 0, -1e300);
  for (int t = 0; t < g.triangleCount(); ++t) {
    if (!g.outer[t] || g.clampedTriangle[t]) continue;
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      const auto v = g.triangles[3 * t + k];
      c += Eigen::Vector3d(s.positions[3 * v], s.positions[3 * v + 1], s.positions[3 * v + 2]) / 3;
    }
    if (c.z() > best.z()) best = c;
  }
  return best;
}

QPoint pixelOf(TissueView* view, const Eigen::Vector3d& world) {
  Camera cam = view->camera();
  cam.setViewport(view->width(), view->height());
  const Eigen::Vector3d p = cam.project(world);
  return QPoint(int(p.x()), int(p.y()));
}

QString buildDir() {
  const QByteArray d = qgetenv("TP_BUILD_DIR");
  return d.isEmpty() ? QDir::currentPath() : QString::fromUtf8(d);
}

}  // namespace

class WindowTest : public QObject {
  Q_OBJECT

  QTemporaryDir dir_;
  QString tissue_;
  std::unique_ptr<MainWindow> w_;
  SimulationController* c_ = nullptr;
  TissueView* view_ = nullptr;

  void waitIdle(int ms = 120000) {
    QTRY_VERIFY_WITH_TIMEOUT(c_->idle(), ms);
    QTest::qWait(50);  // let the last snapshot reach the view
  }

  // Every measured curve removed (a fit fits them all).
  void removeMeasuredCurves() {
    for (int i = int(c_->curves().size()) - 1; i >= 0; --i)
      if (c_->curves()[i].measured) c_->removeCurve(i);
  }

  // A curve simulated at the current site on mesh level `level` at E (MPa) and p (MPa), to
  // `depth` µm in `steps` steps, added again as a measured curve named `name`; the parameters
  // are left at those values (the fixed level).
  NamedCurve addSimulatedAsMeasured(int level, double E, double p, double depth, int steps,
                                    const std::string& name) {
    SimulationParams params = c_->params();
    params.autoMesh = false;
    params.meshLevel = level;
    params.youngModulus = E;
    params.pressure = p;
    c_->setParams(params);
    waitIdle();
    Schedule s;
    s.maxDepth = depth;
    s.steps = steps;
    c_->setSchedule(s);
    c_->runCurve();
    waitIdle();
    NamedCurve measured = c_->curves().back();
    measured.name = name;
    c_->addMeasuredCurve(measured);
    return measured;
  }

 private slots:
  void initTestCase() {
    // A small meristem: 60 cells in a dome of radius 15 µm.
    tp::MeristemParams prm;
    prm.cells = 60;
    prm.shape.radius = 15;
    prm.shape.capHeight = 13;
    prm.shape.stemHeight = 4;
    prm.l1Thickness = 3.5;
    prm.l2Thickness = 4;
    tissue_ = dir_.path() + "/small.ply";
    tp::writePly(tissue_.toStdString(), tp::generateMeristem(prm));

    w_ = std::make_unique<MainWindow>();
    // With no geometry saved yet the window fits the screen (1280×800 here) with room for a
    // title bar, so the status bar, which carries the curve's error, is on it.
    const QRect screen = w_->screen()->availableGeometry();
    QVERIFY2(w_->height() <= screen.height() - 48 && w_->width() <= screen.width(),
             qPrintable(QString("window %1×%2 on a screen of %3×%4")
                            .arg(w_->width())
                            .arg(w_->height())
                            .arg(screen.width())
                            .arg(screen.height())));
    w_->resize(1280, 800);
    w_->show();
    QVERIFY(QTest::qWaitForWindowExposed(w_.get()));
    w_->activateWindow();  // shortcuts (Space, Esc) need the active window
    QVERIFY(QTest::qWaitForWindowActive(w_.get()));
    c_ = w_->controller();
    view_ = w_->view();
    QSignalSpy loaded(c_, &SimulationController::tissueLoaded);
    w_->fileActions()->openTissue(tissue_);
    QTRY_VERIFY_WITH_TIMEOUT(c_->prepared(), 120000);
    waitIdle();
    QCOMPARE(loaded.count(), 1);
    QVERIFY(w_->windowTitle().contains("small.ply"));
    QVERIFY(view_->frameCount() > 0);
  }

  void hoverNamesTheCell() {
    const QPoint p = pixelOf(view_, topOfTissue(c_->latest()));
    sendMouse(view_, QEvent::MouseMove, p, Qt::NoButton, Qt::NoButton);
    QVERIFY(view_->highlightedCell() >= 0);
    QSignalSpy text(view_, &TissueView::hoverChanged);
    sendMouse(view_, QEvent::MouseMove, QPoint(2, 2), Qt::NoButton, Qt::NoButton);  // background
    QCOMPARE(view_->highlightedCell(), -1);
    sendMouse(view_, QEvent::MouseMove, p, Qt::NoButton, Qt::NoButton);
    QCOMPARE(text.count(), 2);
    QVERIFY2(text.last().first().toString().startsWith("Cell "),
             qPrintable(text.last().first().toString()));
    QVERIFY(text.last().first().toString().contains("µm³"));
  }

  void clickChoosesTheSite() {
    const Eigen::Vector3d top = topOfTissue(c_->latest());
    const QPoint p = pixelOf(view_, top);
    const auto hit = view_->pickAt(p);
    QVERIFY(hit);
    QVERIFY((hit->point - top).norm() < 1.0);  // the pixel shows the top
    const int preparation = c_->latest().preparation;
    const double distance = view_->cameraPose().distance;
    QTest::mouseClick(view_, Qt::LeftButton, {}, p);
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().preparation > preparation, 120000);
    waitIdle();
    const Snapshot& s = c_->latest();
    // View ▸ Frame a picked site (on by default): the camera looks at the probe from close by.
    QVERIFY(w_->findChild<QAction*>("frameSiteAction")->isChecked());
    QVERIFY2((view_->cameraPose().target - s.probeCenter()).norm() < 2.0,
             qPrintable(QString("target %1 µm from the probe")
                            .arg((view_->cameraPose().target - s.probeCenter()).norm())));
    QVERIFY2(view_->cameraPose().distance < 0.75 * distance,  // three cells across, not 15
             qPrintable(QString("distance %1 → %2 µm").arg(distance).arg(view_->cameraPose().distance)));
    view_->resetView();
    QVERIFY2((s.site - top).norm() < 1.0,
             qPrintable(QString("site %1 µm from the click").arg((s.site - top).norm())));
    QVERIFY(s.probeVisible);
    QVERIFY(s.axis.z() < -0.5);  // inward at the top: downwards
    // The probe touches the surface: its centre one radius out along the normal.
    QVERIFY(std::abs((s.contactCenter - s.site).norm() - s.probeRadius) < 0.05);
    QCOMPARE(s.depth, 0.0);
    QCOMPARE(int(c_->session().sites.size()), 2);  // the default (top) site and this one
  }

  void dragPushesTheProbeIn() {
    QCoreApplication::processEvents();
    const QImage before = view_->grabFramebuffer();
    const int curves = int(c_->curves().size());
    const int frames = view_->frameCount();
    // Right button, 60 pixels down = 0.6 probe radii = 0.6 µm, in 12 moves.
    const QPoint start = view_->rect().center();
    sendMouse(view_, QEvent::MouseButtonPress, start, Qt::RightButton, Qt::RightButton);
    for (int i = 1; i <= 12; ++i) {
      sendMouse(view_, QEvent::MouseMove, start + QPoint(0, 5 * i), Qt::NoButton, Qt::RightButton);
      // The probe's target follows the mouse at once, ahead of the equilibria.
      QVERIFY(std::abs(view_->targetDepth() - 0.05 * i) < 1e-9);
      QTest::qWait(40);
    }
    sendMouse(view_, QEvent::MouseButtonRelease, start + QPoint(0, 60), Qt::RightButton,
              Qt::NoButton);
    QVERIFY(std::abs(w_->parameterPanel()->depth() - 0.6) < 1e-9);
    QTRY_VERIFY_WITH_TIMEOUT(std::abs(c_->latest().depth - 0.6) < 1e-9, 120000);
    waitIdle();
    QCOMPARE(view_->targetDepth(), -1.0);  // reached
    QVERIFY(view_->frameCount() > frames);
    const Snapshot& s = c_->latest();
    QVERIFY2(s.force > 0, qPrintable(QString("force %1 µN").arg(s.force)));
    // The force rises along the live curve.
    QCOMPARE(int(c_->curves().size()), curves + 1);
    auto pts = c_->curves().back().points;
    QVERIFY(pts.size() >= 2);
    std::sort(pts.begin(), pts.end(), [](auto& a, auto& b) { return a.depth < b.depth; });
    for (size_t i = 1; i < pts.size(); ++i) QVERIFY(pts[i].force > pts[i - 1].force);
    // The plot has the points, the picture has changed.
    QCustomPlot* plot = w_->plotPanel()->plot();
    QVERIFY(plot->graphCount() >= 1);
    QCOMPARE(plot->graph(plot->graphCount() - 1)->data()->size(), int(pts.size()));
    const QImage after = view_->grabFramebuffer();
    const double changed = changedFraction(before, after);
    qInfo("drag: depth %.3f µm, force %.4g µN, %.1f %% of the view's pixels changed", s.depth,
          s.force, 100 * changed);
    QVERIFY(changed > 0.002);
    // The contact patch: outer triangles, each closer to the probe's centre than its radius,
    // outlined in the patch's colour on screen.
    QVERIFY(!s.contactTriangles.empty());
    const auto& g = *s.geometry;
    for (int t : s.contactTriangles) {
      QVERIFY(g.outer[t]);
      double nearest = 1e9;  // a vertex of a pressed triangle lies within a triangle's size
      for (int k = 0; k < 3; ++k) {
        const int v = int(g.triangles[3 * t + k]);
        nearest = std::min(nearest, (Eigen::Vector3d(s.positions[3 * v], s.positions[3 * v + 1],
                                                     s.positions[3 * v + 2]) -
                                     s.probeCenter())
                                        .norm());
      }
      QVERIFY2(nearest < s.probeRadius + 2.0, qPrintable(QString::number(nearest)));
    }
    // Seen as Z shows the probe (40° off its axis; from afar the patch is edge-on at the top).
    view_->setFocus();
    QTest::keyClick(view_, Qt::Key_Z);
    const QImage close = view_->grabFramebuffer();
    QTest::keyClick(view_, Qt::Key_R);  // the whole tissue again, as it was
    int patchPixels = 0;
    for (int y = 0; y < close.height(); ++y)
      for (int x = 0; x < close.width(); ++x) {
        const QColor p = close.pixelColor(x, y);
        patchPixels += p.red() > 200 && p.green() < 90 && p.blue() > 150;
      }
    qInfo("contact patch: %d triangles, %d pixels drawn in its colour",
          int(s.contactTriangles.size()), patchPixels);
    QVERIFY(patchPixels >= 10);
  }

  void screenshotOfTheWindow() {
    QCoreApplication::processEvents();
    const QImage shot = grabWindowWithView(w_.get(), view_);
    const QString path = buildDir() + "/gui_screenshot.png";
    QVERIFY(shot.save(path));
    qInfo("window screenshot: %s (%dx%d, %d colours)", qPrintable(path), shot.width(),
          shot.height(), distinctColours(shot));
    QVERIFY(distinctColours(shot) > 200);
    // The 3D view's region of the window shot is drawn (not one flat colour).
    const QRect region(view_->mapTo(w_.get(), QPoint(0, 0)), view_->size());
    const QImage gl = shot.copy(region);
    QVERIFY2(distinctColours(gl) > 100, "the GL region of the window grab is (nearly) uniform");
    // A screenshot of the view at twice its size.
    QString error;
    const QString png = dir_.path() + "/view.png";
    const QSize size = view_->size() * 2;
    QVERIFY2(w_->fileActions()->exportScreenshot(png, size, &error), qPrintable(error));
    const QImage big(png);
    QCOMPARE(big.size(), size);
    QVERIFY(distinctColours(big) > 100);
  }

  void displayControlsChangeThePicture() {
    const QImage plain = view_->grabFramebuffer();
    w_->displayPanel()->setSectionEnabled(true);
    QVERIFY(view_->clipPlane().has_value());
    const QImage cut = view_->grabFramebuffer();
    QVERIFY(changedFraction(plain, cut) > 0.01);
    w_->displayPanel()->setSectionEnabled(false);
    view_->setField(Field::Displacement);
    QVERIFY(changedFraction(plain, view_->grabFramebuffer()) > 0.01);
    view_->setField(Field::VonMises);
    // Principal directions: a line on every outer triangle of the turgid (stressed) tissue.
    QVERIFY(!c_->latest().principalAxes.empty());
    auto* glyphs = w_->displayPanel()->findChild<QCheckBox*>("glyphsCheckBox");
    QVERIFY(glyphs);
    glyphs->setChecked(true);
    QVERIFY(view_->glyphsVisible());
    QVERIFY(w_->displayPanel()->settings().glyphs);
    QVERIFY(changedFraction(plain, view_->grabFramebuffer()) > 0.01);
    glyphs->setChecked(false);
    QVERIFY(changedFraction(plain, view_->grabFramebuffer()) < 0.001);
  }

  void deformationScaleMagnifiesTheDimple() {
    c_->requestDepth(0.5);
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().depth == 0.5 && !c_->busy(), 60000);
    const Snapshot truth = view_->snapshot();
    QVERIFY(truth.turgidPositions.size() == truth.positions.size());
    const QImage plain = view_->grabFramebuffer();
    auto* scale = w_->displayPanel()->findChild<QDoubleSpinBox*>("deformationScale");
    QVERIFY(scale);
    scale->setValue(20);
    QCOMPARE(view_->deformationScale(), 20.0);
    const Snapshot& shown = view_->shownSnapshot();
    // The vertex that moved most: drawn at turgid + 20 × its displacement.
    size_t most = 0;
    double moved = 0;
    for (size_t i = 0; i < truth.positions.size(); ++i) {
      const double d = std::abs(truth.positions[i] - truth.turgidPositions[i]);
      if (d > moved) moved = d, most = i;
    }
    QVERIFY(moved > 0.1);
    QVERIFY(std::abs(shown.positions[most] -
                     (truth.turgidPositions[most] + 20 * (truth.positions[most] - truth.turgidPositions[most]))) < 1e-3);
    QVERIFY((shown.probeCenter() - truth.contactCenter - 20 * 0.5 * truth.axis).norm() < 1e-9);
    QCOMPARE(view_->snapshot().depth, 0.5);  // numbers stay true
    QCOMPARE(view_->snapshot().force, truth.force);
    QVERIFY(changedFraction(plain, view_->grabFramebuffer()) > 0.001);
    scale->setValue(1);
    QCOMPARE(view_->shownSnapshot().positions, view_->snapshot().positions);

    // The proof: a 1 µm push drawn ×20 changes at least 5 % of the pixels in a box
    // around the site (120 px square; the view is 400–500 px) against the turgid state at ×20,
    // each clearly (by more than 60 of 765 summed over the channels: the stress colours shift a
    // little everywhere near the probe, which is not the dimple).
    scale->setValue(20);
    c_->requestDepth(0.0);
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().depth == 0.0 && !c_->busy(), 60000);
    const Eigen::Vector3d at = view_->camera().project(c_->latest().site);
    const QRect box(int(at.x()) - 60, int(at.y()) - 60, 120, 120);
    QVERIFY(view_->rect().contains(box));
    const QImage flat = view_->grabFramebuffer().copy(box);
    c_->requestDepth(1.0);
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().depth == 1.0 && !c_->busy(), 60000);
    const double dimple = changedFraction(flat, view_->grabFramebuffer().copy(box), 60);
    qInfo("1 µm ×20: %.1f %% of the box around the site changed", 100 * dimple);
    QVERIFY(dimple >= 0.05);
    // Drawn as it is (×1), the same push changes far less of the box (4.9 % against 20.3 %
    // here): the probe and the walls move 1 µm, not 20.
    scale->setValue(1);
    const QImage pushed = view_->grabFramebuffer().copy(box);
    c_->requestDepth(0.0);
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().depth == 0.0 && !c_->busy(), 60000);
    const double plainDimple = changedFraction(view_->grabFramebuffer().copy(box), pushed, 60);
    qInfo("1 µm ×1: %.1f %% of the box changed", 100 * plainDimple);
    QVERIFY(plainDimple < 0.5 * dimple);
    c_->requestDepth(0.0);
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().depth == 0.0 && !c_->busy(), 60000);
  }

  void stressChangeFromTurgidIsShownAboutZero() {
    // Chosen in the panel: the view shows it on the diverging map, its automatic range
    // symmetric about zero; back on von Mises, viridis again.
    auto* quantity = w_->displayPanel()->findChild<QComboBox*>("quantity");
    QVERIFY(quantity);
    quantity->setCurrentIndex(quantity->findData(int(Field::VonMisesChange)));
    QCOMPARE(int(view_->field()), int(Field::VonMisesChange));
    QVERIFY(view_->colorMap().diverging());
    QCOMPARE(view_->colorMap().lo(), -view_->colorMap().hi());
    quantity->setCurrentIndex(quantity->findData(int(Field::VonMises)));
    QVERIFY(!view_->colorMap().diverging());
  }

  void manualColourRange() {
    QVERIFY(view_->autoRange());
    view_->setAutoRange(false);
    view_->setRange(1.0, 2.0);
    QCOMPARE(view_->colorMap().lo(), 1.0);
    QCOMPARE(view_->colorMap().hi(), 2.0);
    QSignalSpy range(view_, &TissueView::rangeChanged);
    view_->setRange(1.0, 2.0);  // unchanged: no signal
    QCOMPARE(range.count(), 0);
    view_->setAutoRange(true);
    QCOMPARE(range.count(), 1);
    QVERIFY(view_->colorMap().hi() > 2.0);  // back to the data (MPa under turgor)
  }

  void keysMoveTheCamera() {
    view_->setFocus();
    QTest::keyClick(view_, Qt::Key_7);
    QVERIFY((view_->camera().viewDirection() - Eigen::Vector3d(0, 0, -1)).norm() < 1e-9);
    QTest::keyClick(view_, Qt::Key_1);
    QVERIFY((view_->camera().viewDirection() - Eigen::Vector3d(0, 1, 0)).norm() < 1e-9);
    QTest::keyClick(view_, Qt::Key_3);
    QVERIFY((view_->camera().viewDirection() - Eigen::Vector3d(-1, 0, 0)).norm() < 1e-9);
    const Eigen::Vector3d eye = view_->camera().eye();
    QTest::keyClick(view_, Qt::Key_Left);
    QVERIFY((view_->camera().eye() - eye).norm() > 1e-3);
    const double d = view_->camera().distance();
    QTest::keyClick(view_, Qt::Key_Plus);
    QVERIFY(view_->camera().distance() < d);
    QTest::keyClick(view_, Qt::Key_F);
    QTest::keyClick(view_, Qt::Key_R);
    QVERIFY(std::abs(view_->camera().up().z()) > 0.5);
  }

  void keysWorkWhereverTheFocusIsButSpaceLeavesNumbersAlone() {
    // The view's keys are the window's: they work from the curve list as from the view.
    auto* list = w_->plotPanel()->findChild<QListWidget*>();
    QVERIFY(list);
    list->setFocus();
    QTest::keyClick(list, Qt::Key_7);
    QVERIFY((view_->camera().viewDirection() - Eigen::Vector3d(0, 0, -1)).norm() < 1e-9);
    QTest::keyClick(list, Qt::Key_1);
    QVERIFY((view_->camera().viewDirection() - Eigen::Vector3d(0, 1, 0)).norm() < 1e-9);
    // Space in a number box neither blanks it (it did) nor starts a run; typing still types.
    auto* box = w_->parameterPanel()->findChild<QDoubleSpinBox*>();
    QVERIFY(box);
    box->setFocus();
    const QString before = box->text();
    const double value = box->value();
    box->selectAll();  // as after Tab into the box: a space typed then replaced the whole text
    QTest::keyClick(box, Qt::Key_Space);
    QCOMPARE(box->text(), before);
    QVERIFY(!c_->running());
    box->selectAll();
    QTest::keyClick(box, Qt::Key_2);
    QVERIFY2(box->text().startsWith("2"), qPrintable(box->text()));
    box->setValue(value);
    QCOMPARE(box->text(), before);
    list->setCurrentRow(-1);  // focusing the list made its first curve the selected one
    list->clearSelection();
    view_->setFocus();
  }

  void runAndCancelCurvesFromTheKeyboard() {
    Schedule s;
    s.maxDepth = 0.3;
    s.steps = 3;
    w_->parameterPanel()->setSchedule(s);
    c_->setSchedule(s);
    const int curves = int(c_->curves().size());
    view_->setFocus();
    QTest::keyClick(view_, Qt::Key_Space);  // Run curve
    QVERIFY(c_->running());
    waitIdle();
    QCOMPARE(int(c_->curves().size()), curves + 1);
    const auto& run = c_->curves().back();
    QCOMPARE(int(run.points.size()), 4);
    for (int i = 1; i < 4; ++i) QVERIFY(run.points[i].force > run.points[i - 1].force);
    QCOMPARE(w_->plotPanel()->curveCount(), curves + 1);

    // Enough steps that the run cannot finish while the key press travels (each step of the
    // small tissue takes milliseconds): cancelled, the curve stops short and says so.
    s.steps = 2000;
    c_->setSchedule(s);
    QSignalSpy progress(c_, &SimulationController::runProgress);
    QSignalSpy messages(c_, &SimulationController::statusMessage);
    QTest::keyClick(view_, Qt::Key_Space);
    QTRY_VERIFY_WITH_TIMEOUT(progress.count() >= 1, 60000);
    QTest::keyClick(view_, Qt::Key_Escape);  // Cancel
    waitIdle();
    QVERIFY(c_->curves().back().points.size() < 1000);
    bool stopped = false;
    for (const auto& m : messages) stopped |= m.at(0).toString().contains("stopped");
    QVERIFY(stopped);
  }

  void earlierSitesAreMarkedAndTheSelectedCurvesSiteStandsOut() {
    // Two sites so far: the default (top) and the one clicked; the probe is on the second, so
    // only the first has a disc, numbered as the curves name their sites.
    const auto& sites = c_->sites();
    QCOMPARE(int(sites.size()), 2);
    QCOMPARE(c_->currentSite(), 1);
    QCOMPARE(int(view_->siteMarkers().size()), 1);
    QCOMPARE(view_->siteMarkers()[0].number, 1);
    QVERIFY(!view_->siteMarkers()[0].highlighted);
    QVERIFY(!view_->siteMarkers()[0].colour.isValid());  // no curve there
    // Selecting a curve of site 2 marks site 2 (in the curve's colour) and thickens its graph.
    auto* list = w_->plotPanel()->findChild<QListWidget*>();
    QVERIFY(list && list->count() >= 1);
    QVERIFY(c_->curves()[0].name.rfind("site 2", 0) == 0);
    list->setCurrentRow(0);
    QCOMPARE(int(view_->siteMarkers().size()), 2);
    const auto& marked = view_->siteMarkers()[1];
    QCOMPARE(marked.number, 2);
    QVERIFY(marked.highlighted);
    // All the curves so far are of site 2: it takes the newest one's colour.
    const int newest = int(c_->curves().size()) - 1;
    QCOMPARE(marked.colour, PlotPanel::colourOf(c_->curves()[newest], newest));
    QVERIFY((marked.position - sites[1]).norm() < 1e-12);
    QCOMPARE(w_->plotPanel()->plot()->graph(0)->pen().widthF(), 3.6);
    QVERIFY(c_->curves().size() >= 2);  // the newest curve's graph (drawn last) is faded
    QCustomPlot* plot = w_->plotPanel()->plot();
    QCOMPARE(plot->graph(plot->graphCount() - 1)->pen().color().alpha(), 90);
    list->setCurrentRow(-1);
    list->clearSelection();
    QCOMPARE(int(view_->siteMarkers().size()), 1);
    QCOMPARE(w_->plotPanel()->plot()->graph(0)->pen().widthF(), 1.8);

    // A click on a graph selects its curve, as the list does: the deepest point of all curves
    // (no other graph passes there) selects the curve it belongs to.
    plot->replot();
    int deepest = -1;
    double deepestDepth = -1, deepestForce = 0;
    for (int k = 0; k < int(c_->curves().size()); ++k)
      for (const auto& q : c_->curves()[k].points)
        if (q.depth > deepestDepth) deepestDepth = q.depth, deepestForce = q.force, deepest = k;
    QVERIFY(deepest >= 0 && deepestDepth > 0.1);
    const QPoint at(int(plot->xAxis->coordToPixel(deepestDepth)),
                    int(plot->yAxis->coordToPixel(deepestForce)));
    QTest::mouseClick(plot, Qt::LeftButton, {}, at);
    QCOMPARE(w_->plotPanel()->selectedCurve(), deepest);
    QCOMPARE(list->currentRow(), deepest);
    QVERIFY(view_->siteMarkers().back().highlighted);  // and its site's disc
    QCOMPARE(view_->siteMarkers().back().number, 2);
    list->setCurrentRow(-1);
    list->clearSelection();

    // A click on a site's disc selects that site and picks no new site: site 1 has no curve.
    // Seen from the top, site 1 (the top of the tissue) is in front.
    view_->setFocus();
    QTest::keyClick(view_, Qt::Key_7);
    view_->update();
    QTRY_VERIFY(view_->markerCentre(1).has_value());
    const QPoint disc = view_->markerCentre(1)->toPoint();
    QCOMPARE(view_->markerAt(disc), 1);
    QSignalSpy discClicks(view_, &TissueView::siteMarkerClicked);
    const int sitesBefore = int(c_->sites().size());
    sendMouse(view_, QEvent::MouseButtonPress, disc, Qt::LeftButton, Qt::LeftButton);
    sendMouse(view_, QEvent::MouseButtonRelease, disc, Qt::LeftButton, Qt::NoButton);
    QCOMPARE(discClicks.count(), 1);
    QCOMPARE(discClicks.first().at(0).toInt(), 1);
    QCOMPARE(int(c_->sites().size()), sitesBefore);
    QCOMPARE(c_->currentSite(), 1);
    QCOMPARE(w_->plotPanel()->selectedCurve(), -1);
    // Site 2's newest curve, by its number (what its disc does once shown).
    QVERIFY(!w_->selectSite(1));
    QVERIFY(w_->selectSite(2));
    QCOMPARE(w_->plotPanel()->selectedCurve(), newest);
    list->setCurrentRow(-1);
    list->clearSelection();
  }

  void exportsAreWrittenAndReadBack() {
    QString error;
    PlotPanel* plot = w_->plotPanel();
    for (const QString ext : {"png", "svg", "pdf"}) {
      const QString path = dir_.path() + "/plot." + ext;
      QVERIFY2(plot->exportImage(path, 800, 500, &error), qPrintable(error));
      QFile f(path);
      QVERIFY(f.open(QIODevice::ReadOnly));
      const QByteArray head = f.read(2000);
      if (ext == "pdf") QVERIFY(head.startsWith("%PDF"));
      if (ext == "svg") QVERIFY(head.contains("<svg"));
      if (ext == "png") QCOMPARE(QImage(path).size(), QSize(800, 500));
    }
    QVERIFY(!plot->exportImage(dir_.path() + "/plot.xyz", 0, 0, &error));
    QVERIFY(error.contains("unknown format"));

    // For a paper: 300 dpi (the PNG says so, its size is the one asked), the legend outside the
    // data area, beside it; inside it when asked; the plot on screen unchanged afterwards.
    const int onScreenColumns = plot->plot()->plotLayout()->columnCount();
    PlotPanel::ExportOptions paper;
    paper.width = 1050;
    paper.height = 700;
    paper.dpi = 300;
    const QString png300 = dir_.path() + "/plot300.png";
    QVERIFY2(plot->exportImage(png300, paper, &error), qPrintable(error));
    const QImage printed(png300);
    QCOMPARE(printed.size(), QSize(1050, 700));
    QCOMPARE(printed.dotsPerMeterX(), int(std::lround(300 / 0.0254)));
    auto [axes, legend] = plot->lastExportLayout();
    QVERIFY(!legend.isEmpty());
    // A long legend on a 3.5-inch figure goes under the axes; on a wide one, right of them.
    QVERIFY2(!legend.intersects(axes) && (legend.left() >= axes.right() || legend.top() >= axes.bottom()),
             qPrintable(QString("legend %1,%2 %3x%4, axes right %5")
                            .arg(legend.x()).arg(legend.y()).arg(legend.width())
                            .arg(legend.height()).arg(axes.right())));
    // 300 dpi draws the same layout 300/96 times larger: the axes span 1050·96/300 units.
    QVERIFY(axes.right() < 1050 * 96 / 300);
    if (const char* keep = std::getenv("TP_KEEP_EXPORTS")) {  // to look at them
      QFile::copy(png300, QString(keep) + "/plot300.png");
    }
    QVERIFY2(axes.width() > 0.6 * 1050 * 96 / 300, "the axes keep most of the width");
    paper.dpi = 96;
    paper.width = 1800;
    QVERIFY2(plot->exportImage(dir_.path() + "/plot-wide.png", paper, &error), qPrintable(error));
    std::tie(axes, legend) = plot->lastExportLayout();
    QVERIFY(legend.left() >= axes.right());
    if (const char* keep = std::getenv("TP_KEEP_EXPORTS"))
      QFile::copy(dir_.path() + "/plot-wide.png", QString(keep) + "/plot-wide.png");
    paper.width = 1050;
    paper.dpi = 300;
    paper.legend = PlotPanel::ExportOptions::Legend::Inside;
    QVERIFY2(plot->exportImage(dir_.path() + "/plot-inside.png", paper, &error), qPrintable(error));
    std::tie(axes, legend) = plot->lastExportLayout();
    QVERIFY2(axes.contains(legend.topLeft()),  // in the data area's corner (long names overflow)
             qPrintable(QString("legend %1,%2 %3x%4, axes %5,%6 %7x%8")
                            .arg(legend.x()).arg(legend.y()).arg(legend.width())
                            .arg(legend.height()).arg(axes.x()).arg(axes.y()).arg(axes.width())
                            .arg(axes.height())));
    paper.legend = PlotPanel::ExportOptions::Legend::None;
    QVERIFY2(plot->exportImage(dir_.path() + "/plot-none.png", paper, &error), qPrintable(error));
    QVERIFY(plot->lastExportLayout().second.isEmpty());
    QCOMPARE(plot->plot()->plotLayout()->columnCount(), onScreenColumns);
    QVERIFY(plot->plot()->legend->visible());
    QVERIFY(plot->plot()->axisRect()->insetLayout()->elementCount() == 1);

    // A figure: the 3D view (left half) and the curves (right half) in one image or PDF.
    const QString fig = dir_.path() + "/figure.png";
    QVERIFY2(w_->fileActions()->exportFigure(fig, QSize(1400, 600), 150, 1, &error),
             qPrintable(error));
    if (const char* keep = std::getenv("TP_KEEP_EXPORTS")) QFile::copy(fig, QString(keep) + "/figure.png");
    const QImage figure(fig);
    QCOMPARE(figure.size(), QSize(1400, 600));
    QCOMPARE(figure.dotsPerMeterX(), int(std::lround(150 / 0.0254)));
    const QImage viewHalf = figure.copy(0, 0, 700, 600), plotHalf = figure.copy(700, 0, 700, 600);
    QVERIFY2(distinctColours(viewHalf) > 200, "the tissue, shaded, in the left half");
    QVERIFY2(distinctColours(plotHalf) > 10, "axes, text and curves in the right half");
    const QString figPdf = dir_.path() + "/figure.pdf";
    QVERIFY2(w_->fileActions()->exportFigure(figPdf, QSize(720, 320), 96, 1, &error),
             qPrintable(error));
    QFile pdf(figPdf);
    QVERIFY(pdf.open(QIODevice::ReadOnly));
    QVERIFY(pdf.read(8).startsWith("%PDF"));
    QVERIFY(!w_->fileActions()->exportFigure(dir_.path() + "/figure.svg", QSize(720, 320), 96, 1,
                                            &error));
    QVERIFY(error.contains("unknown format"));

    const QString all = dir_.path() + "/curves.csv";
    QVERIFY2(w_->fileActions()->exportCurves(all, &error), qPrintable(error));
    QFile f(all);
    QVERIFY(f.open(QIODevice::ReadOnly));
    const auto back = parseCurvesCsv(f.readAll().toStdString(), "curves.csv");
    QCOMPARE(int(back.size()), int(c_->curves().size()));

    const QString one = dir_.path() + "/curve.csv";
    QVERIFY2(w_->fileActions()->exportCurrentCurve(one, &error), qPrintable(error));
    QCOMPARE(tp::readCurveCsv(one.toStdString()).size(), c_->curves().back().points.size());

    const QString vtu = dir_.path() + "/state.vtu";
    QSignalSpy done(c_, &SimulationController::exportFinished);
    c_->exportVtu(vtu);
    QTRY_COMPARE_WITH_TIMEOUT(done.count(), 1, 60000);
    QVERIFY2(done.first().at(1).toBool(), qPrintable(done.first().at(2).toString()));
    QFile v(vtu);
    QVERIFY(v.open(QIODevice::ReadOnly));
    const QByteArray text = v.readAll();
    QVERIFY(text.contains("<VTKFile") && text.contains("von_mises_MPa"));
  }

  void measuredCurvesAreImportedAsPoints() {
    const int before = int(c_->curves().size());
    const QString table = dir_.path() + "/afm.csv";
    {
      QFile f(table);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write("# an AFM curve\ndepth (nm),force (nN)\n0,0\n100,400\n200,1200\n300,2300\n");
    }
    QString error;
    QVERIFY2(w_->fileActions()->importMeasuredCurve(table, &error), qPrintable(error));
    QCOMPARE(int(c_->curves().size()), before + 1);
    const NamedCurve& m = c_->curves().back();
    QVERIFY(m.measured);
    QCOMPARE(m.name, std::string("measured · afm.csv"));
    QCOMPARE(int(m.points.size()), 4);
    QCOMPARE(m.points[3].depth, 0.3);  // µm
    QCOMPARE(m.points[3].force, 2.3);  // µN
    QVERIFY(c_->hasUnsavedCurves());
    // Drawn as markers without a line, its legend entry saying "measured".
    QCustomPlot* plot = w_->plotPanel()->plot();
    QCPGraph* g = plot->graph(plot->graphCount() - 1);
    QCOMPARE(int(g->lineStyle()), int(QCPGraph::lsNone));
    QVERIFY(g->name().contains("measured"));
    // The real JPK export: converted at its contact point, named with it.
    const char* shared = std::getenv("TP_SHARED_DATA_DIR");
    const QString jpk = (shared && *shared ? QString(shared)
                                           : QString(TP_SOURCE_DIR) + "/../shared/data") +
                        "/afm_jpk_text_export/force-save-2021.06.30-12.04.16.071.txt";
    if (QFile::exists(jpk)) {
      QVERIFY2(w_->fileActions()->importMeasuredCurve(jpk, &error), qPrintable(error));
      QVERIFY(QString::fromStdString(c_->curves().back().name).contains("contact at 31.46 µm"));
      auto deepestOf = [](const NamedCurve& c) {
        double d = 0;
        for (const tp::CurvePoint& p : c.points) d = std::max(d, p.depth);
        return d;
      };
      const double deepest = deepestOf(c_->curves().back());
      c_->removeCurve(int(c_->curves().size()) - 1);
      // The contact point is shown and can be moved before the curve is converted: a click on
      // the dialog's plot moves it there; the estimate is kept until it is moved.
      const tp::RawCurveReading reading = tp::readJpkForceCurve(jpk.toStdString());
      ContactPointDialog dialog(reading, "jpk.txt");
      dialog.resize(700, 500);
      dialog.show();
      QVERIFY(QTest::qWaitForWindowExposed(&dialog));
      QVERIFY(!dialog.moved());
      QCOMPARE(dialog.contactHeight(), reading.contactHeight);
      QCPAxis* x = dialog.plot()->xAxis;
      const QPoint at(int(x->coordToPixel(reading.contactHeight - 0.2)),
                      dialog.plot()->height() / 2);
      QTest::mouseClick(dialog.plot(), Qt::LeftButton, {}, at);
      QVERIFY(dialog.moved());
      QVERIFY2(std::abs(dialog.contactHeight() - (reading.contactHeight - 0.2)) <
                   2 * std::abs(x->pixelToCoord(1) - x->pixelToCoord(0)),
               qPrintable(QString::number(dialog.contactHeight())));
      QVERIFY(dialog.findChild<QLabel*>("contactResult")->text().contains("moved"));
      // Converted there, named as chosen.
      QVERIFY2(w_->fileActions()->importMeasuredCurve(jpk, &error, reading.contactHeight - 0.2),
               qPrintable(error));
      QVERIFY(QString::fromStdString(c_->curves().back().name).contains(", chosen"));
      // The same conversion as core's at that point, point for point; the deepest indentation
      // 0.2 µm less, up to the force re-zeroed at the new contact (the baseline's noise / k).
      tp::RawCurveOptions moved;
      moved.contactHeight = reading.contactHeight - 0.2;
      const tp::MeasuredCurve core = tp::readJpkForceCurve(jpk.toStdString(), moved).curve;
      QCOMPARE(c_->curves().back().points.size(), core.depth.size());
      for (size_t k = 0; k < core.depth.size(); ++k) {
        QCOMPARE(c_->curves().back().points[k].depth, core.depth[k]);
        QCOMPARE(c_->curves().back().points[k].force, core.force[k]);
      }
      QVERIFY2(std::abs(deepestOf(c_->curves().back()) - (deepest - 0.2)) <
                   5 * reading.noise / reading.springConstant,
               qPrintable(QString("%1 → %2 µm").arg(deepest, 0, 'g', 12).arg(deepestOf(c_->curves().back()), 0, 'g', 12)));
      c_->removeCurve(int(c_->curves().size()) - 1);
    }
    // A bad table is refused with the file, line and value.
    const QString bad = dir_.path() + "/bad.csv";
    {
      QFile f(bad);
      QVERIFY(f.open(QIODevice::WriteOnly));
      f.write("depth (nm),force (nN)\n0,0\n100,lots\n");
    }
    QVERIFY(!w_->fileActions()->importMeasuredCurve(bad, &error));
    QVERIFY2(error.contains("bad.csv: line 3: force 'lots' is not a finite number"),
             qPrintable(error));
    QCOMPARE(int(c_->curves().size()), before + 1);
  }

  void sessionSavedAndReopened() {
    const QString path = dir_.path() + "/session.json";
    QString error;
    // How the tissue is shown goes into the session too.
    DisplaySettings shown = w_->displayPanel()->settings();
    shown.quantity = "displacement";
    shown.deformationScale = 10;
    shown.section = true;
    shown.sectionAxis = 0;
    shown.sectionPosition = 0.25;
    w_->displayPanel()->applySettings(shown);
    view_->setStandardView(Camera::StandardView::Top);
    const DisplaySettings::Camera pose = view_->cameraPose();
    QCOMPARE(view_->field(), Field::Displacement);
    QVERIFY2(w_->fileActions()->saveSession(path, &error), qPrintable(error));
    w_->displayPanel()->applySettings(DisplaySettings{});
    view_->resetView();
    QCOMPARE(view_->field(), Field::VonMises);
    const auto names = c_->curves();
    const Eigen::Vector3d site = c_->latest().site;
    c_->clearCurves();
    QCOMPARE(w_->plotPanel()->plot()->graphCount(), 0);
    const int preparation = c_->latest().preparation;
    QVERIFY2(w_->fileActions()->openSession(path, &error), qPrintable(error));
    QCOMPARE(int(c_->curves().size()), int(names.size()));
    for (size_t i = 0; i < names.size(); ++i) {
      QCOMPARE(c_->curves()[i].name, names[i].name);
      QCOMPARE(c_->curves()[i].measured, names[i].measured);
    }
    QCOMPARE(w_->plotPanel()->curveCount(), int(names.size()));
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().preparation > preparation, 120000);
    waitIdle();
    QVERIFY((c_->latest().site - site).norm() < 0.5);  // the last site, prepared again
    const DisplaySettings back = w_->displayPanel()->settings();
    QCOMPARE(back.quantity, std::string("displacement"));
    QCOMPARE(back.deformationScale, 10.0);
    QVERIFY(back.section);
    QCOMPARE(back.sectionAxis, 0);
    QCOMPARE(back.sectionPosition, 0.25);
    QCOMPARE(view_->field(), Field::Displacement);
    QCOMPARE(view_->deformationScale(), 10.0);
    QVERIFY((view_->cameraPose().target - pose.target).norm() < 1e-9);
    QVERIFY((view_->cameraPose().orientation - pose.orientation).norm() < 1e-9);
    QCOMPARE(view_->cameraPose().distance, pose.distance);
    w_->displayPanel()->applySettings(DisplaySettings{});
    view_->resetView();
  }

  void nondimensionalAxesShowTheCellSize() {
    PlotPanel* plot = w_->plotPanel();
    const double L = c_->meanCellSize();
    QVERIFY(L > 1 && L < 20);
    const double x =
        plot->plot()->graph(0)->data()->at(plot->plot()->graph(0)->data()->size() - 1)->key;
    plot->setNondimensional(true);
    QVERIFY(plot->plot()->xAxis->label().contains(QString::number(L, 'f', 2)));
    QVERIFY(plot->plot()->yAxis->label().contains("E L²"));
    const double xn =
        plot->plot()->graph(0)->data()->at(plot->plot()->graph(0)->data()->size() - 1)->key;
    QVERIFY(std::abs(xn - x / L) < 1e-12);
    plot->setNondimensional(false);
  }

  void dropAndRecentFiles() {
    QVERIFY(RecentFiles::list().contains(QFileInfo(tissue_).absoluteFilePath()));
    // Dropping a tissue file on the window opens it.
    QSignalSpy loaded(c_, &SimulationController::tissueLoaded);
    auto* mime = new QMimeData;
    mime->setUrls({QUrl::fromLocalFile(tissue_)});
    const QPoint at = w_->rect().center();
    QDragEnterEvent enter(at, Qt::CopyAction, mime, Qt::LeftButton, Qt::NoModifier);
    QApplication::sendEvent(w_.get(), &enter);
    QVERIFY(enter.isAccepted());
    QDropEvent drop(QPointF(at), Qt::CopyAction, mime, Qt::LeftButton, Qt::NoModifier);
    QApplication::sendEvent(w_.get(), &drop);
    QTRY_COMPARE_WITH_TIMEOUT(loaded.count(), 1, 60000);
    QTRY_VERIFY_WITH_TIMEOUT(c_->prepared() && !c_->busy(), 120000);
    delete mime;
  }

  void aBadFileIsRefusedWithAMessage() {
    const QString bad = dir_.path() + "/broken.ply";
    std::ofstream(bad.toStdString())
        << "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\n"
           "property float y\nproperty float z\nend_header\n0 0 0\n";
    const auto geometry = c_->latest().geometry;
    w_->fileActions()->open(bad);
    QMessageBox* box = nullptr;
    QTRY_VERIFY_WITH_TIMEOUT((box = w_->findChild<QMessageBox*>("errorBox")) && box->isVisible(),
                             60000);
    QVERIFY2(box->text().contains("broken.ply"), qPrintable(box->text()));
    box->close();
    waitIdle();
    QCOMPARE(c_->latest().geometry, geometry);  // the previous tissue stays
    QVERIFY(c_->prepared());
  }

  void dragRatesOnTheDefaultMeristem() {
    // A measurement, not a check: TP_GUI_MEASURE=1 build/bin/test_gui_window dragRates...
    if (qEnvironmentVariableIsEmpty("TP_GUI_MEASURE")) QSKIP("set TP_GUI_MEASURE=1 to measure");
    QElapsedTimer load;
    load.start();
    w_->fileActions()->openTissue(QString::fromStdString(tp::defaultTissuePath()));
    QTRY_VERIFY_WITH_TIMEOUT(c_->prepared() && c_->latest().geometry->cellCount() > 400, 300000);
    waitIdle(300000);
    qInfo("default meristem loaded and prepared in %.2f s", load.nsecsElapsed() / 1e9);
    const int frames0 = view_->frameCount(), snaps0 = c_->snapshotCount();
    QElapsedTimer timer;
    timer.start();
    const QPoint start = view_->rect().center();
    sendMouse(view_, QEvent::MouseButtonPress, start, Qt::RightButton, Qt::RightButton);
    // Down to 1 µm and back, repeatedly, at 60 mouse events per second for 20 s.
    int i = 0;
    double travelled = 0, lastDepth = 0, deepest = 0;
    while (timer.elapsed() < 20000) {
      const double d = c_->latest().point ? c_->latest().point->depth : lastDepth;  // as shown
      travelled += std::abs(d - lastDepth);
      deepest = std::max(deepest, d);
      lastDepth = d;
      const int phase = i++ % 200;
      const int dy = phase < 100 ? phase : 200 - phase;
      sendMouse(view_, QEvent::MouseMove, start + QPoint(0, dy), Qt::NoButton, Qt::RightButton);
      QTest::qWait(16);
    }
    sendMouse(view_, QEvent::MouseButtonRelease, start, Qt::RightButton, Qt::NoButton);
    const double s = timer.nsecsElapsed() / 1e9;
    const int frames = view_->frameCount() - frames0, snaps = c_->snapshotCount() - snaps0;
    qInfo(
        "default meristem, probe drag for %.1f s: %d frames (%.1f fps), %d equilibria (%.2f per s); "
        "the probe shown travelled %.2f um, deepest %.2f um",
        s, frames, frames / s, snaps, snaps / s, travelled, deepest);
    waitIdle(300000);
    // Turning the tissue (left drag) for 5 s: every mouse event asks for a frame.
    const int frames1 = view_->frameCount();
    timer.restart();
    sendMouse(view_, QEvent::MouseButtonPress, start, Qt::LeftButton, Qt::LeftButton);
    for (int k = 0; timer.elapsed() < 5000; ++k) {
      sendMouse(view_, QEvent::MouseMove, start + QPoint(4 * (k % 100) - 200, 0), Qt::NoButton,
                Qt::LeftButton);
      QTest::qWait(16);
    }
    sendMouse(view_, QEvent::MouseButtonRelease, start, Qt::LeftButton, Qt::NoButton);
    const double r = timer.nsecsElapsed() / 1e9;
    qInfo("default meristem, turning for %.1f s: %.1f fps", r, (view_->frameCount() - frames1) / r);
  }

  // Answers the next modal message box with `button` once it shows; its text goes to `text`.
  void answerNextMessageBox(QMessageBox::StandardButton button, QString* text) {
    QTimer::singleShot(50, this, [this, button, text] {
      auto* box = qobject_cast<QMessageBox*>(QApplication::activeModalWidget());
      if (!box) return answerNextMessageBox(button, text);  // not shown yet
      if (text) *text = box->text();
      box->button(button)->click();
    });
  }

  void fitReadsBackTheModulusOfACurveAndReportsIt() {
    // Nothing measured: refused with the reason.
    removeMeasuredCurves();
    QString why;
    QVERIFY(!c_->fitMeasuredCurves(true, false, false, false, &why));
    QVERIFY2(why.contains("no measured curve"), qPrintable(why));
    // A curve simulated at E = 100 MPa on the tissue as given (level 0, fast), taken as measured,
    // is read back from E = 150 MPa.
    const NamedCurve measured =
        addSimulatedAsMeasured(0, 100, c_->params().pressure, 0.3, 3, "measured · simulated at E 100");
    QCOMPARE(int(measured.points.size()), 4);
    SimulationParams p = c_->params();
    p.youngModulus = 150;
    c_->setParams(p);
    waitIdle();
    QSignalSpy done(c_, &SimulationController::fitFinished);
    QString text;
    answerNextMessageBox(QMessageBox::Ok, &text);  // the report the window shows
    auto* bar = w_->findChild<QProgressBar*>("runProgressBar");
    QVERIFY(bar);
    QVERIFY(c_->fitMeasuredCurves(true, false, false, false, &why));
    // While it fits the bar runs as busy (its length is not known), then it is full.
    QTRY_COMPARE_WITH_TIMEOUT(bar->maximum(), 0, 10000);
    QTRY_COMPARE_WITH_TIMEOUT(done.count(), 1, 120000);
    QTRY_COMPARE_WITH_TIMEOUT(bar->maximum(), 1, 10000);
    QCOMPARE(bar->value(), 1);
    const auto outcome = done.first().at(0).value<FitOutcome>();
    QVERIFY2(outcome.ok, qPrintable(outcome.message));
    const double E = outcome.result->find("E")->value;
    QVERIFY2(std::abs(E - 100) < 1.0, qPrintable(QString("E = %1").arg(E)));
    QTRY_VERIFY_WITH_TIMEOUT(text.contains("E = "), 10000);
    QVERIFY2(text.contains("Hertz apparent modulus"), qPrintable(text));
    const NamedCurve& fitted = c_->curves().back();
    // Named by the fitted value ("fit · E 100 ± 0.02 MPa, …"; 99.99 as well as 100.01 is a
    // good fit).
    QVERIFY2(QString::fromStdString(fitted.name).startsWith("fit · E " + QString::number(E, 'g', 4) + " ± "),
             fitted.name.c_str());
    // Its residuals (measured − simulated at each point): about nothing, the data being the
    // model's own at E = 100; drawn in a strip under the curves, one graph beside the zero line.
    QCOMPARE(fitted.residuals.size(), fitted.points.size());
    for (size_t k = 0; k < fitted.residuals.size(); ++k)
      QVERIFY2(std::abs(fitted.residuals[k]) < 1e-3 * std::abs(measured.points.back().force),
               qPrintable(QString("residual %1 at %2 um").arg(fitted.residuals[k]).arg(fitted.points[k].depth)));
    QCustomPlot* plot = w_->plotPanel()->plot();
    auto* strip = plot->findChild<QCPAxisRect*>("residualStrip");
    QVERIFY(strip);
    QCOMPARE(int(strip->graphs().size()), 2);
    QCOMPARE(strip->graphs().at(1)->data()->size(), int(fitted.points.size()));
    QCOMPARE(strip->axis(QCPAxis::atBottom)->range().upper, plot->xAxis->range().upper);
    waitIdle();
    // The curve panel's Cancel stops a fit within an iteration and says so; no curve is added.
    const int curves = int(c_->curves().size());
    QString cancelled;
    answerNextMessageBox(QMessageBox::Ok, &cancelled);
    auto* cancelButton = w_->findChild<QPushButton*>("cancelButton");
    QVERIFY(cancelButton);
    QVERIFY(!cancelButton->isEnabled());
    QVERIFY(c_->fitMeasuredCurves(true, true, false, false, &why));
    QVERIFY(cancelButton->isEnabled());
    QTRY_VERIFY_WITH_TIMEOUT(c_->busy(), 10000);
    cancelButton->click();
    QTRY_COMPARE_WITH_TIMEOUT(done.count(), 2, 30000);
    QVERIFY(!done.at(1).at(0).value<FitOutcome>().ok);
    QTRY_COMPARE_WITH_TIMEOUT(bar->value(), 0, 10000);  // cancelled: empty, not full
    QTRY_VERIFY_WITH_TIMEOUT(cancelled.contains("cancelled"), 10000);
    QCOMPARE(int(c_->curves().size()), curves);
    QVERIFY(!c_->fitting());
    QVERIFY(!cancelButton->isEnabled());
    // Without a fit's curve the strip goes.
    c_->removeCurve(int(c_->curves().size()) - 1);
    QTRY_VERIFY(!plot->findChild<QCPAxisRect*>("residualStrip"));
    waitIdle();
    p.autoMesh = true;
    p.youngModulus = 100;
    c_->setParams(p);
    waitIdle();
  }

  void fitHoldsTheSiteAsAMaterialPoint() {
    // The application's fit holds its site as the material point it is, as `tissueprobe-cli fit`
    // holds its default site (the top). A turgid curve made at the top (level 2, E 100 MPa, p 0.8 MPa), taken
    // as measured, fitted for E and p from 130 MPa and 0.6 MPa in the application, and the same
    // fit run in core at that material point (one thread, as the application's worker). The
    // application used to hold the site as the point in space it occupies at the starting
    // values, which slides over the surface as E and p change the turgid shape (from the same
    // start on a level-3 curve it returned E 122.7, p 0.744, as the CLI does with that point as
    // --site, against 98.9, 0.807 now). E and p are correlated at −0.99 along a straight turgid
    // curve, so small differences of the model move where the search ends in that valley: the
    // two must agree closely, not only be near the truth.
    // On the default meristem at its top, with only this test's measured curve (a fit fits
    // every measured curve); the tissue, parameters and curves are put back at the end.
    const QString tissueBefore = c_->tissuePath();
    const SimulationParams paramsBefore = c_->params();
    removeMeasuredCurves();
    const int before = int(c_->curves().size());
    c_->loadTissue(QString());
    waitIdle();
    const NamedCurve measured =
        addSimulatedAsMeasured(2, 100, 0.8, 0.5, 20, "measured · simulated at E 100, p 0.8");
    QCOMPARE(int(measured.points.size()), 21);
    SimulationParams p = c_->params();
    p.youngModulus = 130;
    p.pressure = 0.6;
    c_->setParams(p);
    waitIdle();
    QSignalSpy done(c_, &SimulationController::fitFinished);
    QString report, why;
    answerNextMessageBox(QMessageBox::Ok, &report);
    QVERIFY2(c_->fitMeasuredCurves(true, true, false, false, &why), qPrintable(why));
    QTRY_COMPARE_WITH_TIMEOUT(done.count(), 1, 300000);
    const auto outcome = done.first().at(0).value<FitOutcome>();
    QVERIFY2(outcome.ok, qPrintable(outcome.message));
    QTRY_VERIFY_WITH_TIMEOUT(report.contains("E = "), 10000);
    waitIdle();

    tp::FitSettings fs;
    fs.start = p.experimentSettings();
    tp::FitCurve curve;
    curve.data.name = measured.name;
    for (const auto& pt : measured.points) {
      curve.data.depth.push_back(pt.depth);
      curve.data.force.push_back(pt.force);
    }
    const auto tissue = std::make_shared<const tp::CellComplex>(tp::readTissue(tp::defaultTissuePath()));
    const int threads = omp_get_max_threads();
    omp_set_num_threads(1);
    {  // The top where the application put it: at the parameters it was loaded with.
      SimulationParams atLoad = p;
      atLoad.youngModulus = 100;
      atLoad.pressure = 0.8;
      tp::Experiment e(tissue, atLoad.experimentSettings());
      e.prepareSite(2, tp::Monitor{});
      fs.start.indentation.restSite = e.restSite();
    }
    const tp::FitResult cli = tp::fitCurves(tissue, fs, {curve}, tp::Monitor{});
    omp_set_num_threads(threads);
    QVERIFY2(cli.converged, cli.message.c_str());
    for (const char* key : {"E", "p"}) {
      const double app = outcome.result->find(key)->value, core = cli.find(key)->value;
      QVERIFY2(std::abs(app - core) < 2e-3 * std::abs(core),
               qPrintable(QString("%1: %2 in the application, %3 as the CLI fits").arg(key).arg(app).arg(core)));
    }
    while (int(c_->curves().size()) > before) c_->removeCurve(int(c_->curves().size()) - 1);
    c_->setParams(paramsBefore);
    c_->loadTissue(tissueBefore);
    waitIdle();
  }

  void stiffnessMapRunsShowsItsSitesAndIsSaved() {
    // A map of the cell middles at the tissue's own mesh (level 0, fast), run from the dock.
    SimulationParams p = c_->params();
    p.autoMesh = false;
    p.meshLevel = 0;
    p.youngModulus = 100;
    p.pressure = 0.8;
    c_->setParams(p);
    waitIdle();
    MapRunner* runner = w_->mapRunner();
    MapPanel* panel = w_->mapPanel();
    panel->setCacheRoot(dir_.path() + "/maps");
    panel->findChild<QComboBox*>("mapSites")->setCurrentIndex(0);  // cell middles
    panel->findChild<QDoubleSpinBox*>("mapDepth")->setValue(0.2);
    panel->findChild<QSpinBox*>("mapSteps")->setValue(3);
    auto* start = panel->findChild<QPushButton*>("mapStart");
    auto* show = panel->findChild<QPushButton*>("mapShow");
    QVERIFY(start && show);
    QVERIFY(!show->isEnabled());  // nothing to show yet
    QSignalSpy finished(runner, &MapRunner::finished);
    QTest::mouseClick(start, Qt::LeftButton);
    QVERIFY(runner->running());
    QVERIFY(!start->isEnabled());
    QTRY_COMPARE_WITH_TIMEOUT(finished.count(), 1, 300000);
    QVERIFY2(finished.first().at(0).toBool(), qPrintable(finished.first().at(2).toString()));
    QVERIFY(runner->hasMap());
    const SessionMap map = runner->map();
    const std::vector<tp::MapSite> middles =
        tp::cellMiddleSites(tp::readPly(tissue_.toStdString()));
    QCOMPARE(map.plan.taskCount(), int(middles.size()));
    QCOMPARE(runner->sitesDone(), int(middles.size()));
    double lo = 1e300, hi = -1e300;
    for (const tp::TaskResult& r : map.results) {
      QVERIFY2(r.converged(), r.message.c_str());
      QCOMPARE(r.level, 0);
      QCOMPARE(r.depth, 0.2);
      lo = std::min(lo, r.secant), hi = std::max(hi, r.secant);
    }
    QVERIFY(hi > lo);  // the sites differ
    auto* bar = panel->findChild<QProgressBar*>("mapProgressBar");
    QCOMPARE(bar->value(), bar->maximum());
    QVERIFY(panel->findChild<QLabel*>("mapSummary")->text().contains("cell middles: median"));
    // The table the folder holds is the one tissueprobe-cli map writes.
    QVERIFY(QFile::exists(runner->folder() + "/map.csv"));

    // Shown on the tissue: the outer surface coloured between the sites' values (Shepard's
    // weights are convex), the colour bar named after the map.
    QVERIFY(show->isEnabled());
    QCoreApplication::processEvents();
    const QImage before = view_->grabFramebuffer();
    QTest::mouseClick(show, Qt::LeftButton);
    QCOMPARE(w_->displayPanel()->mapValue(), 0);
    QCOMPARE(view_->mapValue(), 0);
    const auto& values = view_->shownValues();
    const TissueGeometry& g = *c_->latest().geometry;
    int outer = 0, coloured = 0;
    for (int t = 0; t < g.triangleCount(); ++t) {
      if (!g.outer[t]) {
        QVERIFY(std::isnan(values[t]));
        continue;
      }
      ++outer;
      if (!std::isfinite(values[t])) continue;
      ++coloured;
      QVERIFY2(values[t] >= lo * (1 - 1e-6) && values[t] <= hi * (1 + 1e-6),
               qPrintable(QString("%1 outside [%2, %3]").arg(values[t]).arg(lo).arg(hi)));
    }
    QVERIFY2(coloured > outer / 2, qPrintable(QString("%1 of %2").arg(coloured).arg(outer)));
    QVERIFY(changedFraction(before, view_->grabFramebuffer()) > 0.05);

    // A click on a site adds its curve (once) and names its numbers.
    view_->setStandardView(Camera::StandardView::Top);
    QCoreApplication::processEvents();
    int task = -1;  // the site nearest the middle of the view, seen from above
    double best = 1e300;
    for (const tp::TaskResult& r : map.results) {
      const double d = (pixelOf(view_, r.contact) - view_->rect().center()).manhattanLength();
      if (d < best) best = d, task = r.task;
    }
    const tp::TaskResult& r = map.results[task];
    const int curves = int(c_->curves().size());
    const int prepared = c_->latest().preparation;
    QTest::mouseClick(view_, Qt::LeftButton, {}, pixelOf(view_, r.contact));
    QCOMPARE(int(c_->curves().size()), curves + 1);
    const NamedCurve& curve = c_->curves().back();
    QVERIFY2(curve.name.rfind("map " + map.plan.site(task).label + " ", 0) == 0, curve.name.c_str());
    QCOMPARE(int(curve.points.size()), 4);
    QCOMPARE(curve.points.back().force, r.force);
    QCOMPARE(curve.points.back().depth, 0.2);
    QCOMPARE(curve.meshLevel, 0);
    QTest::mouseClick(view_, Qt::LeftButton, {}, pixelOf(view_, r.contact));
    QCOMPARE(int(c_->curves().size()), curves + 1);  // not twice
    QTest::qWait(500);
    QCOMPARE(c_->latest().preparation, prepared);  // a click on the map prepares no new site

    // Exported as the CLI writes them, byte for byte.
    QString error;
    const QString table = dir_.path() + "/exported-map.csv", surface = dir_.path() + "/map.vtu";
    QVERIFY2(w_->fileActions()->exportMapTable(table, &error), qPrintable(error));
    QVERIFY2(w_->fileActions()->exportMapSurface(surface, &error), qPrintable(error));
    QCOMPARE(tp::readTextFile(table.toStdString(), "t"),
             tp::readTextFile((runner->folder() + "/map.csv").toStdString(), "t"));
    QCOMPARE(tp::readTextFile(surface.toStdString(), "s"),
             tp::readTextFile((runner->folder() + "/map-surface.vtu").toStdString(), "s"));

    // Saved in the session and back, shown as it was.
    const QString session = dir_.path() + "/map-session.json";
    QVERIFY2(w_->fileActions()->saveSession(session, &error), qPrintable(error));
    const std::vector<tp::TaskResult> saved = map.results;
    runner->clear();
    w_->displayPanel()->applySettings(DisplaySettings{});
    QVERIFY(!runner->hasMap());
    const int preparation = c_->latest().preparation;
    QVERIFY2(w_->fileActions()->openSession(session, &error), qPrintable(error));
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().preparation > preparation, 120000);
    waitIdle();
    QVERIFY(runner->hasMap());
    QCOMPARE(int(runner->map().results.size()), int(saved.size()));
    for (size_t k = 0; k < saved.size(); ++k) {
      QCOMPARE(runner->map().results[k].secant, saved[k].secant);  // bit for bit
      QCOMPARE(runner->map().results[k].curve, saved[k].curve);
    }
    QCOMPARE(view_->mapValue(), 0);
    QVERIFY(runner->field() && runner->field()->siteCount() == int(saved.size()));

    // Another map, cancelled at once: it stops, keeps what is done, and Start is back.
    finished.clear();
    panel->findChild<QComboBox*>("mapSites")->setCurrentIndex(1);  // junctions
    QVERIFY(panel->startMap());
    runner->cancel();
    QTRY_COMPARE_WITH_TIMEOUT(finished.count(), 1, 120000);
    QVERIFY(!finished.first().at(0).toBool());
    QVERIFY(finished.first().at(1).toBool());
    QVERIFY(!runner->running());
    QVERIFY(start->isEnabled());
    QVERIFY(bar->maximum() > 0);  // not left running as busy
    w_->displayPanel()->applySettings(DisplaySettings{});
    QCOMPARE(view_->mapValue(), -1);
    view_->resetView();
  }

  void junctionBandRefinesTheMeshAndSaysSo() {
    // Parameters ▸ "Band along the junctions": the site is prepared again on a mesh with the
    // band, the status bar says so, and it is a parameter of the curves run (and saved) with it.
    // Without turgor the walls have no bending layer: the box is disabled.
    auto* panel = w_->parameterPanel();
    auto* band = panel->findChild<QCheckBox*>("junctionBandCheck");
    auto* label = w_->findChild<QLabel*>("meshLabel");
    QVERIFY(band && label);
    waitIdle();
    // A refined level (level 0 is the tissue as loaded: nothing to refine), turgid Koiter walls.
    const SimulationParams start = c_->params();
    SimulationParams level2 = start;
    level2.autoMesh = false;
    level2.meshLevel = 2;
    level2.pressure = 0.8;
    level2.bending = tp::BendingModel::Koiter;
    level2.junctionBand = false;
    panel->setParams(level2);  // silently; the controller is given them as the panel would
    c_->setParams(level2);
    waitIdle();
    QVERIFY(!band->isChecked());
    QVERIFY(band->isEnabled());
    const auto vertices = [&] {
      const QRegularExpressionMatch m = QRegularExpression("(\\d+) vertices").match(label->text());
      return m.hasMatch() ? m.captured(1).toInt() : -1;
    };
    int preparation = c_->latest().preparation;
    band->setChecked(true);
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().preparation > preparation, 120000);
    waitIdle();
    QVERIFY(c_->params().junctionBand);
    QVERIFY2(label->text().contains("junction band"), qPrintable(label->text()));
    const int withBand = vertices();
    preparation = c_->latest().preparation;
    band->setChecked(false);
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().preparation > preparation, 120000);
    waitIdle();
    QVERIFY(!c_->params().junctionBand);
    QVERIFY2(!label->text().contains("junction band"), qPrintable(label->text()));
    const int without = vertices();
    QVERIFY2(
        without > 0 && withBand > without,
        qPrintable(QString("%1 vertices with the band, %2 without").arg(withBand).arg(without)));
    SimulationParams p = panel->params();
    const SimulationParams before = p;
    p.pressure = 0;
    panel->setParams(p);  // silently: nothing is prepared
    QVERIFY(!band->isEnabled());
    panel->setParams(before);
    QVERIFY(band->isEnabled());
    panel->setParams(start);
    c_->setParams(start);
    waitIdle();
  }

  void presentationModeIsLargeAndGoesBack() {
    // View ▸ Presentation (F5): larger fonts, the side docks put away, the overlay drawn larger
    // and opaque; F5 again gives back the fonts and exactly the docks there were.
    auto* act = w_->findChild<QAction*>("presentationAction");
    QVERIFY(act);
    auto* params = w_->findChild<QDockWidget*>("parametersDock");
    auto* plotDock = w_->findChild<QDockWidget*>("plotDock");
    QVERIFY(params && plotDock);
    params->show();
    QTRY_VERIFY(params->isVisible());
    const double normalPt = w_->menuBar()->font().pointSizeF();
    const double normalTick = w_->plotPanel()->plot()->xAxis->tickLabelFont().pointSizeF();
    const QImage before = w_->view()->grabFramebuffer();
    const QSize windowSize = w_->size();
    QCOMPARE(act->shortcut(), QKeySequence(Qt::Key_F5));
    act->trigger();
    QVERIFY(act->isChecked());
    QCOMPARE(w_->menuBar()->font().pointSizeF(), 1.5 * normalPt);
    QCOMPARE(plotDock->font().pointSizeF(), 1.5 * normalPt);
    QCOMPARE(params->font().pointSizeF(), normalPt);  // hidden: left alone
    QCOMPARE(w_->plotPanel()->plot()->xAxis->tickLabelFont().pointSizeF(), 1.6 * normalTick);
    QCOMPARE(w_->view()->overlayScale(), 1.6);
    QTRY_VERIFY(!params->isVisible());
    QVERIFY(plotDock->isVisible());
    // The view has the room of the docks, and its overlay (depth/force, colour bar) is larger.
    QTRY_VERIFY(w_->view()->width() > before.width() / w_->view()->devicePixelRatioF() + 100);
    act->trigger();
    QVERIFY(!act->isChecked());
    QCOMPARE(w_->menuBar()->font().pointSizeF(), normalPt);
    QCOMPARE(plotDock->font().pointSizeF(), normalPt);
    QCOMPARE(w_->plotPanel()->plot()->xAxis->tickLabelFont().pointSizeF(), normalTick);
    QCOMPARE(w_->view()->overlayScale(), 1.0);
    QTRY_VERIFY(params->isVisible());
    QTRY_COMPARE(w_->size(), windowSize);  // the large font did not grow the window
  }

  void helpExplainsTheColoursAndTheCurve() {
    auto* act = w_->findChild<QAction*>("explanationAction");
    QVERIFY(act);
    act->trigger();
    auto* dialog = w_->findChild<QDialog*>("explanationDialog");
    QVERIFY(dialog);
    QTRY_VERIFY(dialog->isVisible());
    QVERIFY(!dialog->isModal());
    const QString text = dialog->findChild<QTextBrowser*>("explanationText")->toPlainText();
    // Every colour quantity the menu offers is explained on the page, by its name.
    for (int q = 0; q < tp::kQuantityCount; ++q) {
      const QString name = QString::fromUtf8(tp::quantityInfo(tp::Quantity(q)).name);
      QVERIFY2(text.contains(name, Qt::CaseInsensitive), qPrintable(name));
    }
    for (const char* word : {"turgor", "depth", "force", "plasmolysed", "discretisation error",
                             "What the model leaves out"})
      QVERIFY2(text.contains(QString::fromUtf8(word), Qt::CaseInsensitive), word);
    dialog->hide();
  }

  void crashedSessionsAreOfferedBack() {
    // Unsaved curves are written aside (a whole session, readable); saved ones are not.
    QVERIFY(!c_->curves().empty());
    c_->markCurvesUnsaved();
    w_->fileActions()->autosaveNow();
    Autosave* autosave = w_->fileActions()->autosave();
    const QString own = autosave->path();
    QVERIFY2(QFile::exists(own), qPrintable(own));
    QVERIFY2(own.startsWith(QDir::tempPath()), qPrintable(own));  // never the user's folder
    const int n = int(c_->curves().size());
    QCOMPARE(int(loadSession(own.toStdString()).curves.size()), n);

    // A window that crashed left its file with no live lock: another window sees it as an
    // orphan, but never a running window's own.
    const QString crashed = autosave->folder() + "/session-999999.json";
    QFile::remove(crashed);
    QVERIFY(QFile::copy(own, crashed));
    Autosave other(autosave->folder());
    QCOMPARE(other.orphans(), QStringList{crashed});

    // Open: the curves come back (cleared here first), as unsaved, and the orphan is gone.
    c_->clearCurves();
    QCOMPARE(int(c_->curves().size()), 0);
    QString text;
    const int preparation = c_->latest().preparation;
    answerNextMessageBox(QMessageBox::Open, &text);
    w_->fileActions()->offerRecovery();
    QVERIFY2(text.contains("did not close normally"), qPrintable(text));
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().preparation > preparation, 120000);  // its site again
    waitIdle();
    QCOMPARE(int(c_->curves().size()), n);
    QVERIFY(c_->hasUnsavedCurves());
    QVERIFY(!QFile::exists(crashed));

    // Later keeps an orphan for the next start; Discard deletes it.
    QVERIFY(QFile::copy(own, crashed));
    answerNextMessageBox(QMessageBox::Ignore, &text);
    w_->fileActions()->offerRecovery();
    QVERIFY(QFile::exists(crashed));
    answerNextMessageBox(QMessageBox::Discard, &text);
    w_->fileActions()->offerRecovery();
    QVERIFY(!QFile::exists(crashed));
    QVERIFY(autosave->orphans().isEmpty());

    // Once saved there is nothing to recover: the autosave goes at the next tick.
    c_->markCurvesSaved();
    w_->fileActions()->autosaveNow();
    QVERIFY(!QFile::exists(own));
    c_->markCurvesUnsaved();
    w_->fileActions()->autosaveNow();
    QVERIFY(QFile::exists(own));  // for layoutIsRemembered: a clean exit removes it
  }

  void clearAsksFirst() {
    QVERIFY(!c_->curves().empty());
    const int n = static_cast<int>(c_->curves().size());
    auto* clear = w_->plotPanel()->findChild<QPushButton*>("clearCurves");
    QVERIFY(clear);
    QString text;
    answerNextMessageBox(QMessageBox::No, &text);
    clear->click();
    QVERIFY2(text.contains(QString::number(n)), qPrintable(text));
    QCOMPARE(int(c_->curves().size()), n);  // kept
  }

  void quittingWithUnsavedCurvesAsks() {
    // A curve made after the last save: closing asks, and Cancel keeps the window open.
    c_->requestDepth(0.05);
    QTRY_VERIFY_WITH_TIMEOUT(c_->latest().depth == 0.05 && !c_->busy(), 60000);
    QVERIFY(c_->hasUnsavedCurves());
    QString text;
    answerNextMessageBox(QMessageBox::Cancel, &text);
    QVERIFY(!w_->close());
    QVERIFY2(text.contains("not been saved"), qPrintable(text));
    QVERIFY(w_->isVisible());
    QVERIFY(c_->hasUnsavedCurves());
    // Exported: nothing left to lose, no question.
    QString error;
    QVERIFY2(w_->fileActions()->exportCurves(dir_.path() + "/all.csv", &error), qPrintable(error));
    QVERIFY(!c_->hasUnsavedCurves());
  }

  void layoutIsRemembered() {
    const QString autosaved = w_->fileActions()->autosave()->path();
    c_->markCurvesUnsaved();
    w_->fileActions()->autosaveNow();
    QVERIFY(QFile::exists(autosaved));
    c_->markCurvesSaved();  // no question at quit (that is quittingWithUnsavedCurvesAsks)
    w_->close();
    QVERIFY2(!QFile::exists(autosaved), "a clean exit leaves no autosave");
    QSettings settings;
    QVERIFY(!settings.value("window/geometry").toByteArray().isEmpty());
    QVERIFY(!settings.value("window/state").toByteArray().isEmpty());
    QVERIFY2(settings.fileName().startsWith(QDir::tempPath()), qPrintable(settings.fileName()));
  }

  void cleanupTestCase() { w_.reset(); }
};

TP_GUI_TEST(WindowTest)
#include "test_window.moc"
