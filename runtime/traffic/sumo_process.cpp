#include "runtime/traffic/sumo_process.h"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "foundation/atomic_file.h"

extern char** environ;

namespace vista {

namespace fs = std::filesystem;

namespace {

// The first executable `name` in the folders of `pathList` (':'-separated).
std::string findOnPath(const std::string& name, const std::string& pathList) {
    size_t begin = 0;
    while (begin <= pathList.size()) {
        size_t end = pathList.find(':', begin);
        if (end == std::string::npos) end = pathList.size();
        const std::string dir = pathList.substr(begin, end - begin);
        if (!dir.empty()) {
            const std::string candidate = dir + "/" + name;
            if (::access(candidate.c_str(), X_OK) == 0 && fs::is_regular_file(candidate)) return candidate;
        }
        begin = end + 1;
    }
    return "";
}

// Runs `argv` and returns its stdout (for `sumo --version`); "" on failure.
std::string firstLineOf(const std::string& program, const std::string& arg) {
    std::string cmd = "'" + program + "' " + arg + " 2>/dev/null";
    FILE* f = ::popen(cmd.c_str(), "r");
    if (!f) return "";
    char buf[512];
    std::string line;
    if (std::fgets(buf, sizeof buf, f)) line = buf;
    ::pclose(f);
    while (!line.empty() && (line.back() == '\n' || line.back() == '\r')) line.pop_back();
    return line;
}

std::string versionOf(const std::string& sumo) {
    // "Eclipse SUMO sumo Version 1.15.0" (the last word).
    const std::string line = firstLineOf(sumo, "--version");
    const size_t at = line.rfind("Version ");
    return at == std::string::npos ? std::string() : line.substr(at + 8);
}

std::vector<std::string> childEnvironment(const std::string& home) {
    std::vector<std::string> env;
    for (char** e = environ; e && *e; ++e) {
        const std::string kv = *e;
        if (kv.rfind("LD_PRELOAD=", 0) == 0) continue;
        if (!home.empty() && kv.rfind("SUMO_HOME=", 0) == 0) continue;
        env.push_back(kv);
    }
    if (!home.empty()) env.push_back("SUMO_HOME=" + home);
    return env;
}

std::string readAll(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

Result<SumoTools> findSumo() {
    SumoTools t;
    std::string pathList;
    if (const char* bin = std::getenv("VISTA_SUMO_BIN"); bin && *bin) pathList = bin;
    else if (const char* path = std::getenv("PATH")) pathList = path;
    t.netconvert = findOnPath("netconvert", pathList);
    t.sumo = findOnPath("sumo", pathList);
    if (t.sumo.empty() || t.netconvert.empty())
        return Status::error(std::string("SUMO is not installed: '") + (t.sumo.empty() ? "sumo" : "netconvert") +
                             "' is not on PATH (Debian: apt-get install sumo sumo-tools; or set VISTA_SUMO_BIN to "
                             "the folder that holds sumo and netconvert)");
    if (const char* home = std::getenv("SUMO_HOME"); home && *home) {
        t.home = home;
    } else {
        std::error_code ec;
        fs::path real = fs::canonical(t.sumo, ec);
        const fs::path prefix = (ec ? fs::path(t.sumo) : real).parent_path().parent_path();
        if (fs::exists(prefix / "share" / "sumo" / "data", ec)) t.home = (prefix / "share" / "sumo").string();
    }
    t.version = versionOf(t.sumo);
    if (t.version.empty()) return Status::error("'" + t.sumo + "' does not answer --version: is it SUMO's sumo?");
    return t;
}

std::string sumoErrorLines(const std::string& logText, int maxLines) {
    std::vector<std::string> lines;
    std::istringstream in(logText);
    for (std::string line; std::getline(in, line);)
        if (line.rfind("Error", 0) == 0) lines.push_back(line);
    if (lines.empty()) {
        // No line marked as an error: the last non-empty line says most.
        std::istringstream again(logText);
        std::string last;
        for (std::string line; std::getline(again, line);)
            if (!line.empty()) last = line;
        if (!last.empty()) lines.push_back(last);
    }
    std::string out;
    const size_t first = lines.size() > size_t(maxLines) ? lines.size() - size_t(maxLines) : 0;
    for (size_t i = first; i < lines.size(); ++i) out += (out.empty() ? "" : "; ") + lines[i];
    return out;
}

Status runSumoProgram(const SumoTools& tools, const std::string& program, const std::vector<std::string>& args,
                      const std::string& workDir, const std::string& logFile) {
    const std::string name = fs::path(program).filename().string();
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, logFile.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
    // The child starts in workDir so that SUMO's outputs and the paths it
    // echoes into them are relative names: /bin/sh enters the folder and
    // execs the program, both passed as positional arguments (no quoting).
    std::vector<std::string> argvText = {"/bin/sh", "-c", "cd \"$1\" && shift && exec \"$@\"", "sh", workDir, program};
    argvText.insert(argvText.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : argvText) argv.push_back(a.data());
    argv.push_back(nullptr);
    std::vector<std::string> envText = childEnvironment(tools.home);
    std::vector<char*> envp;
    for (auto& e : envText) envp.push_back(e.data());
    envp.push_back(nullptr);
    pid_t pid = 0;
    const int rc = ::posix_spawn(&pid, "/bin/sh", &actions, nullptr, argv.data(), envp.data());
    posix_spawn_file_actions_destroy(&actions);
    if (rc != 0) return Status::error("cannot start " + program + ": " + std::strerror(rc));
    int status = 0;
    while (::waitpid(pid, &status, 0) < 0) {
        if (errno != EINTR) return Status::error("waiting for " + name + ": " + errnoText());
    }
    if (WIFSIGNALED(status))
        return Status::error(name + " was killed by signal " + std::to_string(WTERMSIG(status)) +
                             "; it said: " + sumoErrorLines(readAll(logFile)));
    if (WEXITSTATUS(status) != 0)
        return Status::error(name + " failed (exit " + std::to_string(WEXITSTATUS(status)) +
                             "); it said: " + sumoErrorLines(readAll(logFile)));
    return Status::ok();
}

Status stripGeneratedDate(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) return Status::error("cannot read '" + path + "': " + errnoText());
    // The comment is within the first lines; read a head, fix it, copy the rest.
    std::string head(4096, '\0');
    in.read(head.data(), std::streamsize(head.size()));
    head.resize(size_t(in.gcount()));
    const std::string mark = "<!-- generated on ";
    const size_t at = head.find(mark);
    if (at == std::string::npos) return Status::ok();
    const size_t by = head.find(" by ", at + mark.size());
    if (by == std::string::npos || head.find('\n', at) < by) return Status::ok();
    std::string fixed = head.substr(0, at) + "<!-- generated" + head.substr(by);
    const std::string tmp = tempPathFor(path);
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) return Status::error("cannot write '" + tmp + "': " + errnoText());
        out << fixed;
        if (in && in.peek() != std::char_traits<char>::eof()) out << in.rdbuf();
        out.flush();
        if (!out) {
            std::error_code ec;
            fs::remove(tmp, ec);
            return Status::error("cannot write '" + tmp + "': " + errnoText());
        }
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
        std::error_code ec;
        fs::remove(tmp, ec);
        return Status::error("cannot rename '" + tmp + "' to '" + path + "': " + errnoText());
    }
    return Status::ok();
}

}  // namespace vista
