// Dataset manifest parsing (see dataset_manifest.h).
#include "runtime/scene/dataset_manifest.h"

#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <set>

#include <nlohmann/json.hpp>

#include "foundation/input_file.h"

namespace vista {

namespace {

namespace fs = std::filesystem;
using Json = nlohmann::json;

// Errors name the manifest and the field: "dataset 'm.json': paths[1].seed: ...".
class Fields {
public:
    explicit Fields(std::string source) : _source(std::move(source)) {}
    Status error(const std::string& field, const std::string& why) const {
        return Status::error("dataset '" + _source + "': " + field + ": " + why);
    }
    static std::string shown(const Json& v) {
        std::string s = v.dump(-1, ' ', true, Json::error_handler_t::replace);
        return s.size() > 60 ? s.substr(0, 57) + "..." : s;
    }
    // Every key of `o` is one of `known`.
    Status onlyKnown(const Json& o, const std::string& field, const std::set<std::string>& known) const {
        for (const auto& [key, value] : o.items())
            if (!known.count(key)) {
                std::string list;
                for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
                return error(field.empty() ? key : field + "." + key, "unknown key (known: " + list + ")");
            }
        return Status::ok();
    }
    Status string(const Json& o, const std::string& field, const char* key, std::optional<std::string>& out) const {
        if (!o.contains(key)) return Status::ok();
        const Json& v = o[key];
        if (!v.is_string() || v.get<std::string>().empty())
            return error(field + "." + key, "expected a non-empty string, got " + shown(v));
        out = v.get<std::string>();
        return Status::ok();
    }
    Status number(const Json& o, const std::string& field, const char* key, std::optional<double>& out) const {
        if (!o.contains(key)) return Status::ok();
        const Json& v = o[key];
        if (!v.is_number() || !std::isfinite(v.get<double>()))
            return error(field + "." + key, "expected a finite number, got " + shown(v));
        out = v.get<double>();
        return Status::ok();
    }
    Status boolean(const Json& o, const std::string& field, const char* key, std::optional<bool>& out) const {
        if (!o.contains(key)) return Status::ok();
        const Json& v = o[key];
        if (!v.is_boolean()) return error(field + "." + key, "expected true or false, got " + shown(v));
        out = v.get<bool>();
        return Status::ok();
    }
    Status whole(const Json& o, const std::string& field, const char* key, uint64_t lo, uint64_t hi,
                 std::optional<uint64_t>& out) const {
        if (!o.contains(key)) return Status::ok();
        const Json& v = o[key];
        const std::string range = std::to_string(lo) + " .. " + std::to_string(hi);
        if (!v.is_number_unsigned() && !v.is_number_integer())
            return error(field + "." + key, "expected a whole number in " + range + ", got " + shown(v));
        if (v.is_number_integer() && !v.is_number_unsigned() && v.get<int64_t>() < 0)
            return error(field + "." + key, shown(v) + " out of range " + range);
        const uint64_t x = v.get<uint64_t>();
        if (x < lo || x > hi) return error(field + "." + key, shown(v) + " out of range " + range);
        out = x;
        return Status::ok();
    }
    const std::string& source() const { return _source; }

private:
    std::string _source;
};

bool goodName(const std::string& n) {
    if (n.empty() || n.size() > 64 || n[0] == '.') return false;
    for (char c : n)
        if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.')) return false;
    return true;
}

// The entry's name: its "name", or its file's name without the extension.
Status entryName(const Fields& f, const Json& o, const std::string& field, const std::string& file,
                 std::set<std::string>& seen, std::string& out) {
    std::optional<std::string> name;
    VISTA_RETURN_IF_ERROR(f.string(o, field, "name", name));
    const std::string where = name ? field + ".name" : field + ".file";
    if (name) out = *name;
    else if (!file.empty()) out = fs::path(file).filename().replace_extension().string();
    else return f.error(field + ".name", "missing (an entry without a file needs a name)");
    if (!goodName(out))
        return f.error(where, "name '" + out +
                                  "' is not 1 .. 64 characters of A-Z a-z 0-9 _ - . (not starting with '.'); "
                                  "give a \"name\"");
    if (!seen.insert(out).second) return f.error(where, "name '" + out + "' used twice in the list");
    return Status::ok();
}

std::string resolved(const std::string& file, const std::string& baseDir) {
    if (file.empty() || fs::path(file).is_absolute() || baseDir.empty()) return file;
    return (fs::path(baseDir) / file).lexically_normal().string();
}

// A list: a non-empty array.
Status list(const Fields& f, const Json& root, const char* key) {
    if (!root.contains(key)) return f.error(key, "missing (a non-empty list)");
    if (!root[key].is_array() || root[key].empty())
        return f.error(key, "expected a non-empty list, got " + Fields::shown(root[key]));
    return Status::ok();
}

Status parseCities(const Fields& f, const Json& root, const std::string& baseDir, DatasetManifest& m) {
    VISTA_RETURN_IF_ERROR(list(f, root, "cities"));
    std::set<std::string> seen;
    for (size_t i = 0; i < root["cities"].size(); ++i) {
        const std::string field = "cities[" + std::to_string(i) + "]";
        Json o = root["cities"][i];
        if (o.is_string()) o = Json{{"file", o}};
        if (!o.is_object())
            return f.error(field, "expected a file name or an object with \"file\", got " + Fields::shown(o));
        VISTA_RETURN_IF_ERROR(f.onlyKnown(o, field, {"name", "file"}));
        std::optional<std::string> file;
        VISTA_RETURN_IF_ERROR(f.string(o, field, "file", file));
        if (!file) return f.error(field + ".file", "missing (the city file or DIR.paged)");
        DatasetCity c;
        c.file = resolved(*file, baseDir);
        VISTA_RETURN_IF_ERROR(entryName(f, o, field, *file, seen, c.name));
        m.cities.push_back(std::move(c));
    }
    return Status::ok();
}

Status parsePaths(const Fields& f, const Json& root, const std::string& baseDir, DatasetManifest& m) {
    VISTA_RETURN_IF_ERROR(list(f, root, "paths"));
    std::set<std::string> seen;
    for (size_t i = 0; i < root["paths"].size(); ++i) {
        const std::string field = "paths[" + std::to_string(i) + "]";
        const Json& o = root["paths"][i];
        if (!o.is_object()) return f.error(field, "expected an object, got " + Fields::shown(o));
        VISTA_RETURN_IF_ERROR(
            f.onlyKnown(o, field, {"name", "file", "seed", "kind", "route", "duration", "run_up", "lht"}));
        DatasetPath p;
        std::optional<std::string> file;
        VISTA_RETURN_IF_ERROR(f.string(o, field, "file", file));
        VISTA_RETURN_IF_ERROR(f.whole(o, field, "seed", 0, std::numeric_limits<uint64_t>::max(), p.seed));
        VISTA_RETURN_IF_ERROR(f.string(o, field, "kind", p.kind));
        VISTA_RETURN_IF_ERROR(f.string(o, field, "route", p.route));
        VISTA_RETURN_IF_ERROR(f.number(o, field, "duration", p.duration));
        VISTA_RETURN_IF_ERROR(f.number(o, field, "run_up", p.runUp));
        VISTA_RETURN_IF_ERROR(f.boolean(o, field, "lht", p.lht));
        if (file) {
            for (const char* k : {"seed", "kind", "route", "duration", "run_up", "lht"})
                if (o.contains(k))
                    return f.error(field + "." + k, "does not apply with \"file\" (a recorded path is not generated)");
            p.file = resolved(*file, baseDir);
        }
        VISTA_RETURN_IF_ERROR(entryName(f, o, field, file.value_or(""), seen, p.name));
        m.paths.push_back(std::move(p));
    }
    return Status::ok();
}

Status parseRigs(const Fields& f, const Json& root, const std::string& baseDir, DatasetManifest& m) {
    VISTA_RETURN_IF_ERROR(list(f, root, "rigs"));
    std::set<std::string> seen;
    for (size_t i = 0; i < root["rigs"].size(); ++i) {
        const std::string field = "rigs[" + std::to_string(i) + "]";
        const Json& o = root["rigs"][i];
        if (!o.is_object()) return f.error(field, "expected an object, got " + Fields::shown(o));
        VISTA_RETURN_IF_ERROR(f.onlyKnown(o, field, {"name", "file", "size", "fov", "mode", "channels"}));
        DatasetRig r;
        std::optional<std::string> file;
        VISTA_RETURN_IF_ERROR(f.string(o, field, "file", file));
        VISTA_RETURN_IF_ERROR(f.string(o, field, "size", r.size));
        VISTA_RETURN_IF_ERROR(f.number(o, field, "fov", r.fov));
        VISTA_RETURN_IF_ERROR(f.string(o, field, "mode", r.mode));
        VISTA_RETURN_IF_ERROR(f.string(o, field, "channels", r.channels));
        if (file) {
            for (const char* k : {"size", "fov", "mode", "channels"})
                if (o.contains(k))
                    return f.error(field + "." + k,
                                   "does not apply with \"file\" (the rig file gives each sensor's model, size and "
                                   "channels)");
            r.file = resolved(*file, baseDir);
        }
        VISTA_RETURN_IF_ERROR(entryName(f, o, field, file.value_or(""), seen, r.name));
        m.rigs.push_back(std::move(r));
    }
    return Status::ok();
}

Status parseOptions(const Fields& f, const Json& root, DatasetManifest& m) {
    if (!root.contains("options")) return Status::ok();
    const Json& o = root["options"];
    if (!o.is_object()) return f.error("options", "expected an object, got " + Fields::shown(o));
    VISTA_RETURN_IF_ERROR(f.onlyKnown(o, "options", {"frames", "sampling", "allow_repeated_frames"}));
    std::optional<uint64_t> frames;
    VISTA_RETURN_IF_ERROR(f.whole(o, "options", "frames", 1, 1000000, frames));
    if (frames) m.options.frames = int(*frames);
    VISTA_RETURN_IF_ERROR(f.string(o, "options", "sampling", m.options.sampling));
    std::optional<bool> repeats;
    VISTA_RETURN_IF_ERROR(f.boolean(o, "options", "allow_repeated_frames", repeats));
    m.options.allowRepeatedFrames = repeats.value_or(false);
    return Status::ok();
}

}  // namespace

std::vector<DatasetDrive> DatasetManifest::drives() const {
    std::vector<DatasetDrive> d;
    for (size_t c = 0; c < cities.size(); ++c)
        for (size_t p = 0; p < paths.size(); ++p)
            for (size_t r = 0; r < rigs.size(); ++r)
                d.push_back({c, p, r, cities[c].name + "/" + paths[p].name + "/" + rigs[r].name});
    return d;
}

Result<DatasetManifest> parseDatasetManifest(const std::string& text, const std::string& source,
                                             const std::string& baseDir) {
    const Fields f(source);
    const Json root = Json::parse(text, nullptr, false);
    if (root.is_discarded())
        return Status::error("dataset '" + source + "': not valid JSON (expected an object with cities, paths, rigs)");
    if (!root.is_object())
        return Status::error("dataset '" + source + "': expected a JSON object with cities, paths, rigs, got " +
                             Fields::shown(root));
    VISTA_RETURN_IF_ERROR(f.onlyKnown(root, "", {"cities", "paths", "rigs", "options"}));
    DatasetManifest m;
    VISTA_RETURN_IF_ERROR(parseCities(f, root, baseDir, m));
    VISTA_RETURN_IF_ERROR(parsePaths(f, root, baseDir, m));
    VISTA_RETURN_IF_ERROR(parseRigs(f, root, baseDir, m));
    VISTA_RETURN_IF_ERROR(parseOptions(f, root, m));
    const double drives = double(m.cities.size()) * double(m.paths.size()) * double(m.rigs.size());
    if (drives > double(kMaxDatasetDrives))
        return f.error("cities, paths, rigs", std::to_string(m.cities.size()) + " x " + std::to_string(m.paths.size()) +
                                                  " x " + std::to_string(m.rigs.size()) + " drives, more than " +
                                                  std::to_string(kMaxDatasetDrives));
    return m;
}

Result<DatasetManifest> loadDatasetManifest(const std::string& path) {
    auto text = readInputFile("dataset manifest", path, kMaxDatasetManifestBytes);
    if (!text) return Status::error("--dataset: " + text.status().message());
    auto m = parseDatasetManifest(*text, path, fs::path(path).parent_path().string());
    if (!m) return m.status();
    const Fields f(path);
    std::error_code ec;
    for (size_t i = 0; i < m->cities.size(); ++i)
        if (!fs::exists(m->cities[i].file, ec))
            return f.error("cities[" + std::to_string(i) + "].file", "'" + m->cities[i].file + "' does not exist");
    for (size_t i = 0; i < m->paths.size(); ++i)
        if (!m->paths[i].file.empty() && !fs::is_regular_file(m->paths[i].file, ec))
            return f.error("paths[" + std::to_string(i) + "].file", "'" + m->paths[i].file + "' is not a file");
    for (size_t i = 0; i < m->rigs.size(); ++i)
        if (!m->rigs[i].file.empty() && !fs::is_regular_file(m->rigs[i].file, ec))
            return f.error("rigs[" + std::to_string(i) + "].file", "'" + m->rigs[i].file + "' is not a file");
    return m;
}

}  // namespace vista
