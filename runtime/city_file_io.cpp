// Scene file I/O: atomic writes, osgb payload + integrity trailer (city_file_io.h).
#include "runtime/city_file_io.h"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <istream>
#include <streambuf>
#include <vector>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <osgDB/Options>
#include <osgDB/ReaderWriter>
#include <osgDB/Registry>

#include "runtime/city_file.h"

namespace vista {
namespace {

constexpr char kTrailerHead[8] = {'V', 'S', 'T', 'A', 'C', 'I', 'T', 'Y'};
constexpr char kTrailerTail[8] = {'V', 'S', 'T', 'A', 'E', 'N', 'D', '1'};
constexpr uint64_t kK1 = 0x9E3779B185EBCA87ull;
constexpr uint64_t kK2 = 0xC2B2AE3D27D4EB4Full;

inline uint64_t rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }
inline uint64_t mixWord(uint64_t h, uint64_t w) { return rotl(h ^ (w * kK1), 31) * kK2 + 0x165667B19E3779F9ull; }
inline uint64_t loadLE64(const unsigned char* p) {
    uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = (v << 8) | p[i];
    return v;
}
inline void storeLE64(unsigned char* p, uint64_t v) {
    for (int i = 0; i < 8; ++i) p[i] = (unsigned char)(v >> (8 * i));
}

// Streaming version of hashBytes64 (same result for any split of the input).
class Hasher {
public:
    explicit Hasher(uint64_t seed = 0) : _h(seed ^ kK2) {}
    void update(const unsigned char* p, size_t n) {
        _size += n;
        while (n > 0 && _pending > 0 && _pending < 8) { _tail[_pending++] = *p++; --n; }
        if (_pending == 8) { _h = mixWord(_h, loadLE64(_tail)); _pending = 0; }
        while (n >= 8) { _h = mixWord(_h, loadLE64(p)); p += 8; n -= 8; }
        while (n > 0) { _tail[_pending++] = *p++; --n; }
    }
    uint64_t finish() const {
        uint64_t h = _h;
        if (_pending) {
            unsigned char t[8] = {0};
            std::memcpy(t, _tail, _pending);
            h = mixWord(h, loadLE64(t));
        }
        h ^= _size;
        h ^= h >> 33; h *= 0xFF51AFD7ED558CCDull; h ^= h >> 33; h *= 0xC4CEB9FE1A85EC53ull; h ^= h >> 33;
        return h;
    }

private:
    uint64_t _h;
    uint64_t _size = 0;
    unsigned char _tail[8] = {0};
    size_t _pending = 0;
};

std::string errnoText() { return std::strerror(errno); }

std::string tempPathFor(const std::string& path) { return path + ".tmp." + std::to_string(::getpid()); }

// Read-only stream buffer over memory, with seeking (OSG may seek).
class MemoryBuf : public std::streambuf {
public:
    MemoryBuf(const char* data, size_t size) {
        char* p = const_cast<char*>(data);
        setg(p, p, p + size);
    }

protected:
    pos_type seekoff(off_type off, std::ios_base::seekdir dir, std::ios_base::openmode which) override {
        if (!(which & std::ios_base::in)) return pos_type(off_type(-1));
        off_type base = dir == std::ios_base::beg ? 0 : dir == std::ios_base::cur ? off_type(gptr() - eback()) : off_type(egptr() - eback());
        off_type np = base + off;
        if (np < 0 || np > off_type(egptr() - eback())) return pos_type(off_type(-1));
        setg(eback(), eback() + np, egptr());
        return pos_type(np);
    }
    pos_type seekpos(pos_type pos, std::ios_base::openmode which) override {
        return seekoff(off_type(pos), std::ios_base::beg, which);
    }
};

osgDB::ReaderWriter* osgbReaderWriter() {
    return osgDB::Registry::instance()->getReaderWriterForExtension("osgb");
}

}  // namespace

uint64_t hashBytes64(const void* data, size_t size, uint64_t seed) {
    Hasher h(seed);
    h.update(static_cast<const unsigned char*>(data), size);
    return h.finish();
}

Status writeFileAtomic(const std::string& path, const std::string& bytes) {
    if (path.empty()) return Status::error("cannot write file: empty path");
    const std::string tmp = tempPathFor(path);
    int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) return Status::error("cannot write '" + path + "': " + errnoText());
    const char* p = bytes.data();
    size_t n = bytes.size();
    while (n > 0) {
        ssize_t w = ::write(fd, p, n);
        if (w < 0) {
            if (errno == EINTR) continue;
            std::string e = errnoText();
            ::close(fd);
            ::unlink(tmp.c_str());
            return Status::error("cannot write '" + path + "': " + e);
        }
        p += w; n -= size_t(w);
    }
    if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) {
        std::string e = errnoText();
        ::close(fd);
        ::unlink(tmp.c_str());
        return Status::error("cannot write '" + path + "': fsync failed: " + e);
    }
    if (::close(fd) != 0) {
        std::string e = errnoText();
        ::unlink(tmp.c_str());
        return Status::error("cannot write '" + path + "': " + e);
    }
    if (::rename(tmp.c_str(), path.c_str()) != 0) {
        std::string e = errnoText();
        ::unlink(tmp.c_str());
        return Status::error("cannot write '" + path + "': rename failed: " + e);
    }
    return Status::ok();
}

Status writeSceneFile(const osg::Node& node, const std::string& path, bool compress) {
    if (path.empty()) return Status::error("cannot write scene file: empty path");
    osgDB::ReaderWriter* rw = osgbReaderWriter();
    if (!rw) return Status::error("cannot write '" + path + "': OpenSceneGraph osgb plugin not found");
    const std::string tmp = tempPathFor(path);
    auto fail = [&](const std::string& why) {
        ::unlink(tmp.c_str());
        return Status::error("cannot write '" + path + "': " + why);
    };
    // 1. osgb payload. OSG's binary writer seeks back to patch block sizes, so
    //    it needs a seekable stream: write the temp file first.
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        if (!out) return Status::error("cannot write '" + path + "': " + errnoText());
        std::string why;
        bool written = false;
        try {
            osg::ref_ptr<osgDB::Options> opts = new osgDB::Options(compress ? "Compressor=zlib" : "");
            osgDB::ReaderWriter::WriteResult wr = rw->writeNode(node, out, opts.get());
            out.flush();
            written = wr.success() && out.good();
            if (!written) why = "osgb writer failed" + (wr.message().empty() ? std::string() : ": " + wr.message());
        } catch (const std::exception& e) {
            why = std::string("osgb writer failed: ") + e.what();
        }
        out.close();
        if (!written || out.fail()) return fail(why.empty() ? "write error" : why);
    }
    // 2. Hash the payload as written, append the trailer, sync, rename.
    int fd = ::open(tmp.c_str(), O_RDWR | O_CLOEXEC);
    if (fd < 0) return fail(errnoText());
    Hasher hasher;
    uint64_t size = 0;
    std::vector<char> chunk(1 << 20);
    for (;;) {
        ssize_t r = ::read(fd, chunk.data(), chunk.size());
        if (r < 0) { if (errno == EINTR) continue; std::string e = errnoText(); ::close(fd); return fail(e); }
        if (r == 0) break;
        hasher.update(reinterpret_cast<unsigned char*>(chunk.data()), size_t(r));
        size += uint64_t(r);
    }
    unsigned char trailer[kSceneTrailerSize];
    std::memcpy(trailer, kTrailerHead, 8);
    storeLE64(trailer + 8, size);
    storeLE64(trailer + 16, hasher.finish());
    std::memcpy(trailer + 24, kTrailerTail, 8);
    size_t done = 0;
    while (done < sizeof trailer) {
        ssize_t w = ::pwrite(fd, trailer + done, sizeof trailer - done, off_t(size + done));
        if (w < 0) { if (errno == EINTR) continue; std::string e = errnoText(); ::close(fd); return fail(e); }
        done += size_t(w);
    }
    if (::fsync(fd) != 0 && errno != EINVAL && errno != EROFS) { std::string e = errnoText(); ::close(fd); return fail("fsync failed: " + e); }
    if (::close(fd) != 0) return fail(errnoText());
    if (::rename(tmp.c_str(), path.c_str()) != 0) return fail("rename failed: " + errnoText());
    return Status::ok();
}

Result<osg::ref_ptr<osg::Node>> readSceneFile(const std::string& path) {
    struct stat st;
    if (::stat(path.c_str(), &st) != 0) return Status::error("cannot open scene file '" + path + "': " + errnoText());
    if (S_ISDIR(st.st_mode)) return Status::error("cannot open scene file '" + path + "': is a directory");
    std::ifstream in(path, std::ios::binary);
    if (!in) return Status::error("cannot open scene file '" + path + "': " + errnoText());
    std::vector<char> data;
    try {
        data.resize(size_t(st.st_size));
    } catch (const std::exception&) {
        return Status::error("cannot read scene file '" + path + "': out of memory");
    }
    if (!data.empty() && !in.read(data.data(), std::streamsize(data.size())))
        return Status::error("cannot read scene file '" + path + "': read error");
    const auto* bytes = reinterpret_cast<const unsigned char*>(data.data());
    // osgb magic: 0x6C910EA1 0x1AFB4545 (little endian uint32 pair).
    static const unsigned char kOsgbMagic[8] = {0xA1, 0x0E, 0x91, 0x6C, 0x45, 0x45, 0xFB, 0x1A};
    if (data.size() < 8 || std::memcmp(bytes, kOsgbMagic, 8) != 0)
        return Status::error("scene file '" + path + "' is not an OpenSceneGraph binary (.osgb) file");
    if (data.size() < 8 + kSceneTrailerSize ||
        std::memcmp(bytes + data.size() - kSceneTrailerSize, kTrailerHead, 8) != 0 ||
        std::memcmp(bytes + data.size() - 8, kTrailerTail, 8) != 0)
        return Status::error("scene file '" + path + "' is truncated or was not written by vista (no integrity trailer)");
    const unsigned char* tr = bytes + data.size() - kSceneTrailerSize;
    uint64_t payload = loadLE64(tr + 8), hash = loadLE64(tr + 16);
    if (payload != data.size() - kSceneTrailerSize)
        return Status::error("scene file '" + path + "' is truncated or corrupted: payload size " + std::to_string(data.size() - kSceneTrailerSize) +
                             " bytes, trailer says " + std::to_string(payload));
    if (hashBytes64(bytes, size_t(payload)) != hash)
        return Status::error("scene file '" + path + "' is corrupted: checksum mismatch");
    osgDB::ReaderWriter* rw = osgbReaderWriter();
    if (!rw) return Status::error("cannot read '" + path + "': OpenSceneGraph osgb plugin not found");
    osg::ref_ptr<osg::Node> node;
    try {
        MemoryBuf mb(data.data(), size_t(payload));
        std::istream is(&mb);
        osgDB::ReaderWriter::ReadResult rr = rw->readNode(is, nullptr);
        if (!rr.validNode())
            return Status::error("cannot read scene file '" + path + "': " + (rr.message().empty() ? std::string("osgb reader returned no node") : rr.message()));
        node = rr.getNode();
    } catch (const std::exception& e) {
        return Status::error("cannot read scene file '" + path + "': " + e.what());
    }
    return node;
}

}  // namespace vista
