// Test helpers shared by the test executables: a private temporary directory
// (removed with everything in it, read-only entries included), whole-file reads
// and writes, and the list of entries under a directory.
#pragma once
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <system_error>

#include <gtest/gtest.h>
#include <stdlib.h>

namespace vista::test {

inline std::string readBytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    std::stringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

// Writes `text` to `path` as it is (binary), replacing what was there.
inline void writeText(const std::string& path, const std::string& text) {
    std::ofstream out(path, std::ios::binary);
    out << text;
}

// Every entry under `dir`, relative to it ("sub/file"); empty when `dir` does not exist.
inline std::set<std::string> listTree(const std::string& dir) {
    namespace fs = std::filesystem;
    std::set<std::string> names;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec))
        names.insert(fs::relative(it->path(), dir).string());
    return names;
}

class TempDir {
public:
    explicit TempDir(const std::string& prefix = "vista_test") {
        std::string tmpl = (std::filesystem::temp_directory_path() / (prefix + "_XXXXXX")).string();
        const char* d = ::mkdtemp(tmpl.data());
        EXPECT_NE(d, nullptr) << "cannot create a temporary directory";
        _path = d ? std::string(d) : std::filesystem::temp_directory_path().string();
    }
    ~TempDir() {
        namespace fs = std::filesystem;
        std::error_code ec;
        // Tests make entries read-only to provoke write errors: restore write access first.
        for (auto it = fs::recursive_directory_iterator(_path, ec); !ec && it != fs::recursive_directory_iterator();
             it.increment(ec))
            fs::permissions(it->path(), fs::perms::owner_write, fs::perm_options::add, ec);
        fs::permissions(_path, fs::perms::owner_all, fs::perm_options::add, ec);
        fs::remove_all(_path, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    std::string file(const std::string& name) const { return _path + "/" + name; }
    const std::string& path() const { return _path; }

private:
    std::string _path;
};

}  // namespace vista::test
