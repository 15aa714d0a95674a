// The work directory of `vista render`: interrupted runs resume
// (docs/formats.md "Ground truth (vista render)", "Interruption and resume").
//
// Layout beside the output directory OUT:
//   OUT.partial/manifest.json     the run's parameters that affect output bytes
//   OUT.partial/lock              flock()ed while a run uses the directory
//   OUT.partial/done/NNNNNN.json  per finished frame: its timings and, under
//                                 "files", each of its files' size and content
//                                 hash (written after the frame's files: the
//                                 mark that the frame is complete)
//   OUT.partial/out/              the output tree (rgb/, depth/, ...)
// commit() renames OUT.partial/out to OUT (one rename: OUT appears whole)
// and removes OUT.partial.
//
// checkOut(): before any work; OUT must not exist, or be an empty
// directory; its parent must exist (the message names the missing parent)
// and be writable. open(): creates OUT.partial with `manifest`, or resumes
// an existing one whose manifest equals `manifest`; a different manifest is
// an error naming the first differing field with both values (restart:
// discard the directory and start over); a directory without a manifest
// that is not empty is refused (not ours). A second run on the same
// directory while one holds the lock is refused. On resume, temporaries of
// killed writes ("*.tmp.*") under out/ are removed. If this object created
// OUT.partial and no frame was finished when it is destroyed without
// commit() (a failure before the first frame), it removes OUT.partial again.
// finishFrame(): adds to `record` "files": {relative path: {"bytes": N,
// "hash": 16 hex digits (hashBytes64 of the file)}} for each of `files`
// (paths under out/, as written), then writes the record. frameIntact(): a
// resumed frame is kept only when its record lists exactly `files` and each
// has its recorded size and hash (a file damaged or truncated after the
// record, or a record without hashes, means the frame is rendered again).
// Errors are Status messages naming --out, the path and the reason.
// Not thread-safe; one object per run.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "foundation/status.h"

namespace vista {

class RenderWorkDir {
public:
    RenderWorkDir() = default;
    RenderWorkDir(const RenderWorkDir&) = delete;
    RenderWorkDir& operator=(const RenderWorkDir&) = delete;
    ~RenderWorkDir();

    Status checkOut(const std::string& out);
    // The part of checkOut() about OUT's parent (exists, a directory, writable).
    static Status checkParent(const std::string& out);
    Status open(const nlohmann::json& manifest, bool restart);
    bool resumed() const { return _resumed; }
    const std::string& partialPath() const { return _partialStr; }
    const std::string& outPath() const { return _outStr; }

    Status subdir(const std::string& name);
    // A path under OUT.partial/out/.
    std::string file(const std::string& rel) const;
    // The frame's record, or null when the frame is not finished.
    nlohmann::json frameRecord(size_t frame) const;
    Status finishFrame(size_t frame, nlohmann::json& record, const std::vector<std::string>& files);
    bool frameIntact(const nlohmann::json& record, const std::vector<std::string>& files) const;
    Status commit();

private:
    std::string _outStr, _partialStr;
    bool _created = false, _resumed = false, _committed = false;
    size_t _finished = 0;
    int _lockFd = -1;
};

// The first field where two manifests differ, "" if none: "size: 160x120 in
// the work directory, 320x240 now".
std::string manifestDifference(const nlohmann::json& previous, const nlohmann::json& now);

}  // namespace vista
