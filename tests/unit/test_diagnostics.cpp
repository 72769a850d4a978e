// The daemon's health on /diagnostics, read off status.json and the fleet's frame.
#include <gtest/gtest.h>

#include "diagnostics.hpp"

using namespace tomomap;
using tomomap::transport::Diagnostic;

namespace {

/// status.json of alpha with bravo up and their pair agreed.
nlohmann::json healthy() {
  return nlohmann::json::parse(R"({
    "agent": "alpha",
    "map": {"version": "v1", "tilt_deg": 0.4, "slices": 40, "waiting": false, "update_refused": ""},
    "peers": {"bravo": {"alive": true, "version": "v2", "slices_received": 38, "slices_total": 38}},
    "pairs": [{"pair": "alpha<-bravo", "state": "agreed", "by": "alpha"}],
    "pairs_agreed": 1, "sent": {"bytes": 1234}, "rejected_samples": 0, "write_error": ""})");
}

std::string value(const Diagnostic& d, const std::string& key) {
  for (const auto& [k, v] : d.values)
    if (k == key) return v;
  return "(absent)";
}

}  // namespace

TEST(Diagnostics, AHealthyDaemonIsOkAndSaysItsSummary) {
  const Diagnostic d = daemon::diagnosticOf(healthy(), FleetFrame{}, "1/1 peers up");
  EXPECT_EQ(d.level, Diagnostic::ok);
  EXPECT_EQ(d.name, "tomomapd: alpha");
  EXPECT_EQ(d.hardware_id, "alpha");
  EXPECT_EQ(d.message, "1/1 peers up");
  EXPECT_EQ(value(d, "peers up"), "1/1");
  EXPECT_EQ(value(d, "peer bravo"), "up, map v2, 38/38 slices");
  EXPECT_EQ(value(d, "pair alpha<-bravo"), "agreed by alpha");
  EXPECT_EQ(value(d, "map tilt [deg]"), "0.40");
  EXPECT_EQ(value(d, "inconsistent pairs"), "none");
  EXPECT_EQ(value(d, "write error"), "none");
}

TEST(Diagnostics, WhatAnOperatorMustLookAtWarnsAndAWriteErrorIsAnError) {
  nlohmann::json s = healthy();
  s["peers"]["bravo"]["alive"] = false;
  s["pairs"][0] = {{"pair", "alpha<-bravo"}, {"state", "kept"}, {"why", "no reliable match: too few slices"}};
  FleetFrame frame;
  PairVerdict inconsistent;
  inconsistent.pair = {"alpha", "charlie"};
  inconsistent.verdict = Consistency::Inconsistent;
  frame.pairs.push_back(inconsistent);
  Diagnostic d = daemon::diagnosticOf(s, frame, "summary");
  EXPECT_EQ(d.level, Diagnostic::warn);
  EXPECT_EQ(d.message,
            "bravo is down; alpha<-bravo has no reliable match; alpha<-charlie is inconsistent with the fleet's other "
            "transforms");
  EXPECT_EQ(value(d, "pair alpha<-bravo"), "kept: no reliable match: too few slices");
  EXPECT_EQ(value(d, "inconsistent pairs"), "alpha<-charlie");

  s["write_error"] = "No space left on device";
  d = daemon::diagnosticOf(s, frame, "summary");
  EXPECT_EQ(d.level, Diagnostic::error);
  EXPECT_EQ(d.message, "cannot write transforms.json: No space left on device");

  nlohmann::json waiting = healthy();
  waiting["map"]["waiting"] = true;
  waiting["map"].erase("tilt_deg");
  d = daemon::diagnosticOf(waiting, FleetFrame{}, "summary");
  EXPECT_EQ(d.level, Diagnostic::warn);
  EXPECT_EQ(value(d, "map tilt [deg]"), "not measured");
}
