// Subcommands of the `vista` tool. Each takes the arguments after its name
// (argv[0] = "vista <name>") and returns the process exit code:
// 0 success, 2 bad input (message already printed), 1 internal failure.
#pragma once
#include <string>

#include "foundation/status.h"

namespace vista {

int runGen(int argc, char** argv);
int runPath(int argc, char** argv);
int runBench(int argc, char** argv);
int runView(int argc, char** argv);
int runBake(int argc, char** argv);
int runExport(int argc, char** argv);
// The --xodr path check shared by gen and export: ends in .xodr, writable.
Status checkXodrPath(const std::string& option, const std::string& path);
int runRender(int argc, char** argv);
int runTraffic(int argc, char** argv);

}  // namespace vista
