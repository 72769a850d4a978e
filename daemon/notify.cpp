#include "notify.hpp"

#include <systemd/sd-daemon.h>

namespace tomomap::daemon {

Notifier::Notifier() {
  uint64_t usec = 0;
  // Only when WATCHDOG_USEC is meant for this process (WATCHDOG_PID unset or ours).
  if (sd_watchdog_enabled(0, &usec) > 0 && usec > 0) watchdog_every_ = std::chrono::microseconds(usec / 2);
}

void Notifier::send(const std::string& message) { sd_notify(0, message.c_str()); }

void Notifier::ready() {
  send("READY=1");
  last_ping_ = std::chrono::steady_clock::now();
}

void Notifier::reloading() { send("RELOADING=1"); }

void Notifier::stopping() { send("STOPPING=1"); }

void Notifier::status(const std::string& text) {
  if (text == last_status_) return;
  last_status_ = text;
  send("STATUS=" + text);
}

void Notifier::tick() {
  if (watchdog_every_ == std::chrono::steady_clock::duration::zero()) return;
  const auto now = std::chrono::steady_clock::now();
  if (now - last_ping_ < watchdog_every_) return;
  last_ping_ = now;
  send("WATCHDOG=1");
}

}  // namespace tomomap::daemon
