// One rule for the files a command writes: no two outputs are the same file,
// and no output is one of the command's inputs.
//
// Every command lists its outputs and inputs (option name and path as the
// user gave them) in a CommandFiles and calls check() before it reads or
// writes anything. Two paths are the same file when, after symlinks, "." and
// "..", they name the same directory entry: the real path of the parent
// directory plus the last component, or, when both exist, the same device
// and inode (hard links too). An error names both options and the path, e.g.
// "options -o and --stats name the same file 'c.osgb': give each output its
// own path". The outputs are then written through an OutputBatch
// (atomic_file.h): all of them appear, or none. Empty paths (options not
// given) are ignored. Thread compatible.
#pragma once
#include <string>
#include <vector>

#include "foundation/status.h"

namespace vista {

class CommandFiles {
public:
    // `option` is the flag ("-o", "--stats") or the argument's name ("city").
    CommandFiles& input(const std::string& option, const std::string& path);
    CommandFiles& output(const std::string& option, const std::string& path);
    Status check() const;

private:
    struct Named {
        std::string option, path;
    };
    std::vector<Named> _inputs, _outputs;
};

// True when `a` and `b` name the same file (the rule above).
bool sameFile(const std::string& a, const std::string& b);

}  // namespace vista
