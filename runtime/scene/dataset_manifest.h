// Dataset manifest: the cities, paths and rigs of a rendered dataset (JSON,
// docs/formats.md "Dataset manifest"), expanded into drives, one per
// (city, path, rig) in that nesting order (cities outermost, rigs innermost).
//
//   {"cities":  ["a.osgb", {"name": "b", "file": "b.paged"}],
//    "paths":   [{"name": "p1", "seed": 2, "duration": 3}, {"file": "drive.csv"}],
//    "rigs":    [{"name": "cam", "size": "160x120", "fov": 60, "mode": "full",
//                 "channels": "rgb,depth,semantic"}, {"file": "kitti.json"}],
//    "options": {"frames": 3, "sampling": "spread", "allow_repeated_frames": false}}
//
// A city is a file name (or an object with "file" and an optional "name"); a
// path is generated on each city's streets from "seed", "kind", "route",
// "duration", "run_up", "lht" (defaults: those of `vista render`), or read
// from a CSV "file" (then none of those); a rig is a camera ("size", "fov",
// "mode", "channels"; defaults: those of `vista render`) or a sensor rig file
// ("file"). Relative file names are relative to the manifest's folder. Names
// (default: the file name without its extension) are 1 .. 64 characters of
// [A-Za-z0-9_.-], not starting with '.', unique within their list; a drive's
// name is "city/path/rig" (its folder under the output).
//
// This parser checks the structure: every key known, every value of its
// type, every list non-empty (at most kMaxDatasetDrives drives), every file
// present; an error names the field ("paths[1].seed: expected a whole number
// >= 0, got \"x\""). Values with a range that the render flags own (image
// size, field of view, path duration, rig files' contents) are checked by the
// caller, which names the field too. Never throws; pure apart from the file
// checks of loadDatasetManifest.
#pragma once
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "foundation/status.h"

namespace vista {

constexpr size_t kMaxDatasetDrives = 1000000;
constexpr uint64_t kMaxDatasetManifestBytes = 16u << 20;

struct DatasetCity {
    std::string name, file;  // file: as resolved (relative to the manifest's folder)
};

struct DatasetPath {
    std::string name;
    std::string file;  // a CSV path; "" = generated from the fields below
    std::optional<uint64_t> seed;
    std::optional<std::string> kind, route;
    std::optional<double> duration, runUp;
    std::optional<bool> lht;
};

struct DatasetRig {
    std::string name;
    std::string file;  // a sensor rig file; "" = one camera from the fields below
    std::optional<std::string> size, mode, channels;
    std::optional<double> fov;
};

struct DatasetOptions {
    std::optional<int> frames;
    std::optional<std::string> sampling;
    bool allowRepeatedFrames = false;
};

struct DatasetDrive {
    size_t city = 0, path = 0, rig = 0;  // indices into the manifest's lists
    std::string name;                    // "city/path/rig"
};

struct DatasetManifest {
    std::vector<DatasetCity> cities;
    std::vector<DatasetPath> paths;
    std::vector<DatasetRig> rigs;
    DatasetOptions options;
    // Every (city, path, rig), cities outermost.
    std::vector<DatasetDrive> drives() const;
};

// Parses manifest text; `source` names it in errors, relative file names are
// resolved against `baseDir`. Files are not checked here.
Result<DatasetManifest> parseDatasetManifest(const std::string& text, const std::string& source,
                                             const std::string& baseDir);
// Reads and parses the file (at most kMaxDatasetManifestBytes), then checks
// that every city, path and rig file it names exists.
Result<DatasetManifest> loadDatasetManifest(const std::string& path);

}  // namespace vista
