// One writer per output (output_lock.h).
#include "foundation/output_lock.h"

#include <cerrno>
#include <cstring>
#include <utility>

#include <fcntl.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>

#include "foundation/atomic_file.h"

namespace vista {

std::string OutputLock::lockPathFor(const std::string& path) {
    std::string p = path;
    while (p.size() > 1 && p.back() == '/') p.pop_back();
    return p + ".lock";
}

OutputLock::OutputLock(OutputLock&& other) noexcept
    : _lockPath(std::move(other._lockPath)), _fd(std::exchange(other._fd, -1)), _shared(other._shared) {
    other._lockPath.clear();
}

OutputLock& OutputLock::operator=(OutputLock&& other) noexcept {
    if (this != &other) {
        release();
        _lockPath = std::move(other._lockPath);
        other._lockPath.clear();
        _fd = std::exchange(other._fd, -1);
        _shared = other._shared;
    }
    return *this;
}

OutputLock::~OutputLock() { release(); }

void OutputLock::release() {
    if (_fd < 0) return;
    // Removed while still locked, so that whoever opened it meanwhile sees
    // that the path no longer names it. A shared holder removes it only when
    // it can have it alone (the last holder).
    if (!_shared || ::flock(_fd, LOCK_EX | LOCK_NB) == 0) ::unlink(_lockPath.c_str());
    ::close(_fd);
    _fd = -1;
    _lockPath.clear();
}

Result<OutputLock> OutputLock::acquire(const std::string& option, const std::string& path, bool shared) {
    if (path.empty() || isSpecialFile(path)) return OutputLock();
    const std::string lockPath = lockPathFor(path);
    const std::string where = "option " + option + " = '" + path + "'";
    for (int attempt = 0; attempt < 64; ++attempt) {
        const int fd = ::open(lockPath.c_str(), O_RDWR | O_CREAT | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK, 0644);
        if (fd < 0) {
            if (errno == ELOOP || errno == ENXIO || errno == EISDIR)
                return Status::error(where + ": its lock file '" + lockPath +
                                     "' exists and is not a vista lock file (an empty file); remove it");
            return Status::error(where + ": cannot create its lock file '" + lockPath + "': " + errnoText());
        }
        struct stat held {};
        if (::fstat(fd, &held) != 0 || !S_ISREG(held.st_mode) || held.st_size != 0) {
            ::close(fd);
            return Status::error(where + ": its lock file '" + lockPath +
                                 "' exists and is not a vista lock file (an empty file); remove it");
        }
        if (::flock(fd, (shared ? LOCK_SH : LOCK_EX) | LOCK_NB) != 0) {
            const int err = errno;
            ::close(fd);
            if (err == EWOULDBLOCK)
                return Status::error(where + ": another vista process is writing this output (it holds the lock '" +
                                     lockPath + "'); wait for it to finish or choose another output");
            return Status::error(where + ": cannot lock '" + lockPath + "': " + std::strerror(err));
        }
        struct stat now {};
        if (::stat(lockPath.c_str(), &now) == 0 && now.st_dev == held.st_dev && now.st_ino == held.st_ino) {
            OutputLock lock;
            lock._lockPath = lockPath;
            lock._fd = fd;
            lock._shared = shared;
            return Result<OutputLock>(std::move(lock));
        }
        ::close(fd);  // its holder released and removed it between our open and flock: take the new one
    }
    return Status::error(where + ": cannot lock '" + lockPath + "': it keeps being replaced");
}

}  // namespace vista
