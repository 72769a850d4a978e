#pragma once
// The systemd notify protocol (sd_notify): READY=1 once the daemon serves,
// STATUS= progress lines, RELOADING=1 / STOPPING=1, and watchdog pings when the
// unit sets WatchdogSec. Without NOTIFY_SOCKET (a terminal) every call is a no-op.
#include <chrono>
#include <string>

namespace tomomap::daemon {

class Notifier {
 public:
  Notifier();

  void ready();
  void reloading();
  void stopping();
  /// Sends STATUS= when the text differs from the last one sent.
  void status(const std::string& text);
  /// Pings the watchdog at half its interval; call from the main loop, so a
  /// loop that hangs stops the pings and systemd restarts the service.
  void tick();

 private:
  void send(const std::string& message);

  std::chrono::steady_clock::duration watchdog_every_{};  ///< zero: no watchdog
  std::chrono::steady_clock::time_point last_ping_{};
  std::string last_status_;
};

}  // namespace tomomap::daemon
