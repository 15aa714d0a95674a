// One rule for a command's outputs (output_paths.h).
#include "foundation/output_paths.h"

#include <cerrno>
#include <climits>
#include <cstdlib>
#include <cstring>
#include <filesystem>

#include <sys/stat.h>

#include "foundation/number_text.h"

namespace vista {

namespace {

namespace fs = std::filesystem;

// The directory entry `path` names: the real path of its parent plus its last
// component (lexically normalised and absolute where the parent does not exist).
std::string resolvedEntry(const std::string& path) {
    fs::path p = fs::path(path).lexically_normal();
    std::error_code ec;
    fs::path abs = fs::absolute(p, ec);
    if (ec) abs = p;
    abs = abs.lexically_normal();
    if (!abs.has_filename()) abs = abs.parent_path();  // "dir/" -> "dir"
    const fs::path name = abs.filename();
    if (name == "." || name == ".." || name.empty()) {
        char buf[PATH_MAX];
        if (::realpath(abs.c_str(), buf)) return buf;
        return abs.string();
    }
    char buf[PATH_MAX];
    if (::realpath(abs.parent_path().c_str(), buf)) return (fs::path(buf) / name).string();
    return abs.string();
}

}  // namespace

bool sameFile(const std::string& a, const std::string& b) {
    struct stat sa {
    }, sb{};
    if (::stat(a.c_str(), &sa) == 0 && ::stat(b.c_str(), &sb) == 0)
        return sa.st_dev == sb.st_dev && sa.st_ino == sb.st_ino;
    // One or both do not exist (yet): the entries they would be, after symlinked parents and "..".
    // A symlink that exists but dangles is followed to its target's entry.
    std::string ra = resolvedEntry(a), rb = resolvedEntry(b);
    for (std::string* r : {&ra, &rb}) {
        std::error_code ec;
        if (fs::is_symlink(*r, ec)) {
            const fs::path target = fs::read_symlink(*r, ec);
            if (!ec) *r = resolvedEntry((target.is_absolute() ? target : fs::path(*r).parent_path() / target).string());
        }
    }
    return ra == rb;
}

Status checkInputPath(const std::string& option, const std::string& path) {
    struct stat st {};
    if (::stat(path.c_str(), &st) == 0) return Status::ok();
    const int err = errno;
    const std::string where = "option " + option + " = '" + echoText(path) + "' ";
    std::error_code ec;
    struct stat lst {};
    const bool entry = ::lstat(path.c_str(), &lst) == 0;
    if (entry && S_ISLNK(lst.st_mode) && err == ELOOP)
        return Status::error(where + "is a symbolic link loop (too many levels of symbolic links)");
    if (entry && S_ISLNK(lst.st_mode) && err == ENOENT)
        return Status::error(where + "is a dangling symbolic link (its target '" +
                             echoText(fs::read_symlink(path, ec).string()) + "' does not exist)");
    if (err == ENOENT) return Status::error(where + "does not exist");
    return Status::error(where + "cannot be reached: " + std::strerror(err));
}

CommandFiles& CommandFiles::input(const std::string& option, const std::string& path) {
    if (!path.empty()) _inputs.push_back({option, path});
    return *this;
}

CommandFiles& CommandFiles::output(const std::string& option, const std::string& path) {
    if (!path.empty()) _outputs.push_back({option, path});
    return *this;
}

CommandFiles& CommandFiles::outputDirectory(const std::string& option, const std::string& path, bool parentMustExist) {
    if (!path.empty()) _outputs.push_back({option, path, true, parentMustExist});
    return *this;
}

CommandFiles& CommandFiles::shareOutputs(bool shared) {
    _shared = shared;
    return *this;
}

Status CommandFiles::check() & {
    // 1. No output is an input or another output (the most telling refusal first).
    for (size_t i = 0; i < _outputs.size(); ++i) {
        const Named& o = _outputs[i];
        for (const Named& in : _inputs)
            if (sameFile(o.path, in.path))
                return Status::error("option " + o.option + " = '" + echoText(o.path) + "' is the same file as the " +
                                     in.option + " input '" + echoText(in.path) +
                                     "': an output never replaces an input; write it elsewhere");
        for (size_t j = 0; j < i; ++j) {
            struct stat st {};
            const bool device = ::stat(o.path.c_str(), &st) == 0 && S_ISCHR(st.st_mode);
            if (!device && sameFile(o.path, _outputs[j].path))
                return Status::error("options " + _outputs[j].option + " and " + o.option + " name the same file '" +
                                     echoText(o.path) + "': give each output its own path");
        }
    }
    // 2. Every path resolves (outputs first: a run whose output cannot be
    //    written is refused whatever its inputs).
    for (const Named& o : _outputs)
        VISTA_RETURN_IF_ERROR(o.directory ? checkWritableDirectory(o.option, o.path, o.parentMustExist)
                                          : checkWritablePath(o.option, o.path));
    for (const Named& in : _inputs) VISTA_RETURN_IF_ERROR(checkInputPath(in.option, in.path));
    // 3. One writer per output.
    if (!_made) _made = std::make_unique<CreatedDirectories>();
    for (const Named& o : _outputs) {
        if (o.directory && !o.parentMustExist) {
            fs::path parent = fs::path(OutputLock::lockPathFor(o.path)).parent_path();
            if (!parent.empty()) VISTA_RETURN_IF_ERROR(_made->create(o.option, parent.string()));
        }
        auto lock = OutputLock::acquire(o.option, o.path, _shared);
        if (!lock) return lock.status();
        _locks.push_back(std::move(*lock));
    }
    return Status::ok();
}

}  // namespace vista
