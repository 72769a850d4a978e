#pragma once
#include <string>

namespace tomomap {

/// PCL's PCD reader maps the file and trusts the sizes it declares: a truncated
/// binary file, or a binary_compressed one whose payload is damaged, crashes it
/// (seen with PCL 1.13). This reads the header and checks that the data the
/// header promises is present and decompresses, before PCL touches the file.
/// Throws InputError naming the file and the problem.
void checkPcdIntegrity(const std::string& path);

}  // namespace tomomap
