#include "Throttle.h"

namespace tp::gui {

Throttle::Throttle(int intervalMs, std::function<void()> action, QObject* parent)
    : QObject(parent), action_(std::move(action)) {
  timer_.setSingleShot(true);
  timer_.setInterval(intervalMs);
  connect(&timer_, &QTimer::timeout, this, [this] {
    if (pending_) fire();
  });
}

void Throttle::request() {
  if (timer_.isActive()) {
    pending_ = true;
    return;
  }
  fire();
}

void Throttle::flush() {
  if (pending_) fire();
}

void Throttle::now() { fire(); }

void Throttle::fire() {
  pending_ = false;
  timer_.start();  // the next call waits for the interval
  action_();
}

}  // namespace tp::gui
