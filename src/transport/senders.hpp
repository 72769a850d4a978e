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

/// The agent a participant speaks for, or why it speaks for none.
struct Binding {
  std::optional<std::string> agent;
  std::string refusal;  ///< when there is no agent
};

/// `cert_subject`: the subject of the participant's authenticated certificate
/// (security on), in OpenSSL's one-line ("/O=x/CN=alpha") or RFC 2253 form.
Binding bindParticipant(const std::string& participant_name, const std::optional<std::string>& cert_subject);

/// The common name (CN) in a subject of either form; none if it has none.
std::optional<std::string> commonName(const std::string& subject);

/// Participants known to speak for an agent, by GUID prefix (12 bytes).
/// Written by discovery, read by every reader's listener: thread-safe.
class SenderDirectory {
 public:
  using Prefix = std::array<uint8_t, 12>;
  void bind(const Prefix& participant, const std::string& agent);
  void forget(const Prefix& participant);
  std::optional<std::string> agentOf(const Prefix& participant) const;

 private:
  mutable std::mutex mutex_;
  std::map<Prefix, std::string> agents_;
};

}  // namespace tomomap::transport
