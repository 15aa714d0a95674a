// Shared command-line helpers for the subcommands.
//
// parseOrExit(): parses with CLI11; on --help prints help and returns 0; on a
// parse error prints "vista <cmd>: <message>" plus a hint and returns 2;
// returns -1 when parsing succeeded and the command should run.
#pragma once
#include <string>

#include <CLI/CLI.hpp>

#include "foundation/status.h"

namespace vista {

int parseOrExit(CLI::App& app, int argc, char** argv);
// Prints "vista <cmd>: <message>" to stderr and returns 2.
int reportBadInput(const std::string& cmd, const Status& s);
// Checks that `path` can be created (its directory exists and is writable)
// without creating it. Error names the option.
Status checkWritablePath(const std::string& option, const std::string& path);
// Peak resident set size of this process in MiB.
double peakRssMb();

}  // namespace vista
