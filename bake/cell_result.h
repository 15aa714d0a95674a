// Cell result: what bakeCell() (bake/bake_cell.h) produces for one view cell,
// and its file codec (the driver writes one file per cell; docs/reference/bake.md
// "Work directory, resume, shards").
//
// File layout ("VBCELL01", native little-endian): magic, config hash (u64),
// the CellResult fields in the order of one field list used by both the
// encoder and the decoder (vectors and strings as u64 count + elements),
// then a 64-bit hash of everything before it (foundation/hash.h). A result
// with textured depth meshes (`--representation mesh`) has the magic
// "VBCMESH1" and the mesh list after the impostor list; a point result's
// bytes are those of VBCELL01 unchanged.
// decodeCellResult() never trusts the bytes: a wrong magic, a config hash
// other than `configHash`, a hash mismatch, any count beyond the bytes left
// (or > 16 notes, > 2 impostors, > 2 meshes), trailing bytes and inconsistent
// impostor or mesh arrays are a Status error naming `what` (the file) — never a crash or a
// huge allocation. Pure; thread-safe.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "bake/impostor_frame.h"
#include "foundation/status.h"
#include "nodes/point_impostor.h"
#include "nodes/textured_depth_mesh.h"

namespace vista {

// Measurements of one impostor bake (--stats); stored as one block of 152 bytes.
struct ImpostorStats {
    size_t farTriangles = 0, tiles = 0;
    int camW[3] = {0, 0, 0}, camH[3] = {0, 0, 0};
    double requiredStep = 0, usedStep = 0;  // LDI angular step (tangent units)
    int64_t ldiRays = 0, mcRays = 0, mcSamples = 0;
    size_t ldiSamples = 0, afterRemoval = 0, points = 0, textured = 0, dropped = 0;
    size_t noiseSingle = 0;                         // single-coloured by the F test (appearance.h)
    size_t screenPixels = 0, screenBBoxPixels = 0;  // from the cell centre, target view
    double bakeMs = 0;                              // not part of the baked scene
};

struct ImpostorResult {
    uint32_t cell = 0;
    uint8_t end = 0;  // 0: towards node a, 1: towards node b
    ImpostorFrame frame;
    std::vector<uint32_t> hiddenTiles;  // root child indices, ascending
    PointImpostorData data;             // in the frame
    ImpostorStats stats;
};

// Measurements of one textured depth mesh bake; stored as one block of 96 bytes.
struct MeshStats {
    uint64_t farTriangles = 0, tiles = 0, imageW = 0, imageH = 0;
    uint64_t samples = 0, hits = 0, leaves = 0, triangles = 0, droppedTriangles = 0, snapped = 0;
    double maxLeafErrorPx = 0;
    double bakeMs = 0;  // not part of the baked scene
};

// The textured depth mesh of one (cell, street end) (bake/depth_mesh.h).
struct MeshResult {
    uint32_t cell = 0;
    uint8_t end = 0;
    ImpostorFrame frame;
    std::vector<uint32_t> hiddenTiles;  // root child indices, ascending (as ImpostorResult)
    TexturedDepthMeshData mesh;         // in the frame
    MeshStats stats;
};

struct CellResult {
    uint32_t cell = 0;
    std::vector<ImpostorResult> impostors;  // at most 2 (one per street end)
    std::vector<MeshResult> meshes;         // --representation mesh: at most 2 (one per street end)
    std::vector<std::string> notes;         // why ends were skipped (at most 16)
    double bakeMs = 0;
};

std::string encodeCellResult(const CellResult& r, uint64_t configHash);
Result<CellResult> decodeCellResult(const std::string& bytes, uint64_t configHash, const std::string& what);

}  // namespace vista
