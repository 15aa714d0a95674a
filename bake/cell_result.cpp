// Cell-result codec: one field list (visit) drives both the Writer and the
// Reader archive, so the two directions cannot drift apart.
#include "bake/cell_result.h"

#include <cmath>
#include <cstring>
#include <type_traits>

#include "foundation/hash.h"

namespace vista {
namespace {

const char kMagic[8] = {'V', 'B', 'C', 'E', 'L', 'L', '0', '1'};
const char kMeshMagic[8] = {'V', 'B', 'C', 'M', 'E', 'S', 'H', '1'};
constexpr size_t kMaxNotes = 16, kMaxImpostors = 2, kMaxMeshes = 2;
constexpr int kMaxImageSide = 16384;
static_assert(sizeof(MeshStats) == 96, "MeshStats is stored as one block: no padding, fixed layout");
static_assert(sizeof(ImpostorStats) == 152, "ImpostorStats is stored as one block: no padding, fixed layout");

class Writer {
public:
    explicit Writer(std::string& out) : _b(out) {}
    template <class T>
    void pod(T& v) {
        static_assert(std::is_trivially_copyable<T>::value, "pod() needs a trivially copyable type");
        _b.append(reinterpret_cast<const char*>(&v), sizeof(T));
    }
    template <class T>
    void vec(std::vector<T>& v) {
        pod64(v.size());
        if (!v.empty()) _b.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    }
    void str(std::string& s) {
        pod64(s.size());
        _b.append(s);
    }
    template <class T, class F>
    void list(std::vector<T>& v, size_t /*max*/, const char* /*what*/, F&& each) {
        pod64(v.size());
        for (T& x : v) each(x);
    }

private:
    void pod64(size_t n) {
        uint64_t u = n;
        pod(u);
    }
    std::string& _b;
};

// Reads from `bytes`; the first failure sticks (later reads do nothing) and
// names what was being read and where.
class Reader {
public:
    Reader(const char* data, size_t size, size_t at) : _d(data), _n(size), _at(at) {}
    bool ok() const { return _error.empty(); }
    const std::string& error() const { return _error; }
    size_t at() const { return _at; }
    template <class T>
    void pod(T& v) {
        static_assert(std::is_trivially_copyable<T>::value, "pod() needs a trivially copyable type");
        if (!take(sizeof(T), "a field")) return;
        std::memcpy(&v, _d + _at - sizeof(T), sizeof(T));
    }
    template <class T>
    void vec(std::vector<T>& v) {
        uint64_t n = 0;
        if (!count(n, (_n - std::min(_n, _at + 8)) / sizeof(T), "an array")) return;
        v.resize(size_t(n));
        if (n && take(size_t(n) * sizeof(T), "an array"))
            std::memcpy(v.data(), _d + _at - size_t(n) * sizeof(T), size_t(n) * sizeof(T));
    }
    void str(std::string& s) {
        uint64_t n = 0;
        if (!count(n, _n - std::min(_n, _at + 8), "a string")) return;
        if (take(size_t(n), "a string")) s.assign(_d + _at - size_t(n), size_t(n));
    }
    template <class T, class F>
    void list(std::vector<T>& v, size_t max, const char* what, F&& each) {
        uint64_t n = 0;
        if (!count(n, max, what)) return;
        v.resize(size_t(n));
        for (T& x : v) {
            if (!ok()) return;
            each(x);
        }
    }
    void fail(const std::string& why) {
        if (ok()) _error = why;
    }

private:
    bool take(size_t n, const char* what) {
        if (!ok()) return false;
        if (n > _n - _at) {
            fail("truncated: " + std::string(what) + " of " + std::to_string(n) + " bytes at byte " +
                 std::to_string(_at) + " runs past the end (" + std::to_string(_n) + " bytes)");
            return false;
        }
        _at += n;
        return true;
    }
    // A u64 count, at most `max` (elements that still fit, or a fixed limit).
    bool count(uint64_t& n, uint64_t max, const char* what) {
        const size_t at = _at;
        pod(n);
        if (!ok()) return false;
        if (n > max) {
            fail(std::string(what) + " count " + std::to_string(n) + " at byte " + std::to_string(at) + " exceeds " +
                 std::to_string(max));
            return false;
        }
        return true;
    }
    const char* _d;
    size_t _n, _at;
    std::string _error;
};

// The fields every result starts with: which street end of which cell, its frame, the tiles it hides.
template <class Ar, class R>
void visitEnd(Ar& ar, R& r) {
    ar.pod(r.cell);
    ar.pod(r.end);
    ar.pod(r.frame.origin);
    ar.pod(r.frame.x);
    ar.vec(r.hiddenTiles);
}

// The one field list of the format.
template <class Ar>
void visit(Ar& ar, ImpostorResult& im) {
    visitEnd(ar, im);
    ar.pod(im.data.planeOrigin);
    ar.pod(im.data.planeU);
    ar.pod(im.data.planeV);
    ar.pod(im.data.texelsX);
    ar.pod(im.data.texelsY);
    ar.vec(im.data.positions);
    ar.vec(im.data.colors);
    ar.vec(im.data.block);
    ar.vec(im.data.texels);
    ar.pod(im.stats);
}

template <class Ar>
void visit(Ar& ar, MeshResult& m) {
    visitEnd(ar, m);
    ar.pod(m.mesh.eye);
    ar.pod(m.mesh.width);
    ar.pod(m.mesh.height);
    ar.vec(m.mesh.image);
    ar.vec(m.mesh.positions);
    ar.vec(m.mesh.texcoords);
    ar.vec(m.mesh.indices);
    ar.pod(m.stats);
}

// `meshes`: the VBCMESH1 layout (the mesh list follows the impostors).
template <class Ar>
void visit(Ar& ar, CellResult& r, bool meshes) {
    ar.pod(r.cell);
    ar.pod(r.bakeMs);
    ar.list(r.notes, kMaxNotes, "notes", [&](std::string& s) { ar.str(s); });
    ar.list(r.impostors, kMaxImpostors, "impostors", [&](ImpostorResult& im) { visit(ar, im); });
    if (meshes) ar.list(r.meshes, kMaxMeshes, "meshes", [&](MeshResult& m) { visit(ar, m); });
}

std::string checkMesh(const MeshResult& m) {
    const TexturedDepthMeshData& d = m.mesh;
    if (m.end > 1) return "mesh street end " + std::to_string(int(m.end)) + " (must be 0 or 1)";
    if (d.width < 1 || d.height < 1 || d.width > kMaxImageSide || d.height > kMaxImageSide)
        return "mesh image " + std::to_string(d.width) + "x" + std::to_string(d.height) + " (sides must be 1.." +
               std::to_string(kMaxImageSide) + ")";
    if (d.image.size() != size_t(d.width) * size_t(d.height))
        return "mesh image size does not match its width and height";
    if (d.texcoords.size() != d.positions.size() || d.indices.size() % 3 != 0) return "inconsistent mesh arrays";
    for (uint32_t i : d.indices)
        if (i >= d.positions.size()) return "mesh index out of range";
    for (size_t k = 0; k < d.positions.size(); ++k) {
        const glm::vec3& p = d.positions[k];
        const glm::vec4& t = d.texcoords[k];
        if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(t.x) ||
            !std::isfinite(t.y) || !std::isfinite(t.w) || !(t.w > 0))
            return "mesh vertex " + std::to_string(k) + " not finite or behind the eye";
    }
    return "";
}

// Consistency the field list cannot express; "" when fine.
std::string checkImpostor(const ImpostorResult& im) {
    const PointImpostorData& d = im.data;
    if (d.texelsX < 1 || d.texelsY < 1)
        return "texel layout " + std::to_string(d.texelsX) + "x" + std::to_string(d.texelsY) + " (must be >= 1x1)";
    const size_t bs = size_t(d.texelsX) * size_t(d.texelsY);
    if (d.colors.size() != d.positions.size() || d.block.size() != d.positions.size() || d.texels.size() % bs != 0)
        return "inconsistent impostor arrays";
    for (int32_t b : d.block)
        if (b >= 0 && size_t(b) >= d.texels.size() / bs) return "texel block index out of range";
    return "";
}

}  // namespace

std::string encodeCellResult(const CellResult& r, uint64_t configHash) {
    const bool meshes = !r.meshes.empty();
    std::string b(meshes ? kMeshMagic : kMagic, 8);
    Writer w(b);
    w.pod(configHash);
    visit(w, const_cast<CellResult&>(r), meshes);  // the Writer only reads
    uint64_t h = hashBytes64(b.data(), b.size());
    w.pod(h);
    return b;
}

Result<CellResult> decodeCellResult(const std::string& bytes, uint64_t configHash, const std::string& what) {
    auto bad = [&](const std::string& why) { return Status::error("cell result '" + what + "': " + why); };
    if (bytes.size() < 8 + 8 + 8 ||
        (std::memcmp(bytes.data(), kMagic, 8) != 0 && std::memcmp(bytes.data(), kMeshMagic, 8) != 0))
        return bad("not a vista cell result (bad magic)");
    const bool meshes = std::memcmp(bytes.data(), kMeshMagic, 8) == 0;
    const size_t body = bytes.size() - 8;
    uint64_t stored = 0;
    std::memcpy(&stored, bytes.data() + body, 8);
    if (hashBytes64(bytes.data(), body) != stored) return bad("truncated or corrupted (hash mismatch)");
    Reader rd(bytes.data(), body, 8);
    uint64_t cfg = 0;
    rd.pod(cfg);
    if (cfg != configHash) return bad("baked with other input or parameters");
    CellResult r;
    visit(rd, r, meshes);
    if (rd.ok() && rd.at() != body) rd.fail(std::to_string(body - rd.at()) + " trailing bytes after the last field");
    if (!rd.ok()) return bad("malformed: " + rd.error());
    for (const ImpostorResult& im : r.impostors)
        if (std::string why = checkImpostor(im); !why.empty()) return bad(why);
    for (const MeshResult& m : r.meshes)
        if (std::string why = checkMesh(m); !why.empty()) return bad(why);
    return r;
}

}  // namespace vista
