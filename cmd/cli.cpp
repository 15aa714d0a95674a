#include "cmd/cli.h"

#include "cmd/options.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sys/resource.h>
#include <unistd.h>

namespace vista {

int parseOrExit(CLI::App& app, int argc, char** argv) {
    try {
        app.parse(argc, argv);
    } catch (const CLI::CallForHelp&) {
        std::printf("%s", app.help().c_str());
        return 0;
    } catch (const CLI::CallForAllHelp&) {
        std::printf("%s", app.help("", CLI::AppFormatMode::All).c_str());
        return 0;
    } catch (const CLI::ParseError& e) {
        std::fprintf(stderr, "%s: %s\nRun '%s --help' for the options.\n", app.get_name().c_str(), e.what(),
                     app.get_name().c_str());
        return 2;
    }
    if (Status s = refuseEmptyValues(app); !s) return reportBadInput(app.get_name(), s);
    return -1;
}

int reportBadInput(const std::string& cmd, const Status& s) {
    std::fprintf(stderr, "%s: %s\n", cmd.c_str(), s.message().c_str());
    return 2;
}

int requireDisplay(const std::string& cmd) {
    const char* display = std::getenv("DISPLAY");
    if (display && *display) return -1;
    std::fprintf(stderr,
                 "%s: no X display (DISPLAY is not set); run under `xvfb-run -a` on a machine without a screen\n",
                 cmd.c_str());
    return 1;
}

double peakRssMb() {
    struct rusage ru {};
    getrusage(RUSAGE_SELF, &ru);
    return double(ru.ru_maxrss) / 1024.0;
}

}  // namespace vista
