#include "senders.hpp"

#include "participant.hpp"

namespace tomomap::transport {

std::string participantName(const std::string& agent) { return "tomomapd/" + agent; }

std::optional<std::string> commonName(const std::string& subject) {
  // An attribute starts the text or follows its separator ('/' one-line, ',' RFC 2253).
  for (size_t at = subject.find("CN="); at != std::string::npos; at = subject.find("CN=", at + 1)) {
    if (at != 0 && subject[at - 1] != '/' && subject[at - 1] != ',') continue;
    const size_t begin = at + 3;
    const size_t end = subject.find_first_of("/,", begin);
    return subject.substr(begin, end == std::string::npos ? std::string::npos : end - begin);
  }
  return std::nullopt;
}

Binding bindParticipant(const std::string& participant_name, const std::optional<std::string>& cert_subject) {
  const std::string prefix = participantName("");
  if (participant_name.rfind(prefix, 0) != 0 || participant_name.size() == prefix.size())
    return {participant_name, std::nullopt, "its name '" + participant_name + "' is not a tomomapd's"};
  const std::string agent = participant_name.substr(prefix.size());
  if (!cert_subject) return {participant_name, agent, ""};
  const auto cn = commonName(*cert_subject);
  if (!cn)
    return {participant_name, std::nullopt,
            "it names itself " + agent + " but its certificate (" + *cert_subject + ") has no CN"};
  if (*cn != agent)
    return {participant_name, std::nullopt, "it names itself " + agent + " but is authenticated as " + *cn};
  return {participant_name, agent, ""};
}

std::optional<Binding> Admission::discovered(const ParticipantKey& p, const std::string& name,
                                             const std::string& subject) {
  Candidate& c = candidates_[p];
  c.name = name;
  c.subject = subject;
  c.discovered = true;
  return settle(p);
}

std::optional<Binding> Admission::authenticated(const ParticipantKey& p) {
  candidates_[p].authenticated = true;
  return settle(p);
}

std::string Admission::failed(const ParticipantKey& p) {
  Candidate& c = candidates_[p];
  c.authenticated = false;
  return c.name.empty() ? "a participant" : c.name;
}

void Admission::gone(const ParticipantKey& p) { candidates_.erase(p); }

std::optional<Binding> Admission::settle(const ParticipantKey& p) {
  const Candidate c = candidates_[p];
  if (!c.discovered || (secure_ && !c.authenticated)) return std::nullopt;
  candidates_.erase(p);
  return bindParticipant(c.name, secure_ ? std::optional<std::string>(c.subject) : std::nullopt);
}

void SenderDirectory::bind(const ParticipantKey& participant, const std::string& agent) {
  std::lock_guard<std::mutex> lock(mutex_);
  agents_[participant] = agent;
}

void SenderDirectory::forget(const ParticipantKey& participant) {
  std::lock_guard<std::mutex> lock(mutex_);
  agents_.erase(participant);
}

std::optional<std::string> SenderDirectory::agentOf(const ParticipantKey& participant) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const auto it = agents_.find(participant);
  if (it == agents_.end()) return std::nullopt;
  return it->second;
}

}  // namespace tomomap::transport
