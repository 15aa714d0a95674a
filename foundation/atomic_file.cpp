// Atomic file writes (atomic_file.h).
#include "foundation/atomic_file.h"

#include <signal.h>

#include <atomic>
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

namespace {

std::atomic<unsigned> gSpecialTemps{0};

bool isSpecialMode(mode_t m) { return S_ISCHR(m) || S_ISBLK(m) || S_ISFIFO(m) || S_ISSOCK(m); }

Status writeError(const std::string& path, const std::string& why) {
    return Status::error("cannot write '" + path + "': " + why);
}

// write(2) of every byte; SIGPIPE is blocked meanwhile in this thread, so a
// pipe whose reader went away is the error EPIPE, not the end of the process.
Status writeAll(int fd, const char* p, size_t n, const std::string& path) {
    sigset_t pipeSet, old;
    sigemptyset(&pipeSet);
    sigaddset(&pipeSet, SIGPIPE);
    sigset_t pending;
    sigemptyset(&pending);
    ::sigpending(&pending);
    const bool wasPending = sigismember(&pending, SIGPIPE) == 1;
    ::pthread_sigmask(SIG_BLOCK, &pipeSet, &old);
    std::string why;
    while (n > 0) {
        const ssize_t w = ::write(fd, p, n);
        if (w < 0 && errno == EINTR) continue;
        if (w < 0) {
            why = errnoText();
            if (errno == EPIPE && !wasPending) {
                const timespec zero{0, 0};
                ::sigtimedwait(&pipeSet, nullptr, &zero);  // the SIGPIPE this write raised
            }
            break;
        }
        if (w == 0) {
            why = "the device accepted no bytes";
            break;
        }
        p += w;
        n -= size_t(w);
    }
    ::pthread_sigmask(SIG_SETMASK, &old, nullptr);
    return why.empty() ? Status::ok() : writeError(path, why);
}

// Opens an existing device or FIFO for writing in place (no create, no truncate).
Result<int> openSpecial(const std::string& path) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC | O_NOCTTY);
    if (fd < 0) {
        if (errno == ENXIO) return writeError(path, "it is a socket (vista writes files, devices and pipes)");
        return writeError(path, errnoText());
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !isSpecialMode(st.st_mode)) {
        ::close(fd);
        return writeError(path, "it is no longer a device or pipe");
    }
    return fd;
}

Status closeChecked(int fd, const std::string& path) {
    if (::close(fd) != 0) return writeError(path, errnoText());
    return Status::ok();
}

Status writeInPlace(const std::string& path, const std::string& bytes) {
    auto fd = openSpecial(path);
    if (!fd) return fd.status();
    if (Status s = writeAll(*fd, bytes.data(), bytes.size(), path); !s) {
        ::close(*fd);
        return s;
    }
    return closeChecked(*fd, path);
}

// Copies the regular file `from` into the device or FIFO `path`.
Status copyInto(const std::string& from, const std::string& path) {
    const int in = ::open(from.c_str(), O_RDONLY | O_CLOEXEC);
    if (in < 0) return writeError(path, "cannot read its staged file: " + errnoText());
    auto fd = openSpecial(path);
    if (!fd) {
        ::close(in);
        return fd.status();
    }
    std::vector<char> buf(size_t(1) << 20);
    Status s = Status::ok();
    for (;;) {
        const ssize_t r = ::read(in, buf.data(), buf.size());
        if (r < 0 && errno == EINTR) continue;
        if (r < 0) {
            s = writeError(path, "cannot read its staged file: " + errnoText());
            break;
        }
        if (r == 0) break;
        if (s = writeAll(*fd, buf.data(), size_t(r), path); !s) break;
    }
    ::close(in);
    if (!s) {
        ::close(*fd);
        return s;
    }
    return closeChecked(*fd, path);
}

}  // namespace

bool isSpecialFile(const std::string& path) {
    struct stat st {};
    return !path.empty() && ::stat(path.c_str(), &st) == 0 && isSpecialMode(st.st_mode);
}

std::string tempPathFor(const std::string& path) {
    if (isSpecialFile(path)) {
        std::error_code ec;
        std::filesystem::path dir = std::filesystem::temp_directory_path(ec);
        if (ec) dir = "/tmp";
        return (dir / ("vista." + std::to_string(::getpid()) + "." + std::to_string(gSpecialTemps++) + "." +
                       std::filesystem::path(path).filename().string()))
            .string();
    }
    return path + ".tmp." + std::to_string(::getpid());
}

Status commitTempFile(const std::string& tmp, const std::string& path) {
    if (isSpecialFile(path)) {
        Status s = copyInto(tmp, path);
        ::unlink(tmp.c_str());
        return s;
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        const std::string e = errnoText();
        ::unlink(tmp.c_str());
        return writeError(path, "rename failed: " + e);
    }
    return Status::ok();
}

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
    const bool special = isSpecialFile(path);
    if (!special) removeStaleTemps(path);
    // not const: returned by move
    std::string staged = special ? tempPathFor(path) : path + ".stage." + std::to_string(::getpid());
    _files.emplace_back(staged, path);
    _special.push_back(special);
    return staged;
}

Status OutputBatch::commit() {
    for (const auto& f : _files)
        if (::access(f.first.c_str(), F_OK) != 0)
            return Status::error("cannot write '" + f.second + "': its staged file is missing");
    // Devices and pipes first: their writes cannot be undone, and a failed one
    // (a full device) then leaves every regular output as it was.
    for (size_t k = 0; k < _files.size(); ++k) {
        if (!_special[k]) continue;
        Status s = copyInto(_files[k].first, _files[k].second);
        ::unlink(_files[k].first.c_str());
        if (!s) return s;  // the destructor removes the other staged files
    }
    // Each output that exists keeps a second name ("<path>.prev.<pid>", a hard
    // link) until every rename is done, so that a failed rename can put the
    // previous outputs back: all new outputs appear, or none.
    const std::string pid = std::to_string(::getpid());
    std::vector<std::string> kept(_files.size());  // "" = no previous file (or no hard link possible)
    std::vector<bool> existed(_files.size(), false);
    auto undo = [&](size_t renamed) {
        for (size_t j = 0; j < renamed; ++j) {
            if (_special[j]) continue;  // written in place; nothing was renamed
            if (!kept[j].empty()) ::rename(kept[j].c_str(), _files[j].second.c_str());
            else if (!existed[j]) ::unlink(_files[j].second.c_str());
        }
        for (size_t j = renamed; j < _files.size(); ++j) {
            if (_special[j]) continue;
            if (!kept[j].empty()) ::unlink(kept[j].c_str());
            ::unlink(_files[j].first.c_str());  // the staged files not renamed
        }
    };
    for (size_t k = 0; k < _files.size(); ++k) {
        if (_special[k]) continue;
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
    if (isSpecialFile(path)) return writeInPlace(path, bytes);
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

namespace {

// Why the existing entry `path` (lstat succeeded, stat failed with `err`)
// cannot be followed: a link that loops, dangles, or an unreachable target.
std::string unfollowable(const std::string& path, int err) {
    std::error_code ec;
    if (std::filesystem::is_symlink(path, ec)) {
        if (err == ELOOP) return "is a symbolic link loop (too many levels of symbolic links)";
        if (err == ENOENT) {
            const std::string target = std::filesystem::read_symlink(path, ec).string();
            return "is a dangling symbolic link (its target '" + target + "' does not exist)";
        }
    }
    return "cannot be reached: " + std::string(std::strerror(err));
}

// lstat's errno for an entry that is not there: missing, or under a
// component that is not a directory or loops (its parent then says which).
bool missingEntry(int err) { return err == ENOENT || err == ENOTDIR || err == ELOOP; }

std::string named(const std::string& option, const std::string& path) {
    return "option " + option + " = '" + path + "'";
}

// `dir` is an existing, reachable, writable directory; `what` names it in messages ("directory 'd'").
Status checkDirectory(const std::string& option, const std::string& path, const std::string& dir,
                      const std::string& missing) {
    struct stat st {};
    if (::stat(dir.c_str(), &st) != 0) {
        const int err = errno;
        struct stat lst {};
        if (err == ENOENT && ::lstat(dir.c_str(), &lst) != 0)
            return Status::error(named(option, path) + ": " + missing);
        return Status::error(named(option, path) + ": directory '" + dir + "' " + unfollowable(dir, err));
    }
    if (!S_ISDIR(st.st_mode))
        return Status::error(named(option, path) + ": " +
                             (missing.empty() ? "'" + dir + "' exists and is not a directory"
                                              : missing + " ('" + dir + "' is not a directory)"));
    if (::access(dir.c_str(), W_OK) != 0)
        return Status::error(named(option, path) + ": directory '" + dir + "' is not writable");
    return Status::ok();
}

}  // namespace

Status checkWritablePath(const std::string& option, const std::string& path) {
    namespace fs = std::filesystem;
    if (path.empty()) return Status::error("option " + option + ": empty path");
    struct stat lst {
    }, st{};
    if (::lstat(path.c_str(), &lst) == 0) {
        if (::stat(path.c_str(), &st) != 0) {
            const int err = errno;
            return Status::error(named(option, path) + " " + unfollowable(path, err) +
                                 ": remove it or give another path");
        }
        if (S_ISDIR(st.st_mode)) return Status::error(named(option, path) + " is a directory, expected a file path");
        if (S_ISSOCK(st.st_mode))
            return Status::error(named(option, path) + " is a socket (vista writes files, devices and pipes)");
        if (isSpecialMode(st.st_mode)) {  // a device or FIFO: written in place
            if (::access(path.c_str(), W_OK) != 0)
                return Status::error(named(option, path) + " is a device or pipe that is not writable");
            return Status::ok();
        }
    } else if (!missingEntry(errno)) {
        return Status::error(named(option, path) + " cannot be reached: " + errnoText());
    }
    fs::path p(path);
    const std::string dir = p.has_parent_path() ? p.parent_path().string() : std::string(".");
    return checkDirectory(option, path, dir, "directory '" + dir + "' does not exist");
}

Status checkWritableDirectory(const std::string& option, const std::string& path, bool parentMustExist) {
    namespace fs = std::filesystem;
    if (path.empty()) return Status::error("option " + option + ": empty path");
    fs::path dir = fs::path(path).lexically_normal();
    if (!dir.has_filename() && dir.has_parent_path()) dir = dir.parent_path();  // "out/" -> "out"
    struct stat lst {};
    if (::lstat(dir.c_str(), &lst) == 0) return checkDirectory(option, path, dir.string(), "");
    if (!missingEntry(errno)) return Status::error(named(option, path) + " cannot be reached: " + errnoText());
    if (parentMustExist) {
        const fs::path parent = dir.has_parent_path() ? dir.parent_path() : fs::path(".");
        return checkDirectory(option, path, parent.string(),
                              "parent directory '" + parent.string() + "' does not exist (create it first)");
    }
    // Up to the nearest existing ancestor (the job creates the rest).
    while (::lstat(dir.c_str(), &lst) != 0) {
        if (!missingEntry(errno)) return Status::error(named(option, path) + " cannot be reached: " + errnoText());
        if (!dir.has_parent_path() || dir.parent_path() == dir) {
            dir = ".";
            break;
        }
        dir = dir.parent_path();
    }
    return checkDirectory(option, path, dir.string(), "");
}

}  // namespace vista
