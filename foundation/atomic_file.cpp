// Atomic file writes (atomic_file.h).
#include "foundation/atomic_file.h"

#include <cerrno>
#include <cstring>
#include <filesystem>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace vista {

std::string errnoText() { return std::strerror(errno); }

std::string tempPathFor(const std::string& path) { return path + ".tmp." + std::to_string(::getpid()); }

Status writeFileAtomic(const std::string& path, const std::string& bytes) {
    if (path.empty()) return Status::error("cannot write file: empty path");
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
        p += w; n -= size_t(w);
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
    if (fs::is_directory(p, ec)) return Status::error("option " + option + " = '" + path + "' is a directory, expected a file path");
    fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec))
        return Status::error("option " + option + " = '" + path + "': directory '" + dir.string() + "' does not exist");
    if (access(dir.c_str(), W_OK) != 0)
        return Status::error("option " + option + " = '" + path + "': directory '" + dir.string() + "' is not writable");
    return Status::ok();
}

}  // namespace vista
