#pragma once
// Small pieces of slices ride in the spare room of other samples. Most slices
// of a map are a few hundred bytes (a slice's last part too), and a sample
// leaves as one datagram per receiver with about 140 bytes of IP, UDP and RTPS
// headers: sent alone, 122 of an agent's 260 datagrams were such pieces.
// Pure: what the owner writes and what a receiver takes apart again.
#include <cstddef>
#include <vector>

#include "tomomap.h"

namespace tomomap::transport {

struct Bundles {
  std::vector<wire::SliceFeatures> samples;  ///< what is written, each at most the sample size
  std::vector<size_t> home;                  ///< home[i]: the sample that carries pieces[i]
};

/// The samples that carry `pieces` (every one of the same agent and version,
/// in the order they are to be sent), none over `max_sample_bytes` serialized
/// unless a piece alone is. A piece within the rider bounds goes into the
/// first sample of its group (`group[i]`; all in one group if empty) with
/// room for it (first fit: it leaves no later than it would alone); any other
/// piece starts a sample of its own.
Bundles bundle(const std::vector<wire::SliceFeatures>& pieces, size_t max_sample_bytes,
               const std::vector<int>& group = {});

/// The pieces one received sample carries: its own, then each rider, as
/// samples of the sample's agent and version with no riders.
std::vector<wire::SliceFeatures> unbundle(wire::SliceFeatures&& sample);

}  // namespace tomomap::transport
