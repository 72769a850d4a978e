#pragma once
// Agreed transforms on the wire (TransformEstimate) and back.
#include "rejection.hpp"
#include "results/agreed_transform.hpp"
#include "tomomap.h"

namespace tomomap::transport {

wire::TransformEstimate toWire(const AgreedTransform& t);

/// Checks a received estimate (ordered pair, finite transform) and converts it;
/// the 4x4 matrix is rebuilt from x, y, z, yaw, never taken from the sample.
Rejection fromWire(const wire::TransformEstimate& e, AgreedTransform& out);

}  // namespace tomomap::transport
