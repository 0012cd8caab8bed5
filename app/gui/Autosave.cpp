#include "Autosave.h"

#include <QCoreApplication>
#include <QDir>
#include <QFile>
#include <QFileInfo>
#include <QLockFile>
#include <QStandardPaths>

#include <algorithm>

namespace tp::gui {

namespace {
QString lockOf(const QString& session) {
  return session.left(session.size() - int(qstrlen(".json"))) + ".lock";
}
}  // namespace

Autosave::Autosave(QString folder) : folder_(std::move(folder)) {}

Autosave::~Autosave() = default;

QString Autosave::defaultFolder() {
  return QStandardPaths::writableLocation(QStandardPaths::AppLocalDataLocation) + "/autosave";
}

QString Autosave::path() {
  if (own_.isEmpty()) {
    QDir().mkpath(folder_);
    own_ = QDir(folder_).filePath(
        QStringLiteral("session-%1.json").arg(QCoreApplication::applicationPid()));
    lock_ = std::make_unique<QLockFile>(lockOf(own_));
    lock_->setStaleLockTime(0);  // held as long as the window runs, however long
    lock_->tryLock(0);
  }
  return own_;
}

QStringList Autosave::orphans() const {
  QFileInfoList files =
      QDir(folder_).entryInfoList({QStringLiteral("session-*.json")}, QDir::Files, QDir::Time);
  QStringList out;
  for (const QFileInfo& f : files) {
    const QString file = f.absoluteFilePath();
    if (!own_.isEmpty() && QFileInfo(own_).absoluteFilePath() == file) continue;
    // A lock we can take is nobody's: its window is gone (QLockFile sees that its process is
    // not running, and takes over the stale lock).
    QLockFile lock(lockOf(file));
    lock.setStaleLockTime(0);
    if (lock.tryLock(0)) {
      lock.unlock();
      out << file;
    }
  }
  return out;
}

QDateTime Autosave::writtenAt(const QString& file) {
  return QFileInfo(file).lastModified();
}

void Autosave::remove(const QString& file) {
  QFile::remove(file);
  if (file == own_) return;  // our lock stays held until finish()
  QFile::remove(lockOf(file));
}

void Autosave::finish() {
  if (own_.isEmpty()) return;
  QFile::remove(own_);
  if (lock_) lock_->unlock();  // removes the lock file
  lock_.reset();
  own_.clear();
}

}  // namespace tp::gui
