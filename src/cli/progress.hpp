#pragma once
// Progress lines on stderr for long work, shown only on a terminal (or when asked).
#include <string>

#include "core/matcher.hpp"

namespace tomomap::cli {

/// A Progress callback that redraws one line on stderr; empty when `enabled` is false.
Progress terminalProgress(bool enabled);

/// True when stderr is a terminal.
bool stderrIsTerminal();

}  // namespace tomomap::cli
