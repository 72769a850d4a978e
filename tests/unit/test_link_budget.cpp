// The link budget (transport/link_budget.hpp): what a robot's bandwidth
// budget allows each kind of traffic, for the budgets and fleets robots use.
#include <gtest/gtest.h>

#include "transport/egress_pacer.hpp"
#include "transport/link_budget.hpp"

using namespace tomomap::transport;

namespace {

TransportConfig fleetOf(double kbps, size_t peers, bool secure) {
  TransportConfig c;
  c.bandwidth_kbps = kbps;
  for (size_t i = 0; i < peers; ++i) c.peers.push_back({"p" + std::to_string(i), "10.0.0.1", 7400});
  if (secure) c.security.ca = "ca.pem";
  return c;
}

}  // namespace

TEST(LinkBudget, TheStreamAndTheControlTrafficShareTheBudgetAndThePacerHoldsIt) {
  for (double kbps : {64.0, 250.0, 800.0, 10000.0})
    for (size_t peers : {1u, 2u, 4u, 6u})
      for (bool secure : {false, true}) {
        SCOPED_TRACE(std::to_string(kbps) + " kbit/s, " + std::to_string(peers) + " peers" +
                     (secure ? ", secure" : ""));
        const TransportConfig c = fleetOf(kbps, peers, secure);
        // Every sample reaches every receiver: the stream's share times the
        // receivers plus control's is the whole budget.
        EXPECT_NEAR(streamKbps(c) * static_cast<double>(peers) + controlShare(c) * kbps, kbps, 1e-9 * kbps);
        EXPECT_GT(controlShare(c), 0.0);
        EXPECT_LE(controlShare(c), 0.5) << "the slice stream keeps half at least";
        EXPECT_LT(pacedKbps(c), kbps) << "the pacer caps just under the budget";
        EXPECT_GT(pacedKbps(c), 0.9 * kbps);
      }
}

TEST(LinkBudget, ASampleIsOneDatagramAndEveryPeriodHoldsSeveral) {
  for (double kbps : {64.0, 250.0, 800.0, 10000.0, 1e6})
    for (size_t peers : {1u, 4u})
      for (bool secure : {false, true}) {
        SCOPED_TRACE(std::to_string(kbps) + " kbit/s, " + std::to_string(peers) + " peers" +
                     (secure ? ", secure" : ""));
        const TransportConfig c = fleetOf(kbps, peers, secure);
        const size_t datagram = sampleDatagramBytes(kbps), sample = maxSampleBytes(kbps, secure);
        EXPECT_GE(datagram, kUdpPayloadInOneFrame) << "never smaller than one Ethernet frame's payload";
        EXPECT_LE(datagram, 65507u) << "one UDP datagram";
        EXPECT_LT(sample, datagram) << "the sample leaves room for its RTPS headers";
        EXPECT_GE(flowBaseMs(c), kFlowPeriodMs);
        EXPECT_EQ(flowPeriodMs(c), flowBaseMs(c) * static_cast<int>(peers));
        // A period's bytes hold kSamplesPerPeriod of the largest samples, headers and all.
        EXPECT_GE(flowBytesPerPeriod(c) + datagram, kSamplesPerPeriod * datagram);
      }
  // Security's framing costs each sample bytes of its own.
  EXPECT_LT(maxSampleBytes(800, true), maxSampleBytes(800, false));
}
