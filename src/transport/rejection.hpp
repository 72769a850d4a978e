#pragma once
// Why a received announcement, sample or estimate was refused: a code the
// daemon counts and a text it logs.
#include <cstdint>
#include <string>

namespace tomomap::transport {

enum class Reject {
  None,
  BadGridOrOrigin,  ///< announcement: grid not positive or origin not finite
  BadRaster,        ///< announcement: width or height 0 or above the image cap
  BadSliceCount,
  SliceOutOfRange,  ///< announcement lists a slice out of range or twice
  BadPartCount,
  OversizedSlice,  ///< announcement: a slice larger than any real slice can be
  BadFeatureSettings,
  VersionMismatch,  ///< announcement whose version is not the hash of its content
  BadUnseen,        ///< announcement: an unseen run out of range, out of order or over a slice it sends
  UnpairedUnseen,   ///< announcement: an unseen run without its last slice (an odd number of bounds)
  BadUp,            ///< announcement or estimate: an up that is not a unit vector within kMaxLevelable of z
  NotAnnounced,     ///< sample of a slice the announcement does not list
  PartNumbering,
  MixedEncoding,
  KeypointOutside,
  LargerThanAnnounced,
  ChecksumMismatch,
  NotInflating,   ///< occupancy that does not inflate to the announced raster
  OverBudget,     ///< a peer's map that would take more memory than peer_memory_mb
  UnorderedPair,  ///< estimate whose target id is not below its source id
  NonFiniteTransform,
  NotRigid,    ///< estimate whose whole transform is not a rotation and a translation
  BadQuality,  ///< estimate: a lead that is not a number >= 0, or a search tomomap does not have
};

struct Rejection {
  Reject why = Reject::None;
  int32_t slice = -1;  ///< the slice concerned, where there is one

  explicit operator bool() const { return why != Reject::None; }
  bool operator==(Reject r) const { return why == r; }
  std::string text() const;
};

}  // namespace tomomap::transport
