#include "egress_pacer.hpp"

#include <algorithm>
#include <stdexcept>
#include <thread>

namespace tomomap::transport {

size_t wireBytes(size_t udp_payload) {
  const size_t ip_payload = udp_payload + kUdpHeader;
  const size_t per_fragment = kEthernetPayload - kIpv4Header;  // 1480, a multiple of 8 as IPv4 requires
  const size_t fragments = std::max<size_t>(1, (ip_payload + per_fragment - 1) / per_fragment);
  return ip_payload + fragments * (kIpv4Header + kEthernetHeader);
}

EgressPacer::EgressPacer(double bytes_per_s) : bytes_per_s_(bytes_per_s) {
  if (!(bytes_per_s > 0)) throw std::invalid_argument("the egress pacer needs a positive rate");
}

bool EgressPacer::send(Clock::time_point deadline, const std::function<size_t()>& send_one) {
  std::unique_lock turn(turn_, std::defer_lock);
  const auto start = turn.try_lock_until(deadline) ? freeAt(Clock::now()) : Clock::time_point::max();
  if (start > deadline) {
    std::lock_guard lock(state_);
    ++refused_;
    return false;
  }
  std::this_thread::sleep_until(start);
  const auto at = Clock::now();
  if (const size_t bytes = send_one()) sent(bytes, at);
  return true;
}

EgressPacer::Clock::time_point EgressPacer::freeAt(Clock::time_point now) const {
  std::lock_guard lock(state_);
  return std::max(now, free_at_);
}

void EgressPacer::sent(size_t wire_bytes, Clock::time_point at) {
  std::lock_guard lock(state_);
  free_at_ = std::max(at, free_at_) + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                          static_cast<double>(wire_bytes) / bytes_per_s_));
  sent_bytes_ += wire_bytes;
}

uint64_t EgressPacer::sentBytes() const {
  std::lock_guard lock(state_);
  return sent_bytes_;
}

uint64_t EgressPacer::refusedDatagrams() const {
  std::lock_guard lock(state_);
  return refused_;
}

}  // namespace tomomap::transport
