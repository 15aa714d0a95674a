// Low-level scene file I/O shared by every writer/reader of .osgb files in
// vista (city file, baked file): osgb payload + a 32-byte integrity trailer.
//
// File layout: <osgb bytes as written by OSG's "osgb" plugin> <trailer>
// trailer (32 bytes, little endian):
//   0..7   "VSTACITY"
//   8..15  payload size in bytes (uint64)
//   16..23 hash64 of the payload (foundation/hash.h hashBytes64)
//   24..31 "VSTAEND1"
// Stock osgviewer / osgconv ignore the trailer (the osgb reader stops after
// the root object). vista readers verify it before handing the bytes to OSG,
// so a truncated or corrupted file is an error, never a crash inside OSG.
//
// Contract: writeSceneFile() is atomic (temp file "<path>.tmp.<pid>" in the
// same directory, then rename); on any error no file is created at `path` and
// an existing file there is left untouched; a device or FIFO at `path` is
// written in place (foundation/atomic_file.h), never replaced. Output bytes depend only on the
// node graph. readSceneFile() returns an error naming the path for missing,
// unreadable, non-osgb, truncated or corrupted files. Both are thread
// compatible (no shared state besides osgDB's registry, which is locked).
#pragma once
#include <cstdint>
#include <string>

#include <osg/Node>
#include <osg/ref_ptr>

#include "foundation/hash.h"
#include "foundation/status.h"

namespace vista {

constexpr size_t kSceneTrailerSize = 32;

// Writes `node` as osgb (+ trailer) to `path` atomically. `compress` selects
// OSG's zlib compressor (stock readers decompress it transparently).
Status writeSceneFile(const osg::Node& node, const std::string& path, bool compress = false);

// Reads a file written by writeSceneFile(); verifies magic, size and hash.
// VISTA_UNTRUSTED_FILES=1 (environment): the payload is decoded once in a
// child process first; one that crashes OSG's reader is an error (trust
// model: docs/measurements/reliability.md).
Result<osg::ref_ptr<osg::Node>> readSceneFile(const std::string& path);

// The content hash of a scene file: its trailer's payload hash (bytes 16..23),
// as 16 lowercase hex digits. Reads only the last 32 bytes (magic and payload
// size are checked against the file size, the payload is not re-hashed:
// readSceneFile() does that). The bake records it as the baked file's
// vista.source_city_hash (docs/formats.md). Errors name the path: missing,
// unreadable, or no trailer (truncated, not written by vista).
Result<std::string> sceneFileContentHash(const std::string& path);

// The trailer writeSceneFile() appends to `payload` (fuzzing, tests).
std::string sceneFileTrailer(const std::string& payload);

}  // namespace vista
