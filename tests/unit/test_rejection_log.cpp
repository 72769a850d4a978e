// Rejected samples are logged without flooding: the first from a sender at
// once, the rest as one summary per sender per minute.
#include <gtest/gtest.h>

#include "clock_start.hpp"
#include "rejection_log.hpp"

using namespace tomomap::daemon;
using namespace std::chrono_literals;

TEST(RejectionLog, TheFirstIsLoggedTheRestSummarisedOncePerMinute) {
  RejectionLog log;
  ASSERT_TRUE(log.note("mallory", "slice 7 not announced", t0).has_value());
  size_t lines = 0;
  for (int i = 0; i < 100000; ++i)
    lines += log.note("mallory", i % 2 ? "slice 7 not announced" : "bad part", t0 + 10ms * (i % 100)).has_value();
  EXPECT_EQ(lines, 0u) << "100,000 more within the minute: no line each";
  EXPECT_TRUE(log.due(t0 + 30s).empty()) << "the minute is not over";
  const auto summary = log.due(t0 + 60s);
  ASSERT_EQ(summary.size(), 1u);
  EXPECT_NE(summary[0].find("100000 more samples from mallory"), std::string::npos) << summary[0];
  EXPECT_NE(summary[0].find("most often"), std::string::npos);
  EXPECT_TRUE(log.due(t0 + 200s).empty()) << "nothing new: no line";
}

TEST(RejectionLog, SendersAreCountedApartAndAQuietSenderIsLoggedAtOnceAgain) {
  RejectionLog log;
  EXPECT_TRUE(log.note("bravo", "crc", t0).has_value());
  EXPECT_TRUE(log.note("charlie", "crc", t0).has_value()) << "another sender's first";
  EXPECT_FALSE(log.note("bravo", "crc", t0 + 1s).has_value());
  EXPECT_EQ(log.due(t0 + 61s).size(), 1u) << "only bravo had more";
  EXPECT_TRUE(log.note("charlie", "crc", t0 + 5min).has_value()) << "quiet for minutes: logged at once";
}
