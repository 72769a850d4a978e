#pragma once
// The link budget: how an agent's bandwidth budget is shared between control
// traffic and the slice stream's receivers, and what that makes of the flow
// controller's period and bytes, the pacer's rate and the largest sample.
// Pure arithmetic on the config, with the constants measured for it
// (docs/protocol.md, "Bandwidth").
#include <cstddef>

#include "transport_config.hpp"

namespace tomomap::transport {

/// Flow-controller period [ms] with one receiver, unless it would hold fewer
/// than kSamplesPerPeriod samples (flowBaseMs).
constexpr int kFlowPeriodMs = 100;
/// The controller sends whole samples only, and one that does not fit the
/// rest of a period waits for the next: with at least this many samples a
/// period, at most about an eighth of the stream's rate goes unused.
constexpr int kSamplesPerPeriod = 8;

/// Share of the budget left to control traffic (discovery, heartbeats,
/// acknowledgements, requests, claims, estimates, announcements), which does
/// not pass the flow controller: the slice data gets the rest. It grows with
/// the receivers: each new peer costs a burst of discovery and announcements
/// (about 20 kB in the first seconds, measured) on top of a steady few kbit/s.
double controlShare(const TransportConfig& c);

/// The budget is total egress, and every slice sample goes to every receiver
/// (one unicast datagram each), so the slice stream itself may use
/// (1 - controlShare) / receivers of it [kbit/s] of samples' serialized
/// payload. Receivers are the configured peers (at least one).
double streamKbps(const TransportConfig& c);

/// The flow controller's period [ms] with one receiver: kFlowPeriodMs, or
/// longer where the stream's payload in it would hold fewer than
/// kSamplesPerPeriod of the largest samples (thin budgets, where a sample is
/// one Ethernet datagram: at 250 kbit/s with four receivers, samples of
/// 1.3 kB and 100 ms, one sample fitted where two did not and the stream ran
/// at half its rate).
int flowBaseMs(const TransportConfig& c);
/// The flow controller's period [ms]: flowBaseMs stretched by the receivers.
/// The stream's bytes of one base period leave per period as samples, each
/// reaching every receiver, so the period stretches with the receivers
/// instead of the bytes per period shrinking (a sample must fit one period's
/// bytes, and the sample size must not depend on the fleet).
int flowPeriodMs(const TransportConfig& c);
/// Bytes the flow controller lets out per period (each message then reaching
/// every receiver): the stream's payload of one base period plus the RTPS
/// headers of the messages that carry it. The controller counts whole
/// messages; counted as payload, the headers (about 120 bytes a full sample)
/// and a period's unused rest had it pass only 86 % of the stream, below what
/// the daemon fed it (MapSender: 85 %), so its queue of new samples never ran
/// dry and repairs, which it serves only then, waited until the whole map had
/// left (10 % loss: a reader stuck 16 s behind one lost sample).
size_t flowBytesPerPeriod(const TransportConfig& c);
/// kbit/s as bytes per second.
double bytesPerSecond(double kbps);

/// Bytes the flow controller may send per period.
size_t bytesPerPeriod(double bandwidth_kbps);

/// The rate every datagram the participant sends is paced to [kbit/s]: a hard
/// cap just under the budget, beneath the flow controller's share for the
/// slice stream (EgressPacer).
double pacedKbps(const TransportConfig& c);

/// The largest slice sample's RTPS message, headers included (one UDP payload).
size_t sampleDatagramBytes(double bandwidth_kbps);

/// Largest slice sample: a fraction of the per-period budget, so that the
/// controller, which sends only whole samples per period, fills each period
/// nearly to the budget; but at thin budgets one full Ethernet datagram, since
/// each datagram pays its headers (docs/protocol.md, "Sample size"); less
/// with security, whose framing each datagram carries too.
size_t maxSampleBytes(double bandwidth_kbps, bool secure);

}  // namespace tomomap::transport
