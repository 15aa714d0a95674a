// Subcommands of the `vista` tool. Each takes the arguments after its name
// (argv[0] = "vista <name>") and returns the process exit code:
// 0 success, 2 bad input (message already printed), 1 internal failure.
#pragma once

namespace vista {

int runGen(int argc, char** argv);
int runPath(int argc, char** argv);
int runBench(int argc, char** argv);
int runView(int argc, char** argv);
int runBake(int argc, char** argv);
int runRender(int argc, char** argv);

}  // namespace vista
