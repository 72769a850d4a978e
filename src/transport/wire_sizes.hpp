#pragma once
// Sizes of what travels, for budgets and reports. No DDS headers: the tool's
// eval includes this to estimate payloads without linking the network stack.
#include <cstddef>

namespace tomomap::transport {

/// Payload bytes of one feature on the wire: pixel u and v (2 bytes each) and
/// the 256-bit ORB descriptor.
constexpr size_t kFeatureBytes = 2 + 2 + 32;

}  // namespace tomomap::transport
