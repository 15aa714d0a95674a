// One writer per output: an advisory lock (flock) that a command takes on
// each of its outputs before any work, so that a second vista process
// writing the same output stops at once instead of mixing its files with the
// first's or failing at its end.
//
// The lock of an output PATH (a file or a directory) is the empty file
// "PATH.lock" beside it (a trailing '/' of a directory is dropped first).
// acquire() creates it if missing and locks it without waiting: exclusive,
// or shared (the shards of one job, which write side by side; an exclusive
// holder and shared holders exclude each other). When another process holds
// it the Status is "option -o = 'PATH': another vista process is writing
// this output (it holds the lock 'PATH.lock'); wait for it to finish or
// choose another output". The lock file is removed when the lock is
// released (the destructor; a shared holder removes it only when it is the
// last holder), so a finished run leaves none; one a killed run leaves
// behind is empty, holds no lock and is taken over by the next run. An
// acquirer that locked a file the holder removed meanwhile notices (the
// path no longer names the inode it locked) and takes the new one.
// A "PATH.lock" that is not an empty regular file (not ours) is refused,
// never removed. Devices and FIFOs written in place (atomic_file.h) take no
// lock (no file is created beside /dev/null); acquire() then returns an
// empty OutputLock. Errors name `option`, the path and the lock file.
// Thread compatible; locks are per open file, so two OutputLocks of one
// process on one output exclude each other too.
#pragma once
#include <string>

#include "foundation/status.h"

namespace vista {

class OutputLock {
public:
    OutputLock() = default;
    OutputLock(OutputLock&& other) noexcept;
    OutputLock& operator=(OutputLock&& other) noexcept;
    OutputLock(const OutputLock&) = delete;
    OutputLock& operator=(const OutputLock&) = delete;
    ~OutputLock();

    static Result<OutputLock> acquire(const std::string& option, const std::string& path, bool shared);
    // "PATH.lock" for `path` (a trailing '/' dropped).
    static std::string lockPathFor(const std::string& path);
    // The lock file held, "" when none.
    const std::string& lockPath() const { return _lockPath; }

private:
    void release();
    std::string _lockPath;
    int _fd = -1;
    bool _shared = false;
};

}  // namespace vista
