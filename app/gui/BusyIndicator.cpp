#include "BusyIndicator.h"

namespace tp::gui {

BusyIndicator::BusyIndicator(QWidget* parent) : QLabel(parent) {
  setObjectName("busyIndicator");
  setTextFormat(Qt::RichText);
  timer_.setInterval(500);
  connect(&timer_, &QTimer::timeout, this, &BusyIndicator::refresh);
}

void BusyIndicator::setBusy(bool busy, const QString& what) {
  if (busy && !busy_) since_.start();
  busy_ = busy;
  what_ = what;
  if (busy)
    timer_.start();
  else
    timer_.stop();
  refresh();
}

void BusyIndicator::refresh() {
  if (!busy_) {
    setText(QString());
    return;
  }
  // Seconds shown from the second second on: short solves do not flicker a number.
  const qint64 s = since_.elapsed() / 1000;
  setText(QStringLiteral("<span style='color:#d07000'>&#9679;</span> %1%2")
              .arg(what_.toHtmlEscaped(), s >= 1 ? QStringLiteral(" (%1 s)").arg(s) : QString()));
}

}  // namespace tp::gui
