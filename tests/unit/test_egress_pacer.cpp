#include <gtest/gtest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include "transport/egress_pacer.hpp"

using tomomap::transport::EgressPacer;
using tomomap::transport::wireBytes;
using Clock = EgressPacer::Clock;
using namespace std::chrono_literals;

TEST(EgressPacer, WireBytesCountEveryHeaderAndFragment) {
  EXPECT_EQ(wireBytes(100), 100u + 8 + 20 + 14);
  EXPECT_EQ(wireBytes(1472), 1514u);               // one full Ethernet frame
  EXPECT_EQ(wireBytes(1473), 1473u + 8 + 2 * 34);  // two fragments
  EXPECT_EQ(wireBytes(9000), 9000u + 8 + 7 * 34);  // a security handshake: seven
}

TEST(EgressPacer, NoWindowHoldsMoreThanTheRateAndOneDatagram) {
  // Bursts of random sizes at random moments, as discovery and the stream
  // arrive together; each datagram leaves when the link is free.
  const double rate = 100000;  // 800 kbit/s
  EgressPacer pacer(rate);
  std::mt19937 rng(7);
  std::uniform_int_distribution<size_t> size(60, 9000);
  std::exponential_distribution<double> gap(500.0);  // 500 a second on average: far above the rate
  const auto start = Clock::time_point{} + 1h;
  auto now = start;
  std::vector<std::pair<double, size_t>> sent;  // (seconds from start, bytes)
  size_t largest = 0;
  for (int i = 0; i < 5000; ++i) {
    now += std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(gap(rng)));
    const size_t bytes = size(rng);
    const auto at = pacer.freeAt(now);
    ASSERT_GE(at, now);
    pacer.sent(bytes, at);
    sent.emplace_back(std::chrono::duration<double>(at - start).count(), bytes);
    largest = std::max(largest, bytes);
  }
  for (const double window : {0.1, 1.0, 5.0}) {
    size_t in_window = 0;
    for (size_t a = 0, b = 0; a < sent.size(); ++a) {
      while (b < sent.size() && sent[b].first < sent[a].first + window) in_window += sent[b++].second;
      EXPECT_LE(static_cast<double>(in_window), rate * window + static_cast<double>(largest)) << "window " << window;
      in_window -= sent[a].second;
    }
  }
  EXPECT_EQ(pacer.sentBytes(),
            std::accumulate(sent.begin(), sent.end(), size_t{0}, [](size_t s, const auto& d) { return s + d.second; }));
}

TEST(EgressPacer, AnIdleLinkSavesNoCredit) {
  EgressPacer pacer(1000);  // 1 kB/s
  const auto start = Clock::time_point{} + 1h;
  EXPECT_EQ(pacer.freeAt(start), start);
  pacer.sent(100, start);
  // Ten seconds idle, then a burst: still one every 100 ms.
  const auto later = start + 10s;
  EXPECT_EQ(pacer.freeAt(later), later);
  pacer.sent(100, later);
  EXPECT_EQ(pacer.freeAt(later), later + 100ms);
  pacer.sent(100, later + 100ms);
  EXPECT_EQ(pacer.freeAt(later), later + 200ms);
}

TEST(EgressPacer, ADatagramThatCannotLeaveBeforeItsDeadlineIsNotSent) {
  EgressPacer pacer(1000);
  pacer.sent(1000000, Clock::now());  // the link is busy for 1000 s
  bool called = false;
  EXPECT_FALSE(pacer.send(Clock::now() + 1ms, [&] {
    called = true;
    return size_t{100};
  }));
  EXPECT_FALSE(called);
  EXPECT_EQ(pacer.refusedDatagrams(), 1u);
  EXPECT_EQ(pacer.sentBytes(), 1000000u);
}

TEST(EgressPacer, OnlyWhatLeftOccupiesTheLink) {
  // A socket that sends nothing (another socket's destination) books nothing.
  EgressPacer pacer(1000);
  EXPECT_TRUE(pacer.send(Clock::now() + 1h, [] { return size_t{0}; }));
  EXPECT_EQ(pacer.sentBytes(), 0u);
  const auto now = Clock::now();
  EXPECT_LE(pacer.freeAt(now), now);
  const auto before = Clock::now();
  EXPECT_TRUE(pacer.send(Clock::now() + 1h, [] { return size_t{500}; }));
  EXPECT_EQ(pacer.sentBytes(), 500u);
  EXPECT_GE(pacer.freeAt(before), before + 500ms);  // busy for 0.5 s after it left
}

TEST(EgressPacer, RefusesANonPositiveRate) {
  EXPECT_THROW(EgressPacer(0), std::invalid_argument);
  EXPECT_THROW(EgressPacer(-5), std::invalid_argument);
}
