// Atomic file writes: every file vista writes appears whole or not at all.
//
// Contract: writeFileAtomic() writes `bytes` to "<path>.tmp.<pid>" in the
// same directory, fsyncs it and renames it over `path`. On any error the
// temporary file is removed, nothing is created at `path`, an existing file
// there is left untouched, and the Status names the path and the reason.
// tempPathFor() gives that temporary name (for writers that stream into it
// themselves and then rename). Thread compatible: distinct paths may be
// written concurrently.
#pragma once
#include <string>

#include "foundation/status.h"

namespace vista {

Status writeFileAtomic(const std::string& path, const std::string& bytes);
std::string tempPathFor(const std::string& path);
// Checks, without creating anything, that a file can be written at `path`:
// not a directory, its directory exists and is writable. The error names
// `option` (the flag or field that gave the path), the path and the reason.
// Long jobs call it before they start, so they never fail at the end.
Status checkWritablePath(const std::string& option, const std::string& path);
// strerror(errno) as a string (for messages).
std::string errnoText();

}  // namespace vista
