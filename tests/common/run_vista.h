// Test helpers that run the built `vista` tool (VISTA_BINARY, a build
// dependency of every test executable) as a child process.
//
// runVista(): one whole run through the shell (`args` is a shell word list;
// `env`, if given, is "NAME=value ..." set for that run only); returns the
// exit code (-1 when it did not exit normally, e.g. killed; a shell may
// report a killed child as 128 + signal instead) and what it wrote to
// stderr; stdout is discarded.
// startVista(): starts a run without a shell and returns its pid at once (for
// tests that kill it); stdout and stderr go to /dev/null. The caller waits for it.
// expectRefusedBeforeTheInput(): for a run whose input is not a valid file
// (a run that read it would fail with that) and whose output cannot be
// written: exit code 2, the message names `option` and `reason` and not the
// input (the output is checked before any work), nothing new under `dir`.
#pragma once
#include <fcntl.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include "tests/common/temp_dir.h"

namespace vista::test {

struct CliRun {
    int code = -1;
    std::string err;
};

inline CliRun runVista(const std::string& args, const std::string& env = "") {
    TempDir tmp("vista_cli_err");
    const std::string errFile = tmp.file("stderr.txt");
    const int st = std::system(((env.empty() ? std::string() : env + " ") + std::string(VISTA_BINARY) + " " + args +
                                " 2>" + errFile + " >/dev/null")
                                   .c_str());
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

inline void expectRefusedBeforeTheInput(const std::string& dir, const std::string& args, const std::string& input,
                                        const std::string& option, const std::string& reason) {
    const std::set<std::string> before = listTree(dir);
    const CliRun r = runVista(args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_NE(r.err.find(option), std::string::npos) << args << ": " << r.err;
    EXPECT_NE(r.err.find(reason), std::string::npos) << args << ": " << r.err;
    const std::string inputName = std::filesystem::path(input).filename().string();
    EXPECT_EQ(r.err.find(inputName), std::string::npos) << args << ": the input was read first: " << r.err;
    EXPECT_EQ(listTree(dir), before) << args;
}

}  // namespace vista::test
