// Which agent a participant speaks for: its name, and with security the CN
// of the certificate it authenticated with, which must agree.
#include <gtest/gtest.h>

#include "transport/senders.hpp"

using namespace tomomap::transport;

TEST(Senders, CommonNameInEitherSubjectForm) {
  EXPECT_EQ(commonName("/O=tomomap fleet/CN=alpha"), "alpha");
  EXPECT_EQ(commonName("CN=alpha,O=tomomap fleet"), "alpha");
  EXPECT_EQ(commonName("O=x,CN=bravo"), "bravo");
  EXPECT_FALSE(commonName("/O=tomomap fleet").has_value());
  EXPECT_FALSE(commonName("O=ACN=alpha").has_value()) << "CN= inside another value is not an attribute";
}

TEST(Senders, APlainParticipantSpeaksForTheAgentInItsName) {
  EXPECT_EQ(bindParticipant("tomomapd/alpha", std::nullopt).agent, "alpha");
  const Binding stranger = bindParticipant("talker", std::nullopt);
  EXPECT_FALSE(stranger.agent);
  EXPECT_NE(stranger.refusal.find("talker"), std::string::npos);
  EXPECT_FALSE(bindParticipant("tomomapd/", std::nullopt).agent);
}

TEST(Senders, ASecureParticipantSpeaksOnlyForItsCertificatesName) {
  EXPECT_EQ(bindParticipant("tomomapd/alpha", std::string("/O=tomomap fleet/CN=alpha")).agent, "alpha");
  const Binding liar = bindParticipant("tomomapd/alpha", std::string("/O=tomomap fleet/CN=charlie"));
  EXPECT_FALSE(liar.agent);
  EXPECT_NE(liar.refusal.find("authenticated as charlie"), std::string::npos) << liar.refusal;
  EXPECT_EQ(liar.participant, "tomomapd/alpha") << "a refusal names the participant, whichever event settled it";
  EXPECT_FALSE(bindParticipant("tomomapd/alpha", std::string("")).agent) << "no subject: no identity";
}

TEST(Senders, TheDirectoryForgetsAParticipantThatLeft) {
  SenderDirectory d;
  const ParticipantKey p{1, 2, 3};
  d.bind(p, "alpha");
  EXPECT_EQ(d.agentOf(p), "alpha");
  EXPECT_FALSE(d.agentOf(ParticipantKey{9}).has_value());
  d.forget(p);
  EXPECT_FALSE(d.agentOf(p).has_value());
}

TEST(Senders, ASecureParticipantIsBoundOnceDiscoveredAndAuthenticatedInEitherOrder) {
  const ParticipantKey a{1}, b{2};
  Admission desk(/*secure=*/true);
  EXPECT_FALSE(desk.discovered(a, "tomomapd/alpha", "/O=f/CN=alpha")) << "discovery alone proves nothing";
  const auto bound = desk.authenticated(a);
  ASSERT_TRUE(bound);
  EXPECT_EQ(bound->agent, "alpha");
  EXPECT_FALSE(desk.authenticated(b));
  EXPECT_EQ(desk.discovered(b, "tomomapd/bravo", "/O=f/CN=bravo")->agent, "bravo");
}

TEST(Senders, AFailedHandshakeFollowedByASuccessfulOneStillBinds) {
  // Two peers' handshakes crossed: one failed, the next succeeded (seen with
  // three daemons started together; binding was lost for good before).
  const ParticipantKey a{1};
  Admission desk(/*secure=*/true);
  EXPECT_FALSE(desk.discovered(a, "tomomapd/alpha", "/O=f/CN=alpha"));
  EXPECT_EQ(desk.failed(a), "tomomapd/alpha");
  const auto bound = desk.authenticated(a);
  ASSERT_TRUE(bound);
  EXPECT_EQ(bound->agent, "alpha");
}

TEST(Senders, APlainParticipantIsBoundOnDiscovery) {
  Admission desk(/*secure=*/false);
  const auto bound = desk.discovered(ParticipantKey{7}, "tomomapd/alpha", "");
  ASSERT_TRUE(bound);
  EXPECT_EQ(bound->agent, "alpha");
}
