// Test helper for fault tests: a tmpfs mounted on an existing directory for
// the life of the object (a small disk: options "size=2m"; a read-only
// directory: flags MS_RDONLY). Mounting needs root with CAP_SYS_ADMIN; when
// it fails, mounted() is false and why() says why (for GTEST_SKIP). The
// destructor always unmounts (lazily, so an open file cannot keep the mount).
// Declare it after the TempDir holding the mount point, so it goes first.
// ReadOnlyDir: an existing directory in which no file can be created, for
// a normal user by its permissions (0555), for root (who ignores them) by a
// read-only tmpfs over it; ready() false and why() when neither works.
#pragma once
#include <sys/mount.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <string>

namespace vista::test {

class TmpfsMount {
public:
    TmpfsMount(const std::string& dir, const std::string& options, unsigned long flags = 0) {
        if (::geteuid() != 0) {
            _why = "not running as root (mount -t tmpfs needs root)";
            return;
        }
        if (::mount("tmpfs", dir.c_str(), "tmpfs", flags, options.c_str()) != 0) {
            _why = "mount -t tmpfs -o " + options + " tmpfs " + dir + " failed: " + std::strerror(errno) +
                   " (no CAP_SYS_ADMIN, e.g. in a container?)";
            return;
        }
        _dir = dir;
    }
    ~TmpfsMount() {
        if (!_dir.empty()) ::umount2(_dir.c_str(), MNT_DETACH);
    }
    TmpfsMount(const TmpfsMount&) = delete;
    TmpfsMount& operator=(const TmpfsMount&) = delete;
    bool mounted() const { return !_dir.empty(); }
    const std::string& why() const { return _why; }

private:
    std::string _dir, _why;
};

class ReadOnlyDir {
public:
    explicit ReadOnlyDir(const std::string& dir) : _dir(dir) {
        if (::geteuid() == 0) _mount = std::make_unique<TmpfsMount>(dir, "size=64k", MS_RDONLY);
        else if (::chmod(dir.c_str(), 0555) != 0) _why = "chmod 0555 " + dir + " failed: " + std::strerror(errno);
    }
    ~ReadOnlyDir() {
        if (!_mount) ::chmod(_dir.c_str(), 0755);
    }
    ReadOnlyDir(const ReadOnlyDir&) = delete;
    ReadOnlyDir& operator=(const ReadOnlyDir&) = delete;
    bool ready() const { return _mount ? _mount->mounted() : _why.empty(); }
    const std::string& why() const { return _mount ? _mount->why() : _why; }

private:
    std::string _dir, _why;
    std::unique_ptr<TmpfsMount> _mount;
};

}  // namespace vista::test
