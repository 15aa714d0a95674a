// Atomic file writes: every file vista writes appears whole or not at all.
//
// Contract: writeFileAtomic() writes `bytes` to "<path>.tmp.<pid>" in the
// same directory, fsyncs it and renames it over `path`. On any error the
// temporary file is removed, nothing is created at `path`, an existing file
// there is left untouched, and the Status names the path and the reason.
// tempPathFor() gives that temporary name (for writers that stream into it
// themselves and then commitTempFile() it). Thread compatible: distinct paths
// may be written concurrently.
//
// Special files: an output that exists (after symlinks) as a character or
// block device or a FIFO (/dev/null, /dev/full, a named pipe) is never
// replaced. It is written in place: opened for writing without creating,
// truncating, staging or renaming, every write and the close checked, so a
// full device (ENOSPC on /dev/full) or a reader that went away (EPIPE; the
// signal is not raised) is an error naming the path and the cause. A writer
// that needs a temporary (a seekable stream, a batch) gets one in the
// system's temporary directory (tempPathFor) and copies it in at the commit.
// A socket is refused (checkWritablePath; writing one fails naming it). A
// write into a device or pipe cannot be undone: what reached it before a
// failure stays there.
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "foundation/status.h"

namespace vista {

Status writeFileAtomic(const std::string& path, const std::string& bytes);
// "<path>.tmp.<pid>" beside a regular (or new) file; for a special file, a new
// name in the system's temporary directory ("vista.<pid>.<n>.<name>").
std::string tempPathFor(const std::string& path);
// Moves the finished temporary `tmp` (from tempPathFor) onto `path`: a rename
// for a regular file, a copy into a special file (in place) and the removal
// of `tmp`. On error `tmp` is removed and the Status names `path` and the cause.
Status commitTempFile(const std::string& tmp, const std::string& path);
// True when `path` exists (after symlinks) and is a character or block
// device, a FIFO or a socket.
bool isSpecialFile(const std::string& path);
// Checks, without creating anything, that a file can be written at `path`:
// not a directory, not a symbolic link loop or a dangling symbolic link, its
// directory exists (reachable: no loop, no component that is not a
// directory) and is writable; or `path` is a writable device or FIFO
// (written in place; a socket is refused). The error names `option` (the
// flag or field that gave the path), the path and the reason. Long jobs call
// it before they start, so they never fail at the end.
Status checkWritablePath(const std::string& option, const std::string& path);
// The same for an output directory that the job creates if missing: `path`
// is a writable directory, or it does not exist and its nearest existing
// ancestor is a writable directory (with `parentMustExist`: its parent is
// that directory). A device, FIFO or socket there is refused (a directory
// output is never written in place), and so are links that loop or dangle.
Status checkWritableDirectory(const std::string& option, const std::string& path, bool parentMustExist = false);
// strerror(errno) as a string (for messages).
std::string errnoText();

// Removes the leftovers of killed runs next to `path`: "<path>.tmp.<pid>",
// "<path>.stage.<pid>", "<path>.stage.<pid>.tmp.<pid>" and "<path>.prev.<pid>"
// whose process no longer exists (kill(pid, 0) fails
// with ESRCH). Files of live processes (a concurrent writer) are kept.
// Returns how many were removed. Called by every writer before it writes.
// A directory is listed once per process (its names that look like
// temporaries are remembered), so that writing N files into one directory
// costs N lookups, not N listings; a leftover that appears after that first
// listing (a run killed while this one goes on) is left for the next run.
// Thread-safe.
int removeStaleTemps(const std::string& path);

// Several outputs of one command committed together or not at all: write each
// output to stage(path) (with any atomic writer), then commit() renames every
// staged file over its path. A special file's output (see above) is staged
// in the temporary directory and copied into it at the commit, before any
// rename, so a failed write into a device (ENOSPC) leaves every regular
// output as it was. If commit() is never reached (an error, an
// exception) the destructor removes the staged files, so no output of a
// failed command appears. A rename failure in commit() is reported and the
// renames before it are undone and the staged files removed: each output
// that existed is kept under a second name ("<path>.prev.<pid>", a hard
// link, removed after the last rename) and put back, each that did not is
// removed. (Where hard links are not possible, a previous file renamed over
// before the failure stays replaced.)
class OutputBatch {
public:
    OutputBatch() = default;
    OutputBatch(const OutputBatch&) = delete;
    OutputBatch& operator=(const OutputBatch&) = delete;
    ~OutputBatch();
    std::string stage(const std::string& path);
    Status commit();

private:
    std::vector<std::pair<std::string, std::string>> _files;  // (staged, final)
    std::vector<bool> _special;                               // per file: the final path is a device or FIFO
    bool _committed = false;
};

// The directories a command creates for its outputs, removed again when a
// failed command leaves them empty: create() is std::filesystem::create_directories
// that remembers each directory it made; unless keep() was called, the
// destructor removes those that are empty, deepest first (one that holds something, such as the whole
// results a rerun resumes from, stays, and so do its ancestors). So a run
// that fails before it writes into a directory leaves no directory behind.
// Errors name `option`, the path and the reason. Not thread-safe.
class CreatedDirectories {
public:
    CreatedDirectories() = default;
    CreatedDirectories(const CreatedDirectories&) = delete;
    CreatedDirectories& operator=(const CreatedDirectories&) = delete;
    ~CreatedDirectories();
    Status create(const std::string& option, const std::string& path);
    // The command succeeded: every directory stays, empty or not.
    void keep() { _made.clear(); }

private:
    std::vector<std::string> _made;  // in the order made (parents first)
};

}  // namespace vista
