// SUMO's programs (netconvert, sumo) found on the system and run as child
// processes: vista simulates no traffic itself (docs/guide/traffic.md).
//
// Contract:
// - findSumo() looks the programs up on PATH (or VISTA_SUMO_BIN, a folder
//   holding both); SUMO_HOME is taken from the environment or derived from
//   the install prefix (<prefix>/share/sumo, where Debian's sumo-tools puts
//   the type maps netconvert reads). A missing program is an error that says
//   what to install.
// - runSumoProgram() runs one program with an argument vector (no shell) in
//   `workDir`, its stdout and stderr to `logFile`, and waits. The child's
//   environment is the caller's with SUMO_HOME set and LD_PRELOAD removed (a
//   sanitizer runtime preloaded into vista's tests must not reach a program
//   that is not built with it). A failure to start, a signal or a non-zero
//   exit is an error naming the program, its exit status and the last error
//   lines it printed.
// - stripGeneratedDate() removes the wall-clock date SUMO writes into the
//   comment at the head of its XML outputs ("generated on <date> by"), so the
//   same inputs give the same bytes. The rest of the file is unchanged; the
//   file is rewritten atomically. A file without that comment is left as is.
// Thread compatible: distinct work directories may run concurrently.
#pragma once
#include <string>
#include <vector>

#include "foundation/status.h"

namespace vista {

struct SumoTools {
    std::string netconvert;  // absolute paths of the programs
    std::string sumo;
    std::string home;     // SUMO_HOME for the children ("" when unknown)
    std::string version;  // "1.15.0", from `sumo --version`
};

Result<SumoTools> findSumo();

Status runSumoProgram(const SumoTools& tools, const std::string& program, const std::vector<std::string>& args,
                      const std::string& workDir, const std::string& logFile);

Status stripGeneratedDate(const std::string& path);

// The lines of a SUMO log that start with "Error" (at most `maxLines`, last
// ones kept), joined by "; ", for messages.
std::string sumoErrorLines(const std::string& logText, int maxLines = 3);

}  // namespace vista
