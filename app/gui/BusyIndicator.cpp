#include "BusyIndicator.h"

namespace tp::gui {

BusyIndicator::BusyIndicator(QWidget* parent) : QLabel(parent) {
  setObjectName("busyIndicator");
  setTextFormat(Qt::RichText);
  timer_.setInterval(250);
  connect(&timer_, &QTimer::timeout, this, &BusyIndicator::refresh);
}

void BusyIndicator::setBusy(bool busy, const QString& what) {
  if (busy && !busy_) since_.start();
  busy_ = busy;
  what_ = what;
  // The text follows on the timer only: the busy/idle flips of a probe drag (one per equilibrium)
  // must not repaint the status bar each time.
  if (!timer_.isActive()) timer_.start();
}

void BusyIndicator::refresh() {
  if (!busy_) {
    timer_.stop();
    if (!text().isEmpty()) setText(QString());
    return;
  }
  // Seconds shown from the second second on: short solves do not flicker a number.
  const qint64 s = since_.elapsed() / 1000;
  setText(QStringLiteral("<span style='color:#d07000'>&#9679;</span> %1%2")
              .arg(what_.toHtmlEscaped(), s >= 1 ? QStringLiteral(" (%1 s)").arg(s) : QString()));
}

}  // namespace tp::gui
