#include "link_budget.hpp"

#include <algorithm>
#include <cmath>

#include "egress_pacer.hpp"

namespace tomomap::transport {

double bytesPerSecond(double kbps) { return kbps * 1000.0 / 8.0; }

size_t bytesPerPeriod(double kbps) {
  return static_cast<size_t>(std::max(1.0, bytesPerSecond(kbps) * kFlowPeriodMs / 1000.0));
}

double pacedKbps(const TransportConfig& c) {
  // A strict pacer lets through at most its rate over any window plus the one
  // datagram that started last: at 250 kbit/s a 1.5 kB datagram is 2.4 kbit/s
  // over 5 s, a 9 kB security handshake 14. 3 % below the budget keeps every
  // 5 s window under it with either.
  constexpr double kBelowBudget = 0.97;
  return kBelowBudget * c.bandwidth_kbps;
}

namespace {
size_t receivers(const TransportConfig& c) { return std::max<size_t>(1, c.peers.size()); }
}  // namespace

double controlShare(const TransportConfig& c) {
  // 13 % with two receivers (peaks 743-770 kbit/s of 800 seen with 10 %), 21 %
  // with four and 29 % with six (with 10 %: peaks up to 921 and 958 kbit/s).
  // Security adds handshakes (about 5 kB each way per peer), secure discovery
  // and a MAC on every heartbeat and acknowledgement: with 13 % for two
  // receivers a peak of 818 kbit/s of 800 was seen.
  constexpr double kBase = 0.05, kPerReceiver = 0.04, kSecure = 0.05, kMax = 0.5;
  return std::min(kMax,
                  kBase + kPerReceiver * static_cast<double>(receivers(c)) + (c.security.enabled() ? kSecure : 0.0));
}

double streamKbps(const TransportConfig& c) {
  return (1 - controlShare(c)) * c.bandwidth_kbps / static_cast<double>(receivers(c));
}

namespace {

/// Datagram bytes besides a sample's CDR that keep the sample one DATA
/// submessage. Fast DDS 2.9 cuts a sample into DATA_FRAGs when its serialized
/// payload (the CDR after a 4-byte encapsulation header) exceeds the message
/// size less 116 bytes it keeps for headers (RTPS header, INFO_DST, INFO_TS,
/// a DATA_FRAG header, a piggybacked HEARTBEAT) and less the 60-byte
/// statistics submessage Debian's build ends every message with. 16 bytes of
/// margin. (A reserve of 160 had every full sample cut in two, 1,452 and 176
/// bytes on the link; 128 plus a 256-byte sample header before left 220 bytes
/// of every full datagram empty.)
constexpr size_t kRtpsOverhead = 116 + 60 + 4 + 16;
/// What DDS Security adds to a sample with metadata_protection_kind ENCRYPT:
/// SEC_PREFIX (24 bytes), SEC_POSTFIX (a 16-byte MAC and its count) and the
/// encrypted body's framing, with a margin.
constexpr size_t kSecurityOverhead = 64;

size_t overhead(bool secure) { return kRtpsOverhead + (secure ? kSecurityOverhead : 0); }

}  // namespace

namespace {

/// The slice stream's bytes written per second (each then reaches every receiver).
double streamBytesPerSecond(const TransportConfig& c) {
  return bytesPerSecond(streamKbps(c) * static_cast<double>(receivers(c)));
}

}  // namespace

/// The largest slice sample's datagram, its RTPS headers included: a
/// kSamplesPerPeriod-th of a period's bytes (one sample per period as at
/// first lost up to half of it). Thin budgets: one Ethernet-sized datagram
/// (each datagram costs its headers; smaller samples paid them more often),
/// and the period grows instead (flowBaseMs). And no sample may exceed one
/// UDP datagram.
size_t sampleDatagramBytes(double kbps) {
  constexpr size_t kDatagram = 60000;
  return std::clamp<size_t>(bytesPerPeriod(kbps) / kSamplesPerPeriod, kUdpPayloadInOneFrame, kDatagram);
}

size_t maxSampleBytes(double kbps, bool secure) { return sampleDatagramBytes(kbps) - overhead(secure); }

int flowBaseMs(const TransportConfig& c) {
  const double sample = static_cast<double>(maxSampleBytes(c.bandwidth_kbps, c.security.enabled()));
  return std::max(kFlowPeriodMs,
                  static_cast<int>(std::ceil(1000.0 * kSamplesPerPeriod * sample / streamBytesPerSecond(c))));
}

int flowPeriodMs(const TransportConfig& c) { return flowBaseMs(c) * static_cast<int>(receivers(c)); }

size_t flowBytesPerPeriod(const TransportConfig& c) {
  // The controller counts whole RTPS messages, headers and all: the stream's
  // payload of a base period, each full sample with its message's headers.
  const double message_per_payload = static_cast<double>(sampleDatagramBytes(c.bandwidth_kbps)) /
                                     static_cast<double>(maxSampleBytes(c.bandwidth_kbps, c.security.enabled()));
  return static_cast<size_t>(streamBytesPerSecond(c) * flowBaseMs(c) / 1000.0 * message_per_payload);
}

}  // namespace tomomap::transport
