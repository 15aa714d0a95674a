// Shard directories of `vista render` and their merge (see render_shards.h).
#include "cmd/render_shards.h"

#include <filesystem>
#include <map>

#include "cmd/render_shared.h"
#include "foundation/atomic_file.h"
#include "foundation/input_file.h"

namespace vista {

namespace {

namespace fs = std::filesystem;
const char* const kFormat = "vista render shard 1";
constexpr uint64_t kMaxRecordBytes = uint64_t(1) << 30;

}  // namespace

std::string shardDir(const std::string& out, const Shard& shard) {
    fs::path o = fs::path(out).lexically_normal();
    if (!o.has_filename()) o = o.parent_path();
    return o.string() + ".shards/" + std::to_string(shard.k()) + "-of-" + std::to_string(shard.count);
}

Result<nlohmann::json> hashTree(const std::string& dir) {
    nlohmann::json files = nlohmann::json::object();
    std::error_code ec;
    std::map<std::string, std::string> sorted;  // rel -> path: the record lists files in one order
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
        if (!it->is_regular_file()) continue;
        const std::string rel = fs::relative(it->path(), dir).generic_string();
        if (rel != kShardRecordFile) sorted[rel] = it->path().string();
    }
    if (ec) return Status::error("cannot list '" + dir + "': " + ec.message());
    for (const auto& [rel, path] : sorted) {
        uint64_t bytes = 0;
        auto h = fileHash(path, bytes);
        if (!h) return h.status();
        files[rel] = {{"bytes", bytes}, {"hash", *h}};
    }
    return files;
}

nlohmann::json shardRecord(const Shard& shard, nlohmann::json fields, const nlohmann::json& files) {
    fields["format"] = kFormat;
    fields["shard"] = shardText(shard);
    fields["files"] = files;
    return fields;
}

Status writeShardRecord(const std::string& dir, const Shard& shard, const nlohmann::json& fields) {
    auto files = hashTree(dir);
    if (!files) return files.status();
    return writeFileAtomic((fs::path(dir) / kShardRecordFile).string(),
                           shardRecord(shard, fields, *files).dump(1) + "\n");
}

Result<nlohmann::json> readShardRecord(const std::string& dir, const Shard& shard) {
    std::error_code ec;
    if (!fs::exists(dir, ec)) {
        if (fs::exists(dir + ".partial", ec)) return Status::error("unfinished (" + dir + ".partial)");
        return Status::error("missing (no " + dir + ")");
    }
    const std::string file = (fs::path(dir) / kShardRecordFile).string();
    if (!fs::exists(file, ec)) return Status::error("no " + std::string(kShardRecordFile) + " (unfinished)");
    auto text = readInputFile("shard record", file, kMaxRecordBytes);
    if (!text) return text.status();
    nlohmann::json r = nlohmann::json::parse(*text, nullptr, false);
    if (r.is_discarded() || !r.is_object() || r.value("format", "") != kFormat || !r.contains("files") ||
        !r["files"].is_object() || !r.contains("inputs"))
        return Status::error(std::string(kShardRecordFile) + " is corrupt (not a " + kFormat + " record)");
    if (r.value("shard", "") != shardText(shard))
        return Status::error(std::string(kShardRecordFile) + " is shard " + r.value("shard", "?") + "'s, not " +
                             shardText(shard) + "'s");
    for (const auto& [rel, f] : r["files"].items()) {
        if (!f.is_object() || !f.contains("bytes") || !f.contains("hash"))
            return Status::error(std::string(kShardRecordFile) + " is corrupt (file " + rel + ")");
        const std::string path = (fs::path(dir) / rel).string();
        uint64_t bytes = 0;
        auto h = fileHash(path, bytes);
        if (!h) return Status::error(rel + ": missing or unreadable");
        if (nlohmann::json(bytes) != f["bytes"])
            return Status::error(rel + ": " + std::to_string(bytes) + " bytes, " + f["bytes"].dump() +
                                 " in the record");
        if (nlohmann::json(*h) != f["hash"]) return Status::error(rel + ": its content hash differs from the record's");
    }
    return r;
}

Result<std::vector<nlohmann::json>> readShards(
    const std::string& out, int count,
    const std::function<std::string(const Shard&, const nlohmann::json&)>& inputsDiffer, const std::string& rerun) {
    std::vector<nlohmann::json> records;
    std::string why, list;
    int bad = 0, first = -1;
    for (int k = 0; k < count; ++k) {
        const Shard s{k, count};
        auto r = readShardRecord(shardDir(out, s), s);
        std::string reason = r ? inputsDiffer(s, *r) : r.status().message();
        if (r && !reason.empty()) reason = "from other inputs: " + reason + " (run it again with --restart)";
        if (reason.empty()) {
            records.push_back(*r);
            continue;
        }
        if (first < 0) first = k;
        if (++bad <= 8) why += (bad > 1 ? "; " : "") + std::string("shard ") + shardText(s) + ": " + reason;
        if (bad <= 20) list += (bad > 1 ? ", " : "") + shardText(s);
    }
    if (bad == 0) return records;
    if (bad > 8) why += "; ...";
    if (bad > 20) list += ", ...";
    std::string msg = "--merge: " + std::to_string(bad) + " of " + std::to_string(count) + " shards of '" + out +
                      "' are missing, corrupt or from other inputs (" + why + "); run " +
                      (bad == 1 ? std::string("shard ") : std::to_string(bad) + " shards ") + list + " again";
    if (bad == 1) return Status::error(msg + ": " + rerun + " " + shardText(Shard{first, count}) + "; then the merge");
    return Status::error(msg + ", each with: " + rerun + " K/" + std::to_string(count) + "; then the merge");
}

Status assembleShards(const std::string& out, const std::vector<nlohmann::json>& records, const std::string& dest,
                      const std::set<std::string>& skip) {
    std::map<std::string, std::pair<std::string, size_t>> placed;  // rel -> hash, shard index
    const int count = int(records.size());
    for (int k = 0; k < count; ++k) {
        const std::string dir = shardDir(out, Shard{k, count});
        for (const auto& [rel, f] : records[size_t(k)]["files"].items()) {
            if (skip.count(rel)) continue;
            const std::string hash = f["hash"].get<std::string>();
            auto [it, fresh] = placed.emplace(rel, std::make_pair(hash, size_t(k)));
            if (!fresh) {
                if (it->second.first != hash)
                    return Status::error("--merge: " + rel + " differs between shard " +
                                         shardText(Shard{int(it->second.second), count}) + " and shard " +
                                         shardText(Shard{k, count}) + " (shards of other inputs?)");
                continue;
            }
            const fs::path to = fs::path(dest) / rel;
            std::error_code ec;
            fs::create_directories(to.parent_path(), ec);
            if (ec) return Status::error("--out: cannot create '" + to.parent_path().string() + "': " + ec.message());
            fs::create_hard_link(fs::path(dir) / rel, to, ec);
            if (ec) {
                ec.clear();
                fs::copy_file(fs::path(dir) / rel, to, fs::copy_options::overwrite_existing, ec);
            }
            if (ec) return Status::error("--out: cannot write '" + to.string() + "': " + ec.message());
        }
    }
    return Status::ok();
}

}  // namespace vista
