#pragma once
// Autosave of the session, to recover the curves after a crash. Each running window keeps one
// file, <folder>/session-<pid>.json, beside a lock file held while it runs; a clean exit removes
// both. At start, a session file whose lock nobody holds (its window crashed or was killed) is
// an orphan the user is offered to recover. Writes are atomic (the last good autosave is kept if
// one fails).

#include <QDateTime>
#include <QString>
#include <QStringList>

#include <memory>

class QLockFile;

namespace tp::gui {

class Autosave {
 public:
  /// `folder`: where the files go (created when needed); by default the application's local
  /// data folder ("…/TissueProbe/autosave").
  explicit Autosave(QString folder = defaultFolder());
  ~Autosave();
  Autosave(const Autosave&) = delete;
  Autosave& operator=(const Autosave&) = delete;

  static QString defaultFolder();
  QString folder() const { return folder_; }

  /// This window's autosave file (claimed, and its lock taken, on first use).
  QString path();
  /// Sessions left by windows that did not end cleanly, the newest first.
  QStringList orphans() const;
  /// When an autosave file was written.
  static QDateTime writtenAt(const QString& file);
  /// Removes a file (an orphan recovered or refused, or this window's own when nothing is left
  /// to lose) and its lock.
  void remove(const QString& file);
  /// A clean exit: this window's file and lock go.
  void finish();

 private:
  QString folder_;
  QString own_;
  std::unique_ptr<QLockFile> lock_;
};

}  // namespace tp::gui
