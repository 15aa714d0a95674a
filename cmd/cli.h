// Shared command-line helpers for the subcommands.
//
// parseOrExit(): parses with CLI11; on --help prints help and returns 0; on a
// parse error prints "vista <cmd>: <message>" plus a hint and returns 2;
// returns -1 when parsing succeeded and the command should run.
#pragma once
#include <string>

#include <CLI/CLI.hpp>

#include "foundation/atomic_file.h"
#include "foundation/status.h"

namespace vista {

int parseOrExit(CLI::App& app, int argc, char** argv);
// Prints "vista <cmd>: <message>" to stderr and returns 2.
int reportBadInput(const std::string& cmd, const Status& s);
// Peak resident set size of this process in MiB.
double peakRssMb();

}  // namespace vista
