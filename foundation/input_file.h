// Bounded reads of the files a user hands to vista.
//
// Contract: every reader of an untrusted file states a limit for its kind
// (the constants below) and reads through these functions, so that a device
// (/dev/zero, /dev/urandom), a pipe, a directory or a file larger than the
// limit is refused with a clear message instead of read without end.
// checkInputFile(): `path` names a regular file (after symlinks) of at most
// `maxBytes` bytes (0 = no size limit). The error names `kind` (e.g.
// "parameter file"), the path and, for a size, the limit: "... is a
// directory, expected a file", "... is not a regular file (a device, pipe or
// socket)", "... is N bytes, more than the limit of M MiB for a <kind>".
// readInputFile(): the same checks, then the whole file; it reads at most
// maxBytes + 1 bytes, so a file that grows while it is read is refused too.
// Thread-safe.
#pragma once
#include <cstdint>
#include <string>

#include "foundation/status.h"

namespace vista {

constexpr uint64_t kMiB = uint64_t(1) << 20;
constexpr uint64_t kMaxParamsFileBytes = 1 * kMiB;        // a parameter file (JSON)
constexpr uint64_t kMaxEffectsTextBytes = 64 * 1024;      // the --effects value (names or JSON)
constexpr uint64_t kMaxPathCsvBytes = 256 * kMiB;         // a walkthrough path (CSV)
constexpr uint64_t kMaxManifestBytes = 64 * kMiB;         // a paged city's manifest.json
constexpr uint64_t kMaxRaySetBytes = 1024 * kMiB;         // a ray set (.rays)
constexpr uint64_t kMaxOsmFileBytes = uint64_t(8) << 30;  // an OpenStreetMap extract (.osm, .osm.pbf, .osm.bz2)

Status checkInputFile(const std::string& kind, const std::string& path, uint64_t maxBytes);
Result<std::string> readInputFile(const std::string& kind, const std::string& path, uint64_t maxBytes);
// "1 MiB", "64 KiB", "8 GiB" or "N bytes": a limit as messages print it.
std::string byteLimitText(uint64_t bytes);

}  // namespace vista
