// Bounded reads of user files (input_file.h).
#include "foundation/input_file.h"

#include <cerrno>
#include <algorithm>
#include <cstring>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include "foundation/number_text.h"

namespace vista {

std::string byteLimitText(uint64_t bytes) {
    if (bytes >= (uint64_t(1) << 30) && bytes % (uint64_t(1) << 30) == 0) return std::to_string(bytes >> 30) + " GiB";
    if (bytes >= kMiB && bytes % kMiB == 0) return std::to_string(bytes >> 20) + " MiB";
    if (bytes >= 1024 && bytes % 1024 == 0) return std::to_string(bytes >> 10) + " KiB";
    return std::to_string(bytes) + " bytes";
}

namespace {

std::string named(const std::string& kind, const std::string& path) { return kind + " '" + echoText(path) + "'"; }

Status checkStat(const std::string& kind, const std::string& path, const struct stat& st, uint64_t maxBytes) {
    if (S_ISDIR(st.st_mode)) return Status::error(named(kind, path) + " is a directory, expected a file");
    if (!S_ISREG(st.st_mode))
        return Status::error(named(kind, path) + " is not a regular file (a device, pipe or socket), expected a file");
    if (maxBytes > 0 && uint64_t(st.st_size) > maxBytes)
        return Status::error(named(kind, path) + " is " + std::to_string(uint64_t(st.st_size)) +
                             " bytes, more than the limit of " + byteLimitText(maxBytes) + " for a " + kind);
    return Status::ok();
}

}  // namespace

Status checkInputFile(const std::string& kind, const std::string& path, uint64_t maxBytes) {
    if (path.empty()) return Status::error(kind + ": empty path");
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0)
        return Status::error(named(kind, path) + " cannot be opened: " + std::strerror(errno));
    return checkStat(kind, path, st, maxBytes);
}

Result<std::string> readInputFile(const std::string& kind, const std::string& path, uint64_t maxBytes) {
    VISTA_RETURN_IF_ERROR(checkInputFile(kind, path, maxBytes));
    // O_NONBLOCK: a FIFO swapped in after the check does not block the open.
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
    if (fd < 0) return Status::error(named(kind, path) + " cannot be opened: " + std::strerror(errno));
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
        ::close(fd);
        return Status::error(named(kind, path) + " is not a regular file (a device, pipe or socket), expected a file");
    }
    std::string text;
    const uint64_t cap = maxBytes > 0 ? maxBytes : UINT64_MAX - 1;
    text.reserve(size_t(std::min<uint64_t>(uint64_t(st.st_size), cap)));
    char buf[1 << 16];
    for (;;) {
        const ssize_t n = ::read(fd, buf, sizeof buf);
        if (n < 0 && errno == EINTR) continue;
        if (n < 0) {
            const std::string e = std::strerror(errno);
            ::close(fd);
            return Status::error(named(kind, path) + " cannot be read: " + e);
        }
        if (n == 0) break;
        text.append(buf, size_t(n));
        if (uint64_t(text.size()) > cap) {
            ::close(fd);
            return Status::error(named(kind, path) + " is more than the limit of " + byteLimitText(maxBytes) +
                                 " for a " + kind);
        }
    }
    ::close(fd);
    return text;
}

}  // namespace vista
