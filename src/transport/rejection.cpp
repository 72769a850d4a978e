#include "rejection.hpp"

#include "core/gravity.hpp"
#include "core/text.hpp"

namespace tomomap::transport {

std::string Rejection::text() const {
  switch (why) {
    case Reject::None:
      return "";
    case Reject::BadGridOrOrigin:
      return "announcement with a bad grid or origin";
    case Reject::BadRaster:
      return "announcement with a bad raster size";
    case Reject::BadSliceCount:
      return "announcement with a bad slice count";
    case Reject::SliceOutOfRange:
      return "announcement lists slice " + std::to_string(slice) + " out of range or twice";
    case Reject::BadPartCount:
      return "announcement with a bad part count";
    case Reject::OversizedSlice:
      return "announcement with an oversized slice";
    case Reject::BadFeatureSettings:
      return "announcement with feature settings out of range";
    case Reject::VersionMismatch:
      return "announcement whose version does not match its content";
    case Reject::UnpairedUnseen:
      return "announcement with an unseen run without its last slice";
    case Reject::BadUnseen:
      return "announcement with unseen slices out of range, out of order or sent (from slice " + std::to_string(slice) +
             ")";
    case Reject::BadUp:
      return "an up direction that is not a unit vector within " + fixed(degrees(kMaxLevelable), 0) + " deg of z";
    case Reject::NotAnnounced:
      return "slice " + std::to_string(slice) + " was not announced";
    case Reject::PartNumbering:
      return "part numbering differs from the announcement";
    case Reject::MixedEncoding:
      return "sample mixes encodings";
    case Reject::KeypointOutside:
      return "keypoint outside the raster";
    case Reject::LargerThanAnnounced:
      return "slice larger than announced";
    case Reject::ChecksumMismatch:
      return "slice checksum mismatch";
    case Reject::NotInflating:
      return "occupancy does not inflate to the announced raster";
    case Reject::OverBudget:
      return "the map would take more memory than peer_memory_mb allows";
    case Reject::UnorderedPair:
      return "estimate with an unordered pair";
    case Reject::NonFiniteTransform:
      return "estimate with a non-finite transform";
    case Reject::NotRigid:
      return "estimate whose whole transform is not rigid";
    case Reject::BadQuality:
      return "estimate with a lead that is not a number >= 0 or an unknown search";
  }
  return "unknown rejection";
}

}  // namespace tomomap::transport
