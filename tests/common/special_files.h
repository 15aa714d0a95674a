// Test helpers for outputs that are not regular files: private device nodes
// (mknod in a test's own directory, never the system's /dev/null) and a
// FIFO with a reader thread.
//
// makeDevice(): a character device node 1,`minor` (3 = null: swallows every
// write; 7 = full: every write fails with ENOSPC); false when mknod is not
// permitted (the tests run as root in CI; elsewhere they skip, naming the
// reason). isDevice(): `path` is still that device node (not replaced by a
// regular file). FifoReader: makes a FIFO and reads it on a thread until
// every writer closed it; finish() waits and returns the bytes (a writer
// that never came is stood in for, so finish() never hangs).
#pragma once
#include <fcntl.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <string>
#include <thread>

namespace vista::test {

constexpr unsigned kNullMinor = 3, kFullMinor = 7;
constexpr const char* kNoMknod = "mknod of a private device node is not permitted here (needs root, as in CI)";

inline bool makeDevice(const std::string& path, unsigned minor) {
    return ::mknod(path.c_str(), S_IFCHR | 0666, ::makedev(1, minor)) == 0;
}

inline bool isDevice(const std::string& path, unsigned minor) {
    struct stat st {};
    return ::lstat(path.c_str(), &st) == 0 && S_ISCHR(st.st_mode) && major(st.st_rdev) == 1 &&
           ::minor(st.st_rdev) == minor;
}

inline bool isFifo(const std::string& path) {
    struct stat st {};
    return ::lstat(path.c_str(), &st) == 0 && S_ISFIFO(st.st_mode);
}

class FifoReader {
public:
    explicit FifoReader(const std::string& path) : _path(path) {
        _made = ::mkfifo(path.c_str(), 0644) == 0;
        if (_made)
            _thread = std::thread([this] {
                const int fd = ::open(_path.c_str(), O_RDONLY);
                if (fd < 0) {
                    _done = true;
                    return;
                }
                char buf[1 << 16];
                for (ssize_t n; (n = ::read(fd, buf, sizeof buf)) > 0;) _bytes.append(buf, size_t(n));
                ::close(fd);
                _done = true;
            });
    }
    ~FifoReader() { finish(); }
    FifoReader(const FifoReader&) = delete;
    FifoReader& operator=(const FifoReader&) = delete;
    bool made() const { return _made; }
    const std::string& finish() {
        if (_thread.joinable()) {
            // A reader still waiting for a writer: open and close the write end.
            while (!_done) {
                const int fd = ::open(_path.c_str(), O_WRONLY | O_NONBLOCK);
                if (fd >= 0) ::close(fd);
                std::this_thread::sleep_for(std::chrono::milliseconds(10));
            }
            _thread.join();
        }
        return _bytes;
    }

private:
    std::string _path, _bytes;
    bool _made = false;
    std::atomic<bool> _done{false};
    std::thread _thread;
};

}  // namespace vista::test
