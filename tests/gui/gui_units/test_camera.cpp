// Camera: fit, projection round trips, standard views, rays, orbit and pan.
#include <QTest>

#include "Camera.h"
#include "TestMain.h"

using namespace tp::gui;

namespace {

Eigen::AlignedBox3d meristemBox() {
  return {Eigen::Vector3d(-40, -40, 0), Eigen::Vector3d(40, 40, 42)};
}

std::vector<Eigen::Vector3d> corners(const Eigen::AlignedBox3d& b) {
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < 8; ++i)
    out.push_back(b.corner(static_cast<Eigen::AlignedBox3d::CornerType>(i)));
  return out;
}

}  // namespace

class CameraTest : public QObject {
  Q_OBJECT

 private slots:
  void lookAlongTurnsTheViewKeepingZUp() {
    Camera cam;
    cam.setViewport(800, 600);
    for (const Eigen::Vector3d d : {Eigen::Vector3d(0.3, -0.5, -0.8), Eigen::Vector3d(1, 0, 0),
                                    Eigen::Vector3d(0, 0, -1)}) {
      cam.lookAlong(d);
      QVERIFY((cam.viewDirection() - d.normalized()).norm() < 1e-12);
      QVERIFY(std::abs(cam.up().dot(cam.viewDirection())) < 1e-12);
      QVERIFY(std::abs(cam.right().z()) < 1e-12);  // no roll: the horizon stays level
      if (std::abs(d.normalized().z()) < 0.99) QVERIFY(cam.up().z() > 0);
    }
  }

  void fitPutsTheBoxInsideTheView_data() {
    QTest::addColumn<int>("width");
    QTest::addColumn<int>("height");
    QTest::addColumn<double>("yaw");
    QTest::addColumn<double>("pitch");
    QTest::newRow("landscape") << 800 << 500 << 0.0 << 0.0;
    QTest::newRow("portrait") << 300 << 900 << 30.0 << 20.0;
    QTest::newRow("square, from below") << 600 << 600 << -70.0 << -60.0;
    QTest::newRow("wide, turned") << 1600 << 300 << 135.0 << 45.0;
  }
  void fitPutsTheBoxInsideTheView() {
    QFETCH(int, width);
    QFETCH(int, height);
    QFETCH(double, yaw);
    QFETCH(double, pitch);
    Camera cam;
    cam.setViewport(width, height);
    cam.setSceneBounds(meristemBox());
    cam.rotateBy(yaw, pitch);
    cam.pan({0, 0}, {200, -100});  // fit must undo any pan
    cam.fit(meristemBox());
    for (const auto& c : corners(meristemBox())) {
      const Eigen::Vector3d p = cam.project(c);
      QVERIFY2(p.x() >= 0 && p.x() <= width && p.y() >= 0 && p.y() <= height,
               qPrintable(QString("corner at pixel (%1, %2)").arg(p.x()).arg(p.y())));
      QVERIFY(p.z() > -1 && p.z() < 1);  // between the near and far planes
    }
    // Fitting also fills the view: the box's centre is at the centre of the viewport.
    const Eigen::Vector3d c = cam.project(meristemBox().center());
    QVERIFY(std::abs(c.x() - width / 2.0) < 1e-6 && std::abs(c.y() - height / 2.0) < 1e-6);
  }

  void projectAndUnprojectAreInverse() {
    Camera cam;
    cam.setViewport(1024, 700);
    cam.setSceneBounds(meristemBox());
    cam.reset();
    cam.rotateBy(23, -11);
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 21), Eigen::Vector3d(39, -12, 5),
                                     Eigen::Vector3d(-30, 30, 40), Eigen::Vector3d(1, 2, 3)}) {
      const Eigen::Vector3d q = cam.unproject(cam.project(p));
      QVERIFY2((q - p).norm() < 1e-6 * 80, qPrintable(QString("error %1").arg((q - p).norm())));
    }
  }

  void rayThroughAProjectedPointPassesThroughIt() {
    Camera cam;
    cam.setViewport(640, 480);
    cam.setSceneBounds(meristemBox());
    cam.reset();
    const Eigen::Vector3d p(10, -5, 30);
    const Eigen::Vector3d px = cam.project(p);
    const Ray r = cam.rayAt(px.x(), px.y());
    QVERIFY(std::abs(r.direction.norm() - 1) < 1e-12);
    const Eigen::Vector3d d = p - r.origin;
    const double off = (d - d.dot(r.direction) * r.direction).norm();
    QVERIFY2(off < 1e-6, qPrintable(QString("ray misses by %1 um").arg(off)));
    QVERIFY(d.dot(r.direction) > 0);
  }

  void standardViewsLookAlongTheirAxes() {
    Camera cam;
    cam.setSceneBounds(meristemBox());
    struct Case {
      Camera::StandardView view;
      Eigen::Vector3d look, up;
    };
    for (const Case& c : {Case{Camera::StandardView::Front, {0, 1, 0}, {0, 0, 1}},
                          Case{Camera::StandardView::Right, {-1, 0, 0}, {0, 0, 1}},
                          Case{Camera::StandardView::Top, {0, 0, -1}, {0, 1, 0}}}) {
      cam.setStandardView(c.view);
      QVERIFY((cam.viewDirection() - c.look).norm() < 1e-12);
      QVERIFY((cam.up() - c.up).norm() < 1e-12);
      QVERIFY((cam.target() - meristemBox().center()).norm() < 1e-9);
    }
  }

  void orbitKeepsTargetAndDistance() {
    for (auto mode : {Camera::RotationMode::Turntable, Camera::RotationMode::Arcball}) {
      Camera cam;
      cam.setViewport(800, 600);
      cam.setSceneBounds(meristemBox());
      cam.reset();
      cam.setRotationMode(mode);
      const Eigen::Vector3d target = cam.target(), eye = cam.eye();
      const double distance = cam.distance();
      cam.rotate({400, 300}, {480, 260});
      QVERIFY((cam.target() - target).norm() < 1e-9);
      QVERIFY(std::abs(cam.distance() - distance) < 1e-9);
      QVERIFY(std::abs((cam.eye() - target).norm() - distance) < 1e-9);
      QVERIFY((cam.eye() - eye).norm() > 1.0);  // it did turn
      QVERIFY(std::abs(cam.orientation().norm() - 1) < 1e-12);
    }
  }

  void turntableKeepsTheVerticalUpright() {
    Camera cam;
    cam.setSceneBounds(meristemBox());
    cam.setStandardView(Camera::StandardView::Front);
    cam.rotate({100, 100}, {300, 100});  // horizontal drag: yaw only
    QVERIFY(std::abs(cam.up().z() - 1) < 1e-12);
    // Positive yaw turns the scene's front to the right: a point on the left comes closer, one
    // on the right goes away; the front point moves right on screen.
    cam.setStandardView(Camera::StandardView::Front);
    const double left = cam.project({-40, 0, 21}).z(), right = cam.project({40, 0, 21}).z();
    const double front = cam.project({0, -40, 21}).x();
    cam.rotateBy(10, 0);
    QVERIFY(cam.project({-40, 0, 21}).z() < left);
    QVERIFY(cam.project({40, 0, 21}).z() > right);
    QVERIFY(cam.project({0, -40, 21}).x() > front);
  }

  void panFollowsTheMouseAtTheTargetDepth() {
    Camera cam;
    cam.setViewport(800, 600);
    cam.setSceneBounds(meristemBox());
    cam.reset();
    const Eigen::Vector3d p = cam.target();
    const Eigen::Vector3d before = cam.project(p);
    cam.pan({400, 300}, {450, 270});
    const Eigen::Vector3d after = cam.project(p);
    QVERIFY(std::abs(after.x() - before.x() - 50) < 1e-6);
    QVERIFY(std::abs(after.y() - before.y() + 30) < 1e-6);
  }

  void zoomAtACursorKeepsThePointUnderIt() {
    Camera cam;
    cam.setViewport(800, 600);
    cam.setSceneBounds(meristemBox());
    cam.reset();
    const Eigen::Vector2d cursor(620, 180);
    const Eigen::Vector3d p =
        cam.unproject({cursor.x(), cursor.y(), cam.project(cam.target()).z()});
    const double d = cam.distance();
    cam.zoomAt(cursor, 1.5);
    QVERIFY(std::abs(cam.distance() - d / 1.5) < 1e-9);
    const Eigen::Vector3d q = cam.project(p);
    QVERIFY2(std::abs(q.x() - cursor.x()) < 1e-6 && std::abs(q.y() - cursor.y()) < 1e-6,
             qPrintable(QString("moved to (%1, %2)").arg(q.x()).arg(q.y())));
  }

  void zoomMovesTheEyeTowardsTheTarget() {
    Camera cam;
    cam.setSceneBounds(meristemBox());
    cam.reset();
    const double d = cam.distance();
    cam.zoom(2);
    QVERIFY(std::abs(cam.distance() - d / 2) < 1e-9);
    cam.zoom(1e-9);  // clamped, never absurd
    QVERIFY(cam.distance() <= 100 * 0.5 * meristemBox().diagonal().norm() + 1e-9);
    cam.zoom(-1);  // ignored
    QVERIFY(cam.distance() > 0);
  }
};

TP_GUI_TEST(CameraTest)
#include "test_camera.moc"
