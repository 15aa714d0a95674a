// Shared command-line helpers for the subcommands.
//
// parseOrExit(): parses with CLI11; on --help prints help and returns 0; on a
// parse error, or an option given with an empty value (refuseEmptyValues,
// options.h), prints "vista <cmd>: <message>" and returns 2; returns -1 when
// parsing succeeded and the command should run.
#pragma once
#include <string>

#include <CLI/CLI.hpp>

#include "foundation/atomic_file.h"
#include "foundation/status.h"

namespace vista {

int parseOrExit(CLI::App& app, int argc, char** argv);
// Prints "vista <cmd>: <message>" to stderr and returns 2.
int reportBadInput(const std::string& cmd, const Status& s);
// The commands that draw with OpenGL (bench, view, render without --rig)
// need an X display: without one (DISPLAY unset or empty) prints "vista
// <cmd>: no X display ..." and returns 1, the exit code of an environment
// error (docs/reference/cli.md); returns -1 when DISPLAY is set. Called
// before any work, so nothing is left behind.
int requireDisplay(const std::string& cmd);
// Peak resident set size of this process in MiB.
double peakRssMb();

}  // namespace vista
