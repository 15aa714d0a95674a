// RaySet file codec (see ray_set.h for the layout and the contract).
#include "runtime/engine/ray_set.h"

#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <utility>

#include "foundation/atomic_file.h"
#include "foundation/hash.h"
#include "foundation/input_file.h"
#include "foundation/units.h"

namespace vista {

namespace {

constexpr char kMagic[8] = {'V', 'R', 'A', 'Y', 'S', 'E', 'T', '1'};
constexpr uint32_t kVersion = 2;
constexpr int kMaxSide = 8192;
// magic, version, frame, width, height, 10 doubles, count.
constexpr size_t kHeaderBytes = 8 + 4 * 4 + 10 * 8 + 8;

void putU32(std::string& s, uint32_t v) {
    for (int k = 0; k < 4; ++k) s.push_back(char((v >> (8 * k)) & 0xFF));
}
void putU64(std::string& s, uint64_t v) {
    unsigned char b[8];
    storeLE64(b, v);
    s.append(reinterpret_cast<const char*>(b), 8);
}
void putF64(std::string& s, double v) {
    uint64_t u;
    std::memcpy(&u, &v, 8);
    putU64(s, u);
}

// Reads little-endian fields from the front of a byte range.
class Cursor {
public:
    // The caller keeps `b` alive and checked that the fields read fit.
    Cursor(const std::string& b, size_t offset) : _p(reinterpret_cast<const unsigned char*>(b.data()) + offset) {}
    uint32_t u32() {
        uint32_t v = 0;
        for (int k = 0; k < 4; ++k) v |= uint32_t(_p[k]) << (8 * k);
        _p += 4;
        return v;
    }
    uint64_t u64() {
        const uint64_t v = loadLE64(_p);
        _p += 8;
        return v;
    }
    double f64() {
        const uint64_t u = u64();
        double v;
        std::memcpy(&v, &u, 8);
        return v;
    }

private:
    const unsigned char* _p;
};

// The header rules of ray_set.h (everything but the pixel list).
Status checkHeader(const RaySet& s, const std::string& what) {
    const Camera& c = s.camera;
    auto bad = [&](const std::string& field, const std::string& value, const std::string& range) {
        return Status::error(what + ": ray set " + field + " = " + value + " out of range " + range);
    };
    if (c.width < 1 || c.width > kMaxSide) return bad("width", std::to_string(c.width), "1 .. 8192");
    if (c.height < 1 || c.height > kMaxSide) return bad("height", std::to_string(c.height), "1 .. 8192");
    const double finite[] = {c.eye.x, c.eye.y, c.eye.z, c.heading, c.pitch, c.roll};
    const char* names[] = {"eye x", "eye y", "eye z", "heading", "pitch", "roll"};
    for (int k = 0; k < 6; ++k)
        if (!std::isfinite(finite[k])) return bad(names[k], std::to_string(finite[k]), "(finite)");
    if (!(c.fovY > 0 && c.fovY < kPi)) return bad("fovY", std::to_string(c.fovY), "(0, pi) radians");
    if (!(c.zNear > 0 && std::isfinite(c.zNear))) return bad("zNear", std::to_string(c.zNear), "(0, inf) metres");
    if (!(s.hazeFar >= 0 && std::isfinite(s.hazeFar)))
        return bad("hazeFar", std::to_string(s.hazeFar), "[0, inf) metres");
    if (!(s.tnear >= 0 && std::isfinite(s.tnear))) return bad("tnear", std::to_string(s.tnear), "[0, inf) metres");
    return Status::ok();
}

// Pixel k of the list: inside the image and above its predecessor.
Status checkPixel(const RaySet& s, size_t k, const std::string& what) {
    const uint64_t n = uint64_t(s.camera.width) * uint64_t(s.camera.height);
    const uint32_t p = s.pixels[k];
    if (p >= n)
        return Status::error(what + ": ray set pixel[" + std::to_string(k) + "] = " + std::to_string(p) +
                             " out of range 0 .. " + std::to_string(n - 1) + " (width * height - 1)");
    if (k > 0 && p <= s.pixels[k - 1])
        return Status::error(what + ": ray set pixel[" + std::to_string(k) + "] = " + std::to_string(p) +
                             " is not above pixel[" + std::to_string(k - 1) + "] = " + std::to_string(s.pixels[k - 1]) +
                             " (the list is ascending)");
    return Status::ok();
}

}  // namespace

std::string encodeRaySet(const RaySet& s) {
    VISTA_CHECK(checkHeader(s, "encodeRaySet").isOk());
    for (size_t k = 0; k < s.pixels.size(); ++k) VISTA_CHECK(checkPixel(s, k, "encodeRaySet").isOk());
    std::string b(kMagic, 8);
    b.reserve(kHeaderBytes + 4 * s.pixels.size() + 8);
    putU32(b, kVersion);
    putU32(b, s.frame);
    putU32(b, uint32_t(s.camera.width));
    putU32(b, uint32_t(s.camera.height));
    const Camera& c = s.camera;
    for (double v : {c.eye.x, c.eye.y, c.eye.z, c.heading, c.pitch, c.roll, c.fovY, c.zNear, s.hazeFar, s.tnear})
        putF64(b, v);
    putU64(b, s.pixels.size());
    for (uint32_t p : s.pixels) putU32(b, p);
    putU64(b, hashBytes64(b.data(), b.size()));
    return b;
}

Result<RaySet> decodeRaySet(const std::string& bytes, const std::string& what) {
    if (bytes.size() < kHeaderBytes + 8)
        return Status::error(what + ": ray set truncated: " + std::to_string(bytes.size()) + " bytes, a header needs " +
                             std::to_string(kHeaderBytes + 8));
    if (std::memcmp(bytes.data(), kMagic, 8) != 0)
        return Status::error(what + ": not a ray set (magic is not VRAYSET1)");
    Cursor in(bytes, 8);
    RaySet s;
    const uint32_t version = in.u32();
    if (version != kVersion)
        return Status::error(what + ": ray set version = " + std::to_string(version) +
                             " unsupported (this build reads 2; dump the rays again with `vista bench --dump-rays`)");
    s.frame = in.u32();
    const uint32_t w = in.u32(), h = in.u32();
    for (auto [name, v] : {std::pair<const char*, uint32_t>{"width", w}, {"height", h}})
        if (v < 1 || v > uint32_t(kMaxSide))
            return Status::error(what + ": ray set " + name + " = " + std::to_string(v) + " out of range 1 .. 8192");
    s.camera.width = int(w);
    s.camera.height = int(h);
    Camera& c = s.camera;
    for (double* v :
         {&c.eye.x, &c.eye.y, &c.eye.z, &c.heading, &c.pitch, &c.roll, &c.fovY, &c.zNear, &s.hazeFar, &s.tnear})
        *v = in.f64();
    VISTA_RETURN_IF_ERROR(checkHeader(s, what));
    const uint64_t count = in.u64();
    const uint64_t room = (bytes.size() - kHeaderBytes - 8) / 4;
    const uint64_t n = uint64_t(c.width) * uint64_t(c.height);
    if (count > n)
        return Status::error(what + ": ray set count = " + std::to_string(count) + " out of range 0 .. " +
                             std::to_string(n) + " (width * height)");
    if (count > room)
        return Status::error(what + ": ray set truncated: count = " + std::to_string(count) + " pixels but room for " +
                             std::to_string(room));
    const size_t end = kHeaderBytes + 4 * size_t(count);
    if (bytes.size() != end + 8)
        return Status::error(what + ": ray set has " + std::to_string(bytes.size() - end - 8) + " trailing bytes");
    Cursor tail(bytes, end);
    if (tail.u64() != hashBytes64(bytes.data(), end))
        return Status::error(what + ": ray set checksum mismatch (the file is damaged)");
    Cursor px(bytes, kHeaderBytes);
    s.pixels.resize(size_t(count));
    for (size_t k = 0; k < s.pixels.size(); ++k) {
        s.pixels[k] = px.u32();
        VISTA_RETURN_IF_ERROR(checkPixel(s, k, what));
    }
    return s;
}

Status writeRaySet(const std::string& path, const RaySet& s) { return writeFileAtomic(path, encodeRaySet(s)); }

Result<RaySet> readRaySet(const std::string& path) {
    auto bytes = readInputFile("ray set", path, kMaxRaySetBytes);
    if (!bytes) return bytes.status();
    return decodeRaySet(*bytes, "'" + path + "'");
}

}  // namespace vista
