#include "TestMain.h"

#include <QApplication>
#include <QSettings>
#include <QTemporaryDir>
#include <QTest>

#include <clocale>

#include "Resources.h"

namespace tp::gui::test {

std::vector<Factory>& registry() {
  static std::vector<Factory> r;
  return r;
}

}  // namespace tp::gui::test

int main(int argc, char** argv) {
  // A temporary configuration folder: the tests must not read or write the user's settings.
  QTemporaryDir config;
  qputenv("XDG_CONFIG_HOME", config.path().toUtf8());
  qputenv("XDG_DATA_HOME", (config.path() + "/data").toUtf8());  // autosaves
  qputenv("XDG_CACHE_HOME", (config.path() + "/cache").toUtf8());  // map results
  tp::gui::setDefaultSurfaceFormat();
  QApplication app(argc, argv);
  std::setlocale(LC_NUMERIC, "C");
  QApplication::setOrganizationName("TissueProbeTest");
  QApplication::setApplicationName("TissueProbeTest");
  QApplication::setApplicationVersion(TP_VERSION);
  QSettings::setPath(QSettings::NativeFormat, QSettings::UserScope, config.path());
  QSettings::setPath(QSettings::IniFormat, QSettings::UserScope, config.path());
  // TP_GUI_TEST_CLASS=CameraTest runs one class (the arguments then select its functions).
  const QByteArray only = qgetenv("TP_GUI_TEST_CLASS");
  int failures = 0;
  for (const auto& make : tp::gui::test::registry()) {
    const std::unique_ptr<QObject> t = make();
    if (!only.isEmpty() && only != t->metaObject()->className()) continue;
    failures += QTest::qExec(t.get(), argc, argv);
  }
  return failures == 0 ? 0 : 1;
}
