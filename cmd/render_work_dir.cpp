#include "cmd/render_work_dir.h"

#include <fcntl.h>
#include <sys/file.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "cmd/render_shared.h"
#include "foundation/atomic_file.h"

namespace vista {

namespace {

namespace fs = std::filesystem;
const char* const kFormat = "vista render work directory 1";

std::string recordName(size_t f) {
    char b[32];
    std::snprintf(b, sizeof b, "done/%06zu.json", f);
    return b;
}

std::string readAll(const fs::path& p, bool& ok) {
    std::ifstream in(p, std::ios::binary);
    ok = bool(in);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::string shown(const nlohmann::json& v) {
    if (v.is_null()) return "(none)";
    if (v.is_string()) return v.get<std::string>();
    return v.dump();
}

}  // namespace

std::string manifestDifference(const nlohmann::json& previous, const nlohmann::json& now) {
    if (!previous.is_object()) return "manifest: not a JSON object in the work directory";
    for (const auto& [key, value] : now.items()) {
        const nlohmann::json before = previous.contains(key) ? previous[key] : nlohmann::json();
        if (before != value) return key + ": " + shown(before) + " in the work directory, " + shown(value) + " now";
    }
    for (const auto& [key, value] : previous.items())
        if (!now.contains(key)) return key + ": " + shown(value) + " in the work directory, (none) now";
    return "";
}

RenderWorkDir::~RenderWorkDir() {
    if (!_committed && _created && _finished == 0 && !_partialStr.empty()) {
        std::error_code ec;
        fs::remove_all(_partialStr, ec);
    }
    if (_lockFd >= 0) ::close(_lockFd);
}

Status RenderWorkDir::checkParent(const std::string& dir) {
    fs::path out = fs::path(dir).lexically_normal();
    if (!out.has_filename()) out = out.parent_path();
    if (out.empty() || out == "." || out == "..") return Status::error("--out '" + dir + "': not a directory name");
    std::error_code ec;
    const fs::path parent = out.has_parent_path() ? out.parent_path() : fs::path(".");
    if (!fs::exists(parent, ec))
        return Status::error("--out '" + dir + "': parent directory '" + parent.string() +
                             "' does not exist (create it first)");
    if (!fs::is_directory(parent, ec))
        return Status::error("--out '" + dir + "': parent '" + parent.string() + "' is not a directory");
    if (::access(parent.c_str(), W_OK) != 0)
        return Status::error("--out '" + dir + "': parent directory '" + parent.string() + "' is not writable");
    return Status::ok();
}

Status RenderWorkDir::checkOut(const std::string& dir) {
    VISTA_RETURN_IF_ERROR(checkParent(dir));
    fs::path out = fs::path(dir).lexically_normal();
    if (!out.has_filename()) out = out.parent_path();
    std::error_code ec;
    if (fs::exists(out, ec)) {
        if (!fs::is_directory(out, ec)) return Status::error("--out '" + dir + "' exists and is not a directory");
        if (!fs::is_empty(out, ec))
            return Status::error("--out '" + dir + "' exists and is not empty (choose a new directory)");
    }
    _outStr = out.string();
    _partialStr = _outStr + ".partial";
    return Status::ok();
}

Status RenderWorkDir::open(const nlohmann::json& manifestIn, bool restart) {
    nlohmann::json manifest = manifestIn;
    manifest["format"] = kFormat;
    const fs::path partial(_partialStr);
    const std::string where = "--out '" + _outStr + "': work directory '" + _partialStr + "'";
    std::error_code ec;
    if (fs::exists(partial, ec) && !fs::is_directory(partial, ec))
        return Status::error(where + " exists and is not a directory");
    if (restart && fs::exists(partial, ec)) {
        fs::remove_all(partial, ec);
        if (ec) return Status::error(where + ": cannot remove it (--restart): " + ec.message());
    }
    if (!fs::exists(partial, ec)) {
        if (!fs::create_directory(partial, ec) || ec)
            return Status::error(where + ": cannot create it: " + (ec ? ec.message() : std::string("unknown error")));
        _created = true;
    }
    _lockFd = ::open((partial / "lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    if (_lockFd < 0) return Status::error(where + ": cannot open its lock file: " + errnoText());
    if (::flock(_lockFd, LOCK_EX | LOCK_NB) != 0)
        return Status::error(where + " is in use by another vista render (one run per output directory at a time)");
    const fs::path mf = partial / "manifest.json";
    if (fs::exists(mf, ec)) {
        bool ok = false;
        const std::string text = readAll(mf, ok);
        const nlohmann::json previous = nlohmann::json::parse(text, nullptr, false);
        if (!ok || previous.is_discarded())
            return Status::error(where + ": its manifest.json is unreadable; remove the directory or add --restart");
        const std::string diff = manifestDifference(previous, manifest);
        if (!diff.empty())
            return Status::error(where + " of an interrupted run was made with other parameters (" + diff +
                                 "): rerun with the same parameters to resume it, or add --restart to discard it");
        _resumed = true;
        // Temporaries of writes a kill interrupted (we hold the lock: no live writer).
        for (fs::recursive_directory_iterator it(partial / "out", ec), end; !ec && it != end; it.increment(ec))
            if (it->is_regular_file(ec) && it->path().filename().string().find(".tmp.") != std::string::npos)
                fs::remove(it->path(), ec);
    } else {
        for (const auto& e : fs::directory_iterator(partial, ec))
            if (e.path().filename() != "lock")
                return Status::error(where +
                                     " exists without a manifest.json (not a vista render work directory); "
                                     "remove it or add --restart");
        if (Status s = writeFileAtomic(mf.string(), manifest.dump(2) + "\n"); !s) return s;
    }
    fs::create_directories(partial / "done", ec);
    if (!ec) fs::create_directories(partial / "out", ec);
    if (ec) return Status::error(where + ": cannot create its subdirectories: " + ec.message());
    return Status::ok();
}

Status RenderWorkDir::subdir(const std::string& name) {
    std::error_code ec;
    const fs::path d = fs::path(_partialStr) / "out" / name;
    fs::create_directories(d, ec);
    return ec ? Status::error("--out: cannot create '" + d.string() + "': " + ec.message()) : Status::ok();
}

std::string RenderWorkDir::file(const std::string& rel) const { return (fs::path(_partialStr) / "out" / rel).string(); }

nlohmann::json RenderWorkDir::frameRecord(size_t frame) const {
    bool ok = false;
    const std::string text = readAll(fs::path(_partialStr) / recordName(frame), ok);
    if (!ok) return nullptr;
    nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    return j.is_object() ? j : nlohmann::json();
}

Status RenderWorkDir::finishFrame(size_t frame, nlohmann::json& record, const std::vector<std::string>& files) {
    nlohmann::json list = nlohmann::json::object();
    for (const std::string& rel : files) {
        uint64_t bytes = 0;
        auto hash = fileHash(file(rel), bytes);
        if (!hash) return Status::error("--out: frame " + std::to_string(frame) + ": " + hash.status().message());
        list[rel] = {{"bytes", bytes}, {"hash", *hash}};
    }
    record["files"] = std::move(list);
    if (Status s = writeFileAtomic((fs::path(_partialStr) / recordName(frame)).string(), record.dump() + "\n"); !s)
        return s;
    ++_finished;
    return Status::ok();
}

bool RenderWorkDir::frameIntact(const nlohmann::json& record, const std::vector<std::string>& files) const {
    if (!record.is_object() || !record.contains("files") || !record["files"].is_object()) return false;
    const nlohmann::json& list = record["files"];
    if (list.size() != files.size()) return false;
    for (const std::string& rel : files) {
        if (!list.contains(rel) || !list[rel].is_object()) return false;
        const nlohmann::json& e = list[rel];
        uint64_t bytes = 0;
        auto hash = fileHash(file(rel), bytes);
        if (!hash || !e.contains("bytes") || !e.contains("hash") || e["bytes"] != bytes || e["hash"] != *hash)
            return false;
    }
    return true;
}

Status RenderWorkDir::commit() {
    std::error_code ec;
    const fs::path out(_outStr);
    if (fs::exists(out, ec)) fs::remove(out, ec);  // an empty directory (checkOut)
    fs::rename(fs::path(_partialStr) / "out", out, ec);
    if (ec)
        return Status::error("--out '" + _outStr + "': cannot rename the finished output into place: " + ec.message());
    _committed = true;
    fs::remove_all(_partialStr, ec);  // bookkeeping only; the output is complete
    return Status::ok();
}

}  // namespace vista
