#include "cmd/cli.h"

#include <cstdio>
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
    return -1;
}

int reportBadInput(const std::string& cmd, const Status& s) {
    std::fprintf(stderr, "%s: %s\n", cmd.c_str(), s.message().c_str());
    return 2;
}

Status checkWritablePath(const std::string& option, const std::string& path) {
    namespace fs = std::filesystem;
    if (path.empty()) return Status::error("option " + option + ": empty path");
    std::error_code ec;
    fs::path p(path);
    if (fs::is_directory(p, ec)) return Status::error("option " + option + " = '" + path + "' is a directory, expected a file path");
    fs::path dir = p.has_parent_path() ? p.parent_path() : fs::path(".");
    if (!fs::is_directory(dir, ec))
        return Status::error("option " + option + " = '" + path + "': directory '" + dir.string() + "' does not exist");
    if (access(dir.c_str(), W_OK) != 0)
        return Status::error("option " + option + " = '" + path + "': directory '" + dir.string() + "' is not writable");
    return Status::ok();
}

double peakRssMb() {
    struct rusage ru {};
    getrusage(RUSAGE_SELF, &ru);
    return double(ru.ru_maxrss) / 1024.0;
}

}  // namespace vista
