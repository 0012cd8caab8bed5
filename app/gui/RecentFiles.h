#pragma once
// The recently opened tissues and sessions, newest first, kept in QSettings ("recentFiles").

#include <QString>
#include <QStringList>

namespace tp::gui {

class RecentFiles {
 public:
  static constexpr int kMax = 8;
  static QStringList list();
  /// Puts `path` first (absolute), dropping duplicates and files beyond kMax.
  static void add(const QString& path);
  static void clear();
};

}  // namespace tp::gui
