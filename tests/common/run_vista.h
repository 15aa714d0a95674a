// Test helpers that run the built `vista` tool (VISTA_BINARY, a build
// dependency of every test executable) as a child process.
//
// runVista(): one whole run through the shell (`args` is a shell word list);
// returns the exit code (-1 when it did not exit normally, e.g. killed) and
// what it wrote to stderr; stdout is discarded.
// startVista(): starts a run without a shell and returns its pid at once (for
// tests that kill it); stdout and stderr go to /dev/null. The caller waits for it.
#pragma once
#include <fcntl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <string>
#include <vector>

#include "tests/common/temp_dir.h"

namespace vista::test {

struct CliRun {
    int code = -1;
    std::string err;
};

inline CliRun runVista(const std::string& args) {
    TempDir tmp("vista_cli_err");
    const std::string errFile = tmp.file("stderr.txt");
    const int st = std::system((std::string(VISTA_BINARY) + " " + args + " 2>" + errFile + " >/dev/null").c_str());
    CliRun r;
    r.code = WIFEXITED(st) ? WEXITSTATUS(st) : -1;
    r.err = readBytes(errFile);
    return r;
}

inline pid_t startVista(const std::vector<std::string>& args) {
    std::vector<char*> argv{const_cast<char*>(VISTA_BINARY)};
    for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int devNull = ::open("/dev/null", O_WRONLY);
        ::dup2(devNull, 1);
        ::dup2(devNull, 2);
        ::execv(VISTA_BINARY, argv.data());
        ::_exit(127);
    }
    return pid;
}

}  // namespace vista::test
