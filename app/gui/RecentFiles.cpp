#include "RecentFiles.h"

#include <QFileInfo>
#include <QSettings>

namespace tp::gui {

namespace {
constexpr const char* kKey = "recentFiles";
}

QStringList RecentFiles::list() {
  return QSettings().value(kKey).toStringList();
}

void RecentFiles::add(const QString& path) {
  if (path.isEmpty()) return;
  const QString abs = QFileInfo(path).absoluteFilePath();
  QStringList files = list();
  files.removeAll(abs);
  files.prepend(abs);
  while (files.size() > kMax) files.removeLast();
  QSettings().setValue(kKey, files);
}

void RecentFiles::clear() {
  QSettings().remove(kKey);
}

}  // namespace tp::gui
