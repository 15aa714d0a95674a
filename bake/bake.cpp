#include "bake/bake.h"
#include "foundation/units.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <sstream>

#include <osg/Geode>
#include <osg/MatrixTransform>
#include <osg/UserDataContainer>

#include "foundation/rng.h"
#include "runtime/scene/scene_graph.h"
#include "citygen/terrain.h"
#include "runtime/scene/scene_file.h"

namespace vista {

std::string BakeParams::canonical() const {
    std::ostringstream o;
    o.precision(17);
    o << "eye=" << cells.eyeMin << "," << cells.eyeMax << ";minLen=" << cells.minLength << ";minW=" << cells.minWidth
      << ";out=" << sampling.outWidth << "x" << sampling.outHeight << ";fov=" << sampling.fovYDeg << ";os=" << sampling.oversample
      << ";fp=" << sampling.perspective << ";diag=" << sampling.diagonalFactor << ";layers=" << sampling.maxLayers
      << ";maxRays=" << sampling.maxRaysPerCamera << ";removal=" << sampling.removeRedundant << ";texels=" << appearance.texelsX
      << "x" << appearance.texelsY << ";mc=" << appearance.minSamples << "," << appearance.maxSamples << ","
      << appearance.varianceThreshold << "," << appearance.singleColorThreshold << "," << appearance.viewSigma << ","
      << appearance.pixelSigma << "," << appearance.significance << ";margin=" << margin << ";depth=" << farDepth << ";opening=" << openingExtra
      << ";minTri=" << minTriangles << ";seed=" << seed;
    return o.str();
}

std::vector<CityTile> indexTiles(const SceneModel& city) {
    std::vector<CityTile> tiles;
    auto expand = [](CityTile& t, const glm::dvec3& w) {
        t.lo = glm::min(t.lo, glm::dvec2(w));
        t.hi = glm::max(t.hi, glm::dvec2(w));
    };
    auto addMesh = [&](CityTile& t, uint32_t mi) {
        const SceneMesh& m = city.meshes[mi];
        t.meshes.push_back(mi);
        t.triangles += m.indices.size() / 3;
        for (const auto& p : m.positions) expand(t, m.origin + glm::dvec3(p));
    };
    auto addInstance = [&](CityTile& t, uint32_t ii) {
        const SceneInstance& in = city.instances[ii];
        t.instances.push_back(ii);
        if (in.prototype >= city.prototypes.size()) return;
        const SceneMesh& pm = city.prototypes[in.prototype];
        t.triangles += pm.indices.size() / 3;
        for (const auto& p : pm.positions) expand(t, glm::dvec3(in.transform * glm::dvec4(glm::dvec3(p), 1.0)));
    };
    osg::Group* root = sceneRoot(city) ? sceneRoot(city)->asGroup() : nullptr;
    if (!root) {  // hand-built city (tests): one tile per mesh, then per instance
        for (uint32_t i = 0; i < city.meshes.size(); ++i) {
            CityTile t;
            t.child = i;
            addMesh(t, i);
            tiles.push_back(t);
        }
        for (uint32_t i = 0; i < city.instances.size(); ++i) {
            CityTile t;
            t.child = uint32_t(city.meshes.size()) + i;
            addInstance(t, i);
            tiles.push_back(t);
        }
        return tiles;
    }
    // tileGeometries() walks the file in loadCityFile's order, so meshes and
    // instances are attributed to their tiles by position.
    uint32_t nextMesh = 0, nextInst = 0;
    for (unsigned ci = 0; ci < root->getNumChildren(); ++ci) {
        osg::MatrixTransform* xf = asCityTile(root->getChild(ci));
        if (!xf) continue;
        CityTile t;
        t.child = ci;
        for (osg::Geometry* g : tileGeometries(*xf)) {
            if (g->getName().rfind(kTreeGeometryPrefix, 0) == 0) {
                const int n = std::max(0, g->getPrimitiveSet(0)->getNumInstances());
                for (int k = 0; k < n && nextInst < city.instances.size(); ++k) addInstance(t, nextInst++);
            } else if (nextMesh < city.meshes.size()) {
                addMesh(t, nextMesh++);
            }
        }
        tiles.push_back(t);
    }
    return tiles;
}

BakeInput prepareBake(const SceneModel& city, const BakeParams& p) {
    BakeInput in;
    in.city = &city;
    in.tiles = indexTiles(city);
    const CityParams cp = city.params;
    auto ground = [&cp](const glm::dvec2& q) { return terrainHeight(cp, q); };
    in.cells = makeViewCells(city.streets, glm::dvec2(cp.origin_x, cp.origin_y), ground, p.cells, &in.skipped);
    return in;
}

glm::dvec3 toImpostorFrame(const ImpostorResult& r, const glm::dvec3& w) {
    const glm::dvec3 d = w - r.frameOrigin;
    return {d.x * r.frameX.x + d.y * r.frameX.y, -d.x * r.frameX.y + d.y * r.frameX.x, d.z};
}

glm::dvec3 fromImpostorFrame(const ImpostorResult& r, const glm::dvec3& l) {
    return r.frameOrigin + glm::dvec3(l.x * r.frameX.x - l.y * r.frameX.y, l.x * r.frameX.y + l.y * r.frameX.x, l.z);
}

Box3 cellInFrame(const ViewCell& c, const ImpostorResult& r) {
    glm::dvec3 corners[8];
    c.box.corners(corners);
    Box3 b{glm::dvec3(1e300), glm::dvec3(-1e300)};
    for (const auto& k : corners) {
        const glm::dvec3 l = toImpostorFrame(r, k);
        b.lo = glm::min(b.lo, l);
        b.hi = glm::max(b.hi, l);
    }
    return b;
}

TriangleSoup farFieldSoup(const BakeInput& in, const ViewCell& cell, int end, const BakeParams& p, ImpostorResult& r) {
    const SceneModel& city = *in.city;
    const glm::dvec2 u = end == 1 ? cell.box.axis : -cell.box.axis;
    const glm::dvec2 e = glm::dvec2(cell.box.center) + u * cell.box.halfLength;
    r.cell = cell.id;
    r.end = uint8_t(end);
    r.frameOrigin = glm::dvec3(e, cell.groundMin);
    r.frameX = u;
    r.hiddenTiles.clear();
    const double hw0 = cell.box.halfWidth + p.openingExtra;
    const double slope = hw0 / (cell.box.halfLength + p.margin);
    TriangleSoup soup;
    for (const CityTile& t : in.tiles) {
        if (t.triangles == 0 || t.lo.x > t.hi.x) continue;
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        bool inWedge = false;
        for (int c = 0; c < 4; ++c) {
            const glm::dvec3 w((c & 1) ? t.hi.x : t.lo.x, (c & 2) ? t.hi.y : t.lo.y, 0.0);
            const glm::dvec3 l = toImpostorFrame(r, w);
            x0 = std::min(x0, l.x); x1 = std::max(x1, l.x);
            y0 = std::min(y0, l.y); y1 = std::max(y1, l.y);
            if (std::abs(l.y) <= hw0 + slope * (l.x - p.margin)) inWedge = true;
        }
        if (x0 < p.margin || x1 > p.margin + p.farDepth) continue;
        if (!inWedge && !(y0 <= 0 && y1 >= 0)) continue;
        r.hiddenTiles.push_back(t.child);
        auto addMesh = [&](const SceneMesh& m, const glm::dmat4* xf) {
            const uint32_t base = uint32_t(soup.positions.size());
            for (size_t i = 0; i < m.positions.size(); ++i) {
                glm::dvec3 w = xf ? glm::dvec3(*xf * glm::dvec4(glm::dvec3(m.positions[i]), 1.0)) : m.origin + glm::dvec3(m.positions[i]);
                soup.positions.push_back(glm::vec3(toImpostorFrame(r, w)));
                soup.colors.push_back(i < m.colors.size() ? m.colors[i] : glm::u8vec4(255));
            }
            for (uint32_t idx : m.indices) soup.indices.push_back(base + idx);
        };
        for (uint32_t mi : t.meshes) addMesh(city.meshes[mi], nullptr);
        for (uint32_t ii : t.instances) {
            const SceneInstance& inst = city.instances[ii];
            if (inst.prototype < city.prototypes.size()) addMesh(city.prototypes[inst.prototype], &inst.transform);
        }
    }
    std::sort(r.hiddenTiles.begin(), r.hiddenTiles.end());
    return soup;
}

namespace {

// Software projection of the points from the cell centre (target view looking
// along the sampling-plane normal): covered pixels and screen bounding box.
void screenStats(const PointImpostorData& d, const Box3& cell, const SamplingSetup& s, const SamplingParams& sp, ImpostorStats& st) {
    const glm::dvec3 eye = cell.center();
    const double f = 1.0 / std::tan(0.5 * sp.fovYDeg * kPi / 180.0);
    const double aspect = double(sp.outWidth) / sp.outHeight;
    std::vector<uint8_t> hit(size_t(sp.outWidth) * size_t(sp.outHeight), 0);
    int bx0 = sp.outWidth, bx1 = -1, by0 = sp.outHeight, by1 = -1;
    for (const auto& p : d.positions) {
        const glm::dvec3 v = glm::dvec3(p) - eye;
        const double z = glm::dot(v, s.n);
        if (z <= 0) continue;
        const double x = glm::dot(v, s.U) / z * f / aspect, y = glm::dot(v, s.V) / z * f;
        const int px = int(std::floor((x * 0.5 + 0.5) * sp.outWidth)), py = int(std::floor((0.5 - y * 0.5) * sp.outHeight));
        if (px < 0 || py < 0 || px >= sp.outWidth || py >= sp.outHeight) continue;
        hit[size_t(py) * size_t(sp.outWidth) + size_t(px)] = 1;
        bx0 = std::min(bx0, px); bx1 = std::max(bx1, px); by0 = std::min(by0, py); by1 = std::max(by1, py);
    }
    st.screenPixels = size_t(std::count(hit.begin(), hit.end(), uint8_t(1)));
    st.screenBBoxPixels = bx1 >= bx0 ? size_t(bx1 - bx0 + 1) * size_t(by1 - by0 + 1) : 0;
}

}  // namespace

Status bakeImpostor(const TriangleSoup& soup, const Box3& cellBox, const BakeParams& p, uint64_t entity, ImpostorResult& r) {
    Box3 far{glm::dvec3(1e300), glm::dvec3(-1e300)};
    for (uint32_t idx : soup.indices) {
        far.lo = glm::min(far.lo, glm::dvec3(soup.positions[idx]));
        far.hi = glm::max(far.hi, glm::dvec3(soup.positions[idx]));
    }
    r.stats.farTriangles = soup.triangleCount();
    auto setup = setupSampling(cellBox, far);
    if (!setup) return setup.status();
    auto scene = FarScene::build(soup);
    if (!scene) return scene.status();
    const SamplingSetup& s = *setup;
    LdiResult ldi = sampleLdi(**scene, s, far, p.sampling);
    std::vector<uint8_t> keep = removeRedundant(ldi, s, cellBox, p.sampling);
    std::vector<glm::vec3> pts;
    for (size_t i = 0; i < ldi.samples.size(); ++i)
        if (keep[i]) pts.push_back(ldi.samples[i].pos);
    r.stats.ldiRays = ldi.rays;
    r.stats.ldiSamples = ldi.samples.size();
    r.stats.afterRemoval = pts.size();
    r.stats.requiredStep = ldi.requiredStep;
    r.stats.usedStep = std::max({ldi.cams[0].step, ldi.cams[1].step, ldi.cams[2].step});
    for (int k = 0; k < 3; ++k) {
        r.stats.camW[k] = ldi.cams[size_t(k)].width;
        r.stats.camH[k] = ldi.cams[size_t(k)].height;
    }
    AppearanceParams ap = p.appearance;
    ap.pixelAngle = outputPixelAngle(p.sampling);
    AppearanceStats as;
    computeAppearance(**scene, s, pts, ap, p.seed, entity, r.data, as, nullptr, &cellBox);
    // Atlas capacity: later textured points fall back to their mean colour.
    const size_t blockSize = size_t(ap.texelsX) * size_t(ap.texelsY);
    const size_t maxBlocks = size_t(kAtlasBlocksPerRow) * size_t(kMaxAtlasHeight / ap.texelsY);
    if (r.data.texels.size() / blockSize > maxBlocks) {
        r.data.texels.resize(maxBlocks * blockSize);
        for (auto& b : r.data.block)
            if (b >= 0 && size_t(b) >= maxBlocks) b = -1;
    }
    r.stats.mcRays = as.rays;
    r.stats.mcSamples = as.samples;
    r.stats.points = r.data.positions.size();
    r.stats.textured = size_t(std::count_if(r.data.block.begin(), r.data.block.end(), [](int32_t b) { return b >= 0; }));
    r.stats.dropped = as.dropped;
    r.stats.noiseSingle = as.noiseOnly;
    screenStats(r.data, cellBox, s, p.sampling, r.stats);
    return Status::ok();
}

CellResult bakeCell(const BakeInput& in, const ViewCell& cell, const BakeParams& p) {
    const auto t0 = std::chrono::steady_clock::now();
    CellResult out;
    out.cell = cell.id;
    for (int end = 0; end < 2; ++end) {
        const auto ti = std::chrono::steady_clock::now();
        ImpostorResult r;
        TriangleSoup soup = farFieldSoup(in, cell, end, p, r);
        if (soup.triangleCount() < std::max<size_t>(p.minTriangles, 1)) {
            out.notes.push_back("end " + std::to_string(end) + ": far field small (" + std::to_string(soup.triangleCount()) +
                                " triangles < " + std::to_string(p.minTriangles) + ")");
            continue;
        }
        r.stats.tiles = r.hiddenTiles.size();
        Status st = bakeImpostor(soup, cellInFrame(cell, r), p, hashKeys(cell.id, uint64_t(end)), r);
        if (!st) {
            out.notes.push_back("end " + std::to_string(end) + ": " + st.message());
            continue;
        }
        if (r.data.positions.empty()) {
            out.notes.push_back("end " + std::to_string(end) + ": no visible points");
            continue;
        }
        r.stats.bakeMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - ti).count();
        out.impostors.push_back(std::move(r));
    }
    out.bakeMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    return out;
}

// ---------------------------------------------------------------- encoding
namespace {

const char kMagic[8] = {'V', 'B', 'C', 'E', 'L', 'L', '0', '1'};

struct Writer {
    std::string b;
    template <class T> void pod(const T& v) { b.append(reinterpret_cast<const char*>(&v), sizeof(T)); }
    template <class T> void vec(const std::vector<T>& v) {
        pod(uint64_t(v.size()));
        if (!v.empty()) b.append(reinterpret_cast<const char*>(v.data()), v.size() * sizeof(T));
    }
    void str(const std::string& s) { pod(uint64_t(s.size())); b.append(s); }
};

struct Reader {
    const std::string& b;
    size_t at = 0;
    bool ok = true;
    explicit Reader(const std::string& s) : b(s) {}
    template <class T> void pod(T& v) {
        if (!ok || at + sizeof(T) > b.size()) { ok = false; return; }
        std::memcpy(&v, b.data() + at, sizeof(T));
        at += sizeof(T);
    }
    template <class T> void vec(std::vector<T>& v) {
        uint64_t n = 0;
        pod(n);
        if (!ok || n > (b.size() - at) / sizeof(T)) { ok = false; return; }
        v.resize(size_t(n));
        if (n) std::memcpy(v.data(), b.data() + at, size_t(n) * sizeof(T));
        at += size_t(n) * sizeof(T);
    }
    void str(std::string& s) {
        uint64_t n = 0;
        pod(n);
        if (!ok || n > b.size() - at) { ok = false; return; }
        s.assign(b.data() + at, size_t(n));
        at += size_t(n);
    }
};

}  // namespace

std::string encodeCellResult(const CellResult& r, uint64_t configHash) {
    Writer w;
    w.b.append(kMagic, 8);
    w.pod(configHash);
    w.pod(r.cell);
    w.pod(r.bakeMs);
    w.pod(uint64_t(r.notes.size()));
    for (const auto& n : r.notes) w.str(n);
    w.pod(uint64_t(r.impostors.size()));
    for (const auto& im : r.impostors) {
        w.pod(im.cell);
        w.pod(im.end);
        w.pod(im.frameOrigin);
        w.pod(im.frameX);
        w.vec(im.hiddenTiles);
        w.pod(im.data.planeOrigin);
        w.pod(im.data.planeU);
        w.pod(im.data.planeV);
        w.pod(im.data.texelsX);
        w.pod(im.data.texelsY);
        w.vec(im.data.positions);
        w.vec(im.data.colors);
        w.vec(im.data.block);
        w.vec(im.data.texels);
        w.pod(im.stats);
    }
    const uint64_t h = hashBytes64(w.b.data(), w.b.size());
    w.pod(h);
    return w.b;
}

Result<CellResult> decodeCellResult(const std::string& bytes, uint64_t configHash, const std::string& what) {
    auto bad = [&](const std::string& why) { return Status::error("cell result '" + what + "': " + why); };
    if (bytes.size() < 8 + 8 + 8 || std::memcmp(bytes.data(), kMagic, 8) != 0) return bad("not a vista cell result (bad magic)");
    uint64_t stored = 0;
    std::memcpy(&stored, bytes.data() + bytes.size() - 8, 8);
    if (hashBytes64(bytes.data(), bytes.size() - 8) != stored) return bad("truncated or corrupted (hash mismatch)");
    const std::string body = bytes.substr(0, bytes.size() - 8);
    Reader rd(body);
    rd.at = 8;
    uint64_t cfg = 0;
    rd.pod(cfg);
    if (cfg != configHash) return bad("baked with other input or parameters");
    CellResult r;
    rd.pod(r.cell);
    rd.pod(r.bakeMs);
    uint64_t nn = 0;
    rd.pod(nn);
    if (!rd.ok || nn > 16) return bad("malformed notes");
    r.notes.resize(size_t(nn));
    for (auto& n : r.notes) rd.str(n);
    uint64_t ni = 0;
    rd.pod(ni);
    if (!rd.ok || ni > 2) return bad("malformed impostor count");
    r.impostors.resize(size_t(ni));
    for (auto& im : r.impostors) {
        rd.pod(im.cell);
        rd.pod(im.end);
        rd.pod(im.frameOrigin);
        rd.pod(im.frameX);
        rd.vec(im.hiddenTiles);
        rd.pod(im.data.planeOrigin);
        rd.pod(im.data.planeU);
        rd.pod(im.data.planeV);
        rd.pod(im.data.texelsX);
        rd.pod(im.data.texelsY);
        rd.vec(im.data.positions);
        rd.vec(im.data.colors);
        rd.vec(im.data.block);
        rd.vec(im.data.texels);
        rd.pod(im.stats);
        if (!rd.ok) break;
        const size_t bs = size_t(std::max(1, im.data.texelsX)) * size_t(std::max(1, im.data.texelsY));
        if (im.data.texelsX < 1 || im.data.texelsY < 1 || im.data.colors.size() != im.data.positions.size() ||
            im.data.block.size() != im.data.positions.size() || im.data.texels.size() % bs != 0)
            return bad("inconsistent impostor arrays");
        for (int32_t b : im.data.block)
            if (b >= 0 && size_t(b) >= im.data.texels.size() / bs) return bad("texel block index out of range");
    }
    if (!rd.ok || rd.at != body.size()) return bad("malformed or truncated body");
    return r;
}

// ---------------------------------------------------------------- assembly
osg::ref_ptr<ViewCellSwitch> assembleBakedScene(const SceneModel& city, const std::vector<ViewCell>& cells,
                                                const std::vector<CellResult>& results, const std::string& paramsText) {
    osg::ref_ptr<ViewCellSwitch> root = new ViewCellSwitch;
    root->setName("vista.city");
    osg::Group* cityRoot = sceneRoot(city) ? sceneRoot(city)->asGroup() : nullptr;
    if (cityRoot) {
        if (cityRoot->getUserDataContainer())
            root->setUserDataContainer(osg::clone(cityRoot->getUserDataContainer(), osg::CopyOp::DEEP_COPY_ALL));
        root->setStateSet(cityRoot->getStateSet());
        for (unsigned i = 0; i < cityRoot->getNumChildren(); ++i) root->addChild(cityRoot->getChild(i));
    }
    root->setTileCount(root->getNumChildren());
    root->setUserValue("vista.baked", 1);
    root->setUserValue("vista.bake_params", paramsText);
    // Cell ids are edge ids; the switch is indexed by edge id (absent edges get empty boxes).
    uint32_t maxId = 0;
    for (const auto& c : cells) maxId = std::max(maxId, c.id + 1);
    std::vector<ViewCellBox> boxes(maxId);
    for (const auto& c : cells) boxes[c.id] = c.box;
    root->setCells(boxes);
    std::vector<std::vector<uint32_t>> hidden(maxId), imps(maxId);
    for (const CellResult& cr : results) {
        for (const ImpostorResult& im : cr.impostors) {
            if (im.cell >= maxId) continue;
            osg::ref_ptr<osg::MatrixTransform> xf = new osg::MatrixTransform;
            xf->setName("impostor_" + std::to_string(im.cell) + "_" + std::to_string(int(im.end)));
            xf->setDataVariance(osg::Object::DYNAMIC);
            const osg::Matrixd m(im.frameX.x, im.frameX.y, 0, 0, -im.frameX.y, im.frameX.x, 0, 0, 0, 0, 1, 0, im.frameOrigin.x,
                                 im.frameOrigin.y, im.frameOrigin.z, 1);
            xf->setMatrix(m);
            osg::ref_ptr<osg::Geode> geode = new osg::Geode;
            osg::ref_ptr<PointImpostor> pi = new PointImpostor;
            pi->setName(xf->getName());
            pi->setData(im.data);
            geode->addDrawable(pi.get());
            xf->addChild(geode.get());
            imps[im.cell].push_back(root->getNumChildren());
            root->addChild(xf.get());
            hidden[im.cell].insert(hidden[im.cell].end(), im.hiddenTiles.begin(), im.hiddenTiles.end());
        }
    }
    for (uint32_t c = 0; c < maxId; ++c) {
        std::sort(hidden[c].begin(), hidden[c].end());
        hidden[c].erase(std::unique(hidden[c].begin(), hidden[c].end()), hidden[c].end());
    }
    // Build the CSR lists in one go (setCellChildren per cell would be quadratic).
    osg::ref_ptr<osg::UIntArray> hs = new osg::UIntArray, hi = new osg::UIntArray, is = new osg::UIntArray, ii = new osg::UIntArray;
    hs->push_back(0);
    is->push_back(0);
    for (uint32_t c = 0; c < maxId; ++c) {
        hi->insert(hi->end(), hidden[c].begin(), hidden[c].end());
        ii->insert(ii->end(), imps[c].begin(), imps[c].end());
        hs->push_back(unsigned(hi->size()));
        is->push_back(unsigned(ii->size()));
    }
    root->setHiddenStart(hs.get());
    root->setHiddenItems(hi.get());
    root->setImpostorStart(is.get());
    root->setImpostorItems(ii.get());
    return root;
}

}  // namespace vista
