#pragma once
// Who sent a sample. Every sample names an agent (the announcer, the
// requester, the claimer, the computer); it counts only if the participant
// that wrote it speaks for that agent. A participant speaks for the agent in
// its name ("tomomapd/<agent>"); with DDS Security only if its authenticated
// certificate's common name is that agent too (docs/protocol.md, "Identity").
#include <array>
#include <cstdint>
#include <map>
#include <mutex>
#include <optional>
#include <string>

namespace tomomap::transport {

/// A participant's GUID prefix: the key of everything below.
using ParticipantKey = std::array<uint8_t, 12>;

/// The agent a participant speaks for, or why it speaks for none.
struct Binding {
  std::string participant;  ///< its name
  std::optional<std::string> agent;
  std::string refusal;  ///< when there is no agent
};

/// `cert_subject`: the subject of the participant's authenticated certificate
/// (security on), in OpenSSL's one-line ("/O=x/CN=alpha") or RFC 2253 form.
Binding bindParticipant(const std::string& participant_name, const std::optional<std::string>& cert_subject);

/// The common name (CN) in a subject of either form; none if it has none.
std::optional<std::string> commonName(const std::string& subject);

/// Decides when a participant is bound. With security, discovery (its
/// announcement: plain text, the identity token unproven) and authentication
/// are reported apart and in either order, and a handshake that fails can be
/// followed by one that succeeds (handshakes of two peers cross): a
/// participant is bound once it was discovered and its latest handshake
/// succeeded. Without security, on discovery. Not thread-safe.
class Admission {
 public:
  explicit Admission(bool secure) : secure_(secure) {}
  /// The binding to make now, if any.
  std::optional<Binding> discovered(const ParticipantKey& p, const std::string& name, const std::string& subject);
  std::optional<Binding> authenticated(const ParticipantKey& p);
  /// A failed handshake: the name to report it under ("a participant" if unknown).
  std::string failed(const ParticipantKey& p);
  void gone(const ParticipantKey& p);

 private:
  struct Candidate {
    std::string name, subject;
    bool discovered = false, authenticated = false;
  };
  std::optional<Binding> settle(const ParticipantKey& p);
  const bool secure_;
  std::map<ParticipantKey, Candidate> candidates_;  ///< discovered or authenticated, not bound yet
};

/// Participants known to speak for an agent, by GUID prefix (12 bytes).
/// Written by discovery, read by every reader's listener: thread-safe.
class SenderDirectory {
 public:
  void bind(const ParticipantKey& participant, const std::string& agent);
  void forget(const ParticipantKey& participant);
  std::optional<std::string> agentOf(const ParticipantKey& participant) const;

 private:
  mutable std::mutex mutex_;
  std::map<ParticipantKey, std::string> agents_;
};

}  // namespace tomomap::transport
