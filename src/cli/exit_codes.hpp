#pragma once
// Exit codes of the `tomomap` tool, documented in `tomomap --help` and docs/cli.md.
namespace tomomap::cli {
constexpr int kExitOk = 0;        ///< success: a reliable transform was found / work done
constexpr int kExitNoMatch = 1;   ///< the maps were read but no reliable match exists
constexpr int kExitBadInput = 2;  ///< bad arguments, missing/corrupt/empty map, bad pose file
constexpr int kExitInternal = 3;  ///< unexpected failure (a bug: please report it)
}  // namespace tomomap::cli
