#pragma once
// What the daemon leaves on disk for users and for `tomomap status`:
// transforms.json (the agreed transforms) and status.json (progress), each
// replaced atomically (write a temporary file, then rename) so a reader never
// sees half a file, even if the daemon is killed mid-write.
#include <nlohmann/json.hpp>
#include <string>

namespace tomomap::daemon {

void writeJsonAtomically(const std::string& path, const nlohmann::json& j);

}  // namespace tomomap::daemon
