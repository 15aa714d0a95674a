// Atomic file writes (atomic_file.h).
#include "foundation/atomic_file.h"

#include <signal.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <vector>
#include <unordered_map>
#include <mutex>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace vista {

std::string errnoText() { return std::strerror(errno); }

std::string tempPathFor(const std::string& path) { return path + ".tmp." + std::to_string(::getpid()); }

namespace {

// Per directory listed by this process: its names that look like temporaries.
std::mutex gTempsMutex;
std::unordered_map<std::string, std::vector<std::string>> gTempNames;

// The pid of `f` if it is a temporary of `name` ("<name>.tmp.<pid>",
// "<name>.stage.<pid>", "<name>.stage.<pid>.tmp.<pid>" or "<name>.prev.<pid>"), else 0.
long tempOwner(const std::string& f, const std::string& name) {
    for (const char* tag : {".tmp.", ".stage.", ".prev."}) {
        const std::string prefix = name + tag;
        if (f.size() <= prefix.size() || f.compare(0, prefix.size(), prefix) != 0) continue;
        std::string digits = f.substr(prefix.size());
        // A staged file's own temporary: "<path>.stage.<pid>.tmp.<pid>".
        const size_t inner = digits.find(".tmp.");
        if (std::string(tag) == ".stage." && inner != std::string::npos) {
            const std::string rest = digits.substr(inner + 5);
            if (rest.empty() || rest.find_first_not_of("0123456789") != std::string::npos) continue;
            digits = digits.substr(0, inner);
        }
        if (digits.empty() || digits.size() > 9 || digits.find_first_not_of("0123456789") != std::string::npos)
            continue;
        return std::stol(digits);
    }
    return 0;
}

}  // namespace

int removeStaleTemps(const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    const fs::path p(path);
    const fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    const std::string name = p.filename().string();
    if (name.empty()) return 0;
    std::lock_guard<std::mutex> lock(gTempsMutex);
    auto it = gTempNames.find(dir.string());
    if (it == gTempNames.end()) {
        std::vector<std::string> names;
        for (fs::directory_iterator d(dir, ec), end; !ec && d != end; d.increment(ec)) {
            std::string f = d->path().filename().string();
            if (f.find(".tmp.") != std::string::npos || f.find(".stage.") != std::string::npos ||
                f.find(".prev.") != std::string::npos)
                names.push_back(std::move(f));
        }
        it = gTempNames.emplace(dir.string(), std::move(names)).first;
    }
    int removed = 0;
    std::vector<std::string>& names = it->second;
    for (size_t k = 0; k < names.size();) {
        const long pid = tempOwner(names[k], name);
        const bool dead = pid > 0 && pid != long(::getpid()) && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH;
        if (dead && fs::remove(dir / names[k], ec)) ++removed;
        if (dead) {
            names[k] = std::move(names.back());
            names.pop_back();
        } else {
            ++k;
        }
    }
    return removed;
}

OutputBatch::~OutputBatch() {
    if (_committed) return;
    for (const auto& f : _files) ::unlink(f.first.c_str());
}

std::string OutputBatch::stage(const std::string& path) {
    removeStaleTemps(path);
    std::string staged = path + ".stage." + std::to_string(::getpid());  // not const: returned by move
    _files.emplace_back(staged, path);
    return staged;
}

Status OutputBatch::commit() {
    for (const auto& f : _files)
        if (::access(f.first.c_str(), F_OK) != 0)
            return Status::error("cannot write '" + f.second + "': its staged file is missing");
    // Each output that exists keeps a second name ("<path>.prev.<pid>", a hard
    // link) until every rename is done, so that a failed rename can put the
    // previous outputs back: all new outputs appear, or none.
    const std::string pid = std::to_string(::getpid());
    std::vector<std::string> kept(_files.size());  // "" = no previous file (or no hard link possible)
    std::vector<bool> existed(_files.size(), false);
    auto undo = [&](size_t renamed) {
        for (size_t j = 0; j < renamed; ++j) {
            if (!kept[j].empty()) ::rename(kept[j].c_str(), _files[j].second.c_str());
            else if (!existed[j]) ::unlink(_files[j].second.c_str());
        }
        for (size_t j = renamed; j < _files.size(); ++j) {
            if (!kept[j].empty()) ::unlink(kept[j].c_str());
            ::unlink(_files[j].first.c_str());  // the staged files not renamed
        }
    };
    for (size_t k = 0; k < _files.size(); ++k) {
        const std::string& target = _files[k].second;
        const std::string prev = target + ".prev." + pid;
        ::unlink(prev.c_str());
        if (::link(target.c_str(), prev.c_str()) == 0) {
            kept[k] = prev;
            existed[k] = true;
        } else {
            existed[k] = errno != ENOENT;
        }
        if (::rename(_files[k].first.c_str(), target.c_str()) != 0) {
            const std::string e = errnoText();
            undo(k);
            return Status::error("cannot write '" + target + "': rename failed: " + e);
        }
    }
    for (const std::string& k : kept)
        if (!k.empty()) ::unlink(k.c_str());
    _committed = true;
    return Status::ok();
}

CreatedDirectories::~CreatedDirectories() {
    for (auto it = _made.rbegin(); it != _made.rend(); ++it) ::rmdir(it->c_str());  // fails unless empty
}

Status CreatedDirectories::create(const std::string& option, const std::string& path) {
    namespace fs = std::filesystem;
    std::error_code ec;
    std::vector<std::string> missing;
    fs::path d = fs::path(path).lexically_normal();
    if (!d.has_filename()) d = d.parent_path();  // "out/" -> "out"
    for (; !d.empty() && !fs::exists(fs::symlink_status(d, ec)); d = d.parent_path()) {
        missing.push_back(d.string());
        if (!d.has_parent_path() || d.parent_path() == d) break;
    }
    for (auto it = missing.rbegin(); it != missing.rend(); ++it) {
        if (::mkdir(it->c_str(), 0777) == 0) _made.push_back(*it);
        else if (errno != EEXIST)
            return Status::error("option " + option + " = '" + path + "': cannot create directory '" + *it +
                                 "': " + errnoText());
    }
    if (!fs::is_directory(path, ec)) return Status::error("option " + option + " = '" + path + "': not a directory");
    return Status::ok();
}

Status writeFileAtomic(const std::string& path, const std::string& bytes) {
    if (path.empty()) return Status::error("cannot write file: empty path");
    removeStaleTemps(path);
    const std::string tmp = tempPathFor(path);
    int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return Status::error("cannot write '" + path + "': " + errnoText());
    const char* p = bytes.data();
    size_t n = bytes.size();
    while (n > 0) {
        ssize_t w = ::write(fd, p, n);
        if (w < 0) {
            if (errno == EINTR) continue;
            std::string e = errnoText();
            ::close(fd);
            ::unlink(tmp.c_str());
            return Status::error("cannot write '" + path + "': " + e);
        }
        p += w;
        n -= size_t(w);
    }
    if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
        std::string e = errnoText();
        ::close(fd);
        ::unlink(tmp.c_str());
        return Status::error("cannot write '" + path + "': fsync failed: " + e);
    }
    if (::close(fd) != 0) {
        std::string e = errnoText();
        ::unlink(tmp.c_str());
        return Status::error("cannot write '" + path + "': " + e);
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        std::string e = errnoText();
        ::unlink(tmp.c_str());
        return Status::error("cannot write '" + path + "': rename failed: " + e);
    }
    return Status::ok();
}

Status checkWritablePath(const std::string& option, const std::string& path) {
    namespace fs = std::filesystem;
    if (path.empty()) return Status::error("option " + option + ": empty path");
    std::error_code ec;
    fs::path p(path);
    if (fs::is_directory(p, ec))
        return Status::error("option " + option + " = '" + path + "' is a directory, expected a file path");
    fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec))
        return Status::error("option " + option + " = '" + path + "': directory '" + dir.string() + "' does not exist");
    if (access(dir.c_str(), W_OK) != 0)
        return Status::error("option " + option + " = '" + path + "': directory '" + dir.string() +
                             "' is not writable");
    return Status::ok();
}

Status checkWritableDirectory(const std::string& option, const std::string& path) {
    namespace fs = std::filesystem;
    if (path.empty()) return Status::error("option " + option + ": empty path");
    std::error_code ec;
    fs::path dir = fs::path(path).lexically_normal();  // up to the nearest existing ancestor
    while (!fs::exists(fs::symlink_status(dir, ec)) && dir.has_parent_path() && dir.parent_path() != dir)
        dir = dir.parent_path();
    if (!fs::exists(fs::symlink_status(dir, ec))) dir = ".";
    if (!fs::is_directory(dir, ec))
        return Status::error("option " + option + " = '" + path + "': '" + dir.string() +
                             "' exists and is not a directory");
    if (access(dir.c_str(), W_OK) != 0)
        return Status::error("option " + option + " = '" + path + "': directory '" + dir.string() +
                             "' is not writable");
    return Status::ok();
}

}  // namespace vista
