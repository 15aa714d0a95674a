// Shards of `vista render` (--shard K/N, --merge --shards N): each shard
// renders its share into its own directory OUT.shards/K-of-N (published
// whole, like any render output) holding a record, shard.json:
//   {"format": "vista render shard 1", "shard": "K/N",
//    "inputs": {...what decides the bytes: city, path, rig, option hashes...},
//    "files": {relative path: {"bytes": N, "hash": 16 hex digits}}, ...}
// "files" lists every other file of the directory with its size and content
// hash (hashBytes64). The merge reads the N records, refuses unless every
// shard is present, intact (every file with its recorded size and hash) and
// from the inputs the merge expects, then links (or copies, across file
// systems) the shards' files into its output. A refusal names each bad shard
// and why, and ends "run shard K/N again: COMMAND K/N; then the merge" (or
// "run M shards K1/N, K2/N again, each with: COMMAND K/N; ..."), the form
// the Slurm merge script reads. Errors are Status messages; not thread-safe.
#pragma once
#include <functional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "foundation/shard.h"
#include "foundation/status.h"

namespace vista {

constexpr const char* kShardRecordFile = "shard.json";

// OUT.shards/K-of-N: shard K's directory beside the output OUT.
std::string shardDir(const std::string& out, const Shard& shard);

// Every regular file under `dir` but shard.json: {relative path: {"bytes", "hash"}}.
Result<nlohmann::json> hashTree(const std::string& dir);

// The record of a shard whose files are complete under `dir`: `fields`
// (inputs and anything the merge needs) plus "format", "shard" and "files"
// (hashTree(dir)), written atomically as dir/shard.json.
nlohmann::json shardRecord(const Shard& shard, nlohmann::json fields, const nlohmann::json& files);
Status writeShardRecord(const std::string& dir, const Shard& shard, const nlohmann::json& fields);

// The record in `dir` when it is shard `shard`'s and every file it lists has
// its size and hash; otherwise an error saying what is wrong ("missing",
// "no shard.json (unfinished)", "rgb/000003.png: 812 bytes, 1024 in the
// record"). Only shard.json's own files are checked, not extra files.
Result<nlohmann::json> readShardRecord(const std::string& dir, const Shard& shard);

// Reads the records of shards 1 .. N of OUT. `inputsDiffer(shard, record)`
// returns "" when the shard's inputs are those the merge expects, else the
// first difference ("size (--size): 96x72 in the shard, 80x60 now"). Any bad shard makes
// the whole read an error (see the header comment); `rerun` is the command
// that runs one shard, without its K/N ("vista render ... --out OUT --shard").
Result<std::vector<nlohmann::json>> readShards(
    const std::string& out, int count,
    const std::function<std::string(const Shard&, const nlohmann::json&)>& inputsDiffer, const std::string& rerun);

// Links every shard's files into `dest` (created as needed), skipping the
// relative paths in `skip`: a file in several shards must have the same hash
// in each (else an error naming both shards).
Status assembleShards(const std::string& out, const std::vector<nlohmann::json>& records, const std::string& dest,
                      const std::set<std::string>& skip);

}  // namespace vista
