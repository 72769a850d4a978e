#pragma once
// Where time starts in the tests of clock-injected parts (PairBoard, MapSender,
// PeerMaps, RejectionLog): every instant they are handed is t0 plus a duration.
// One definition for all of them, since the unity build compiles them together.
#include "clock.hpp"

inline const tomomap::daemon::Clock::time_point t0{};
