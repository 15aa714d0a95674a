// One rule for the files a command reads and writes: every path resolved up
// front, no two outputs are the same file, no output is one of the
// command's inputs, and one writer per output.
//
// Every command lists its outputs and inputs (option name and path as the
// user gave them) in a CommandFiles and calls check() before it reads or
// writes anything, keeping the object alive until it has written its
// outputs. check() then, in this order:
//  1. the aliasing rule: two paths are the same file when, after symlinks,
//     "." and "..", they name the same directory entry: the real path of the
//     parent directory plus the last component, or, when both exist, the
//     same device and inode (hard links too). An error names both options
//     and the path, e.g. "options -o and --stats name the same file
//     'c.osgb': give each output its own path". Two outputs that are one
//     character device (/dev/null twice) are allowed;
//  2. resolves every path once: an output file is checkWritablePath, an
//     output directory checkWritableDirectory (atomic_file.h: symbolic link
//     loops, dangling links, a missing or unreachable directory, a device
//     or pipe where a directory is expected are refused); an input is
//     checkInputPath below;
//  3. takes the lock of every output (output_lock.h), exclusive, or shared
//     after shareOutputs(true) (the shards of one job), creating the missing
//     parents of an output directory that the command creates anyway (they
//     are removed again if left empty). The locks are held while the object
//     lives.
// Errors name the option and the path; nothing is left behind by a refusal.
// The outputs are then written through an OutputBatch (atomic_file.h): all
// of them appear, or none. Empty paths (options not given) are ignored.
// Thread compatible.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "foundation/atomic_file.h"
#include "foundation/output_lock.h"
#include "foundation/status.h"

namespace vista {

class CommandFiles {
public:
    CommandFiles() = default;
    CommandFiles(CommandFiles&&) = default;
    CommandFiles& operator=(CommandFiles&&) = default;
    // `option` is the flag ("-o", "--stats") or the argument's name ("city").
    CommandFiles& input(const std::string& option, const std::string& path);
    // A file output (written whole; a device or FIFO written in place).
    CommandFiles& output(const std::string& option, const std::string& path);
    // A directory output. `parentMustExist`: the command refuses to create
    // its parent (render --out); otherwise missing parents are created.
    CommandFiles& outputDirectory(const std::string& option, const std::string& path, bool parentMustExist = false);
    CommandFiles& shareOutputs(bool shared);
    // Only on a named object: the locks live as long as it does.
    Status check() &;

private:
    struct Named {
        std::string option, path;
        bool directory = false, parentMustExist = false;
    };
    std::vector<Named> _inputs, _outputs;
    bool _shared = false;
    std::unique_ptr<CreatedDirectories> _made;  // destroyed after the locks (declared before them)
    std::vector<OutputLock> _locks;
};

// An input path resolves: it exists and is reachable, or the error names
// `option`, the path and why: "is a symbolic link loop (too many levels of
// symbolic links)", "is a dangling symbolic link (its target 'T' does not
// exist)", "does not exist", "cannot be reached: Permission denied". What
// the file holds is its reader's business (input_file.h).
Status checkInputPath(const std::string& option, const std::string& path);

// True when `a` and `b` name the same file (the rule above).
bool sameFile(const std::string& a, const std::string& b);

}  // namespace vista
