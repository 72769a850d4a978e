#pragma once
#include <optional>
#include <string>

#include "core/types.hpp"

namespace tomomap {

/// PCL's PCD reader maps the file and trusts the sizes it declares: a truncated
/// binary file, or a binary_compressed one whose payload is damaged, crashes it
/// (seen with PCL 1.13). This reads the header and checks that the data the
/// header promises is present and decompresses, before PCL touches the file.
/// Throws InputError naming the file and the problem.
///
/// Where the check has the data in hand anyway (binary and binary_compressed
/// files whose x, y and z are single floats or doubles, i.e. what PCL and
/// most SLAM tools write) it returns the points too: reading them through
/// PCL's generic blob afterwards decompressed the file a second time and
/// held two more copies (docs/results.md, "Loading"). Otherwise (ascii,
/// other field types) nullopt: PCL reads it, through pcl_module.hpp, so the
/// common files never load PCL's io at all.
std::optional<Points> checkAndReadPcd(const std::string& path);

}  // namespace tomomap
