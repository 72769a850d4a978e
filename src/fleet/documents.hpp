#pragma once
// The two XML documents DDS Security's access control reads, as tomomap's
// fleets use them (docs/operations.md, "A secure fleet"). Both are signed by
// the fleet CA before a daemon loads them (pki.hpp, smimeSign).
#include <string>

namespace tomomap::fleet {

/// Every tomomap topic's name starts with this; permissions grant on "<prefix>*".
inline constexpr const char* kTopicPrefix = "tomomap/";

/// Domain-wide rules: only authenticated participants join, discovery and
/// every topic's submessages are encrypted and authenticated (AES-GCM), and
/// every topic needs a grant to read or write.
std::string governanceXml();

/// One agent's grant: the certificate subject `subject` may publish and
/// subscribe to tomomap's topics in every domain from `not_before` to
/// `not_after` (UTC, "YYYY-MM-DDThh:mm:ss"); nothing else.
std::string permissionsXml(const std::string& agent, const std::string& subject, const std::string& not_before,
                           const std::string& not_after);

}  // namespace tomomap::fleet
