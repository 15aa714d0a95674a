#include "bake/bake_cell.h"

#include <algorithm>
#include <cmath>

#include <tbb/parallel_for.h>

#include "bake/point_removal.h"
#include "citygen/terrain.h"
#include "foundation/hash.h"
#include "foundation/timing.h"
#include "foundation/units.h"

namespace vista {

BakeInput prepareBake(const SceneModel& city, const BakeParams& p) {
    BakeInput in;
    in.city = &city;
    in.tiles = bakeTiles(city);
    const CityParams cp = city.params;
    auto ground = [&cp](const glm::dvec2& q) { return terrainHeight(cp, q); };
    in.cells = makeViewCells(city.streets, glm::dvec2(cp.origin_x, cp.origin_y), ground, p.cells, &in.skipped);
    if (p.representation == BakeRepresentation::Points && p.placement.byCost) {
        auto rays = RayScene::build(city);
        if (rays) in.cityRays = std::shared_ptr<const RayScene>(std::move(*rays));
        in.tileLookup = TileLookup::build(city, in.tiles);
    }
    return in;
}

namespace {

// Software projection of the points from the cell centre (target view looking
// along the sampling-plane normal): covered pixels and screen bounding box.
void screenStats(const PointImpostorData& d, const Box3& cell, const SamplingSetup& s, const SamplingParams& sp,
                 ImpostorStats& st) {
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
        const int px = int(std::floor((x * 0.5 + 0.5) * sp.outWidth)),
                  py = int(std::floor((0.5 - y * 0.5) * sp.outHeight));
        if (px < 0 || py < 0 || px >= sp.outWidth || py >= sp.outHeight) continue;
        hit[size_t(py) * size_t(sp.outWidth) + size_t(px)] = 1;
        bx0 = std::min(bx0, px);
        bx1 = std::max(bx1, px);
        by0 = std::min(by0, py);
        by1 = std::max(by1, py);
    }
    st.screenPixels = size_t(std::count(hit.begin(), hit.end(), uint8_t(1)));
    st.screenBBoxPixels = bx1 >= bx0 ? size_t(bx1 - bx0 + 1) * size_t(by1 - by0 + 1) : 0;
}

}  // namespace

Status bakeImpostor(const TriangleSoup& soup, const Box3& cellBox, const BakeParams& p, uint64_t entity,
                    ImpostorResult& r,
                    const std::function<std::vector<uint8_t>(const std::vector<glm::vec3>&)>& keepVisible) {
    Box3 far{glm::dvec3(1e300), glm::dvec3(-1e300)};
    for (uint32_t idx : soup.indices) {
        far.lo = glm::min(far.lo, glm::dvec3(soup.positions[idx]));
        far.hi = glm::max(far.hi, glm::dvec3(soup.positions[idx]));
    }
    r.stats.farTriangles = soup.triangleCount();
    auto setup = setupSampling(cellBox, far);
    if (!setup) return setup.status();
    auto scene = RayScene::build(soup);  // medium quality, no back-face culling: every layer of the far field
    if (!scene) return scene.status();
    const SamplingSetup& s = *setup;
    LdiResult ldi = sampleLdi(**scene, s, far, p.sampling);
    // Visibility first (cheap per sample), then the removal only among the
    // visible samples: both are decided per sample, so the order does not
    // change the result, only the work.
    std::vector<uint8_t> visible;
    if (keepVisible) {
        std::vector<glm::vec3> all(ldi.samples.size());
        for (size_t i = 0; i < all.size(); ++i) all[i] = ldi.samples[i].pos;
        visible = keepVisible(all);
        visible.resize(all.size(), 0);
    }
    std::vector<uint8_t> keep = removeRedundant(ldi, s, cellBox, p.sampling, keepVisible ? &visible : nullptr);
    std::vector<glm::vec3> pts;
    for (size_t i = 0; i < ldi.samples.size(); ++i)
        if (keep[i]) pts.push_back(ldi.samples[i].pos);
    r.stats.ldiRays = ldi.rays;
    r.stats.ldiSamples = ldi.samples.size();
    r.stats.afterRemoval = pts.size();
    const size_t occludedDropped = keepVisible ? size_t(std::count(visible.begin(), visible.end(), uint8_t(0))) : 0;
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
    r.stats.textured =
        size_t(std::count_if(r.data.block.begin(), r.data.block.end(), [](int32_t b) { return b >= 0; }));
    r.stats.dropped = as.dropped + occludedDropped;
    r.stats.noiseSingle = as.noiseOnly;
    screenStats(r.data, cellBox, s, p.sampling, r.stats);
    return Status::ok();
}

Status bakeMeshEnd(const TriangleSoup& soup, const Box3& cellBox, const BakeParams& p, MeshResult& r) {
    r.stats.farTriangles = soup.triangleCount();
    SoupSceneOptions so;
    so.cullBackFaces = true;  // as the rasteriser draws the far field
    auto scene = RayScene::build(soup, so);
    if (!scene) return scene.status();
    const int endBudget = std::max(p.mesh.maxTriangles / 2, 2);
    const DepthView view =
        chooseDepthView(soup, cellBox.center(), std::tan(outputPixelAngle(p.sampling)), p.mesh.imageSize, endBudget);
    const FarImage img = renderFarImage(**scene, view);
    const double cellRadius = 0.5 * glm::length(cellBox.hi - cellBox.lo);
    DepthMeshStats ds;
    r.mesh = buildDepthMesh(img, cellRadius, endBudget, p.mesh.errorPx, ds);
    r.stats.imageW = uint64_t(view.width);
    r.stats.imageH = uint64_t(view.height);
    r.stats.samples = ds.samples;
    r.stats.hits = ds.hits;
    r.stats.leaves = ds.leaves;
    r.stats.triangles = ds.triangles;
    r.stats.droppedTriangles = ds.droppedTriangles;
    r.stats.snapped = ds.snapped;
    r.stats.maxLeafErrorPx = ds.maxLeafErrorPx;
    return Status::ok();
}

namespace {

// The cell's two street ends, each with its far set: a far field with too few
// triangles gets a note; otherwise bakeEnd(far set, end, note prefix, the end's
// stopwatch, out) bakes it. Result header fields of both representations.
template <class BakeEnd>
CellResult forEachEnd(const BakeInput& in, const ViewCell& cell, const BakeParams& p, BakeEnd&& bakeEnd) {
    const Stopwatch cellTime;
    CellResult out;
    out.cell = cell.id;
    for (int end = 0; end < 2; ++end) {
        const Stopwatch endTime;
        FarSet fs = selectFarSet(*in.city, in.tiles, cell, end, p.far);
        const std::string what = "end " + std::to_string(end) + ": ";
        if (fs.soup.triangleCount() < std::max<size_t>(p.far.minTriangles, 1)) {
            out.notes.push_back(what + "far field small (" + std::to_string(fs.soup.triangleCount()) + " triangles < " +
                                std::to_string(p.far.minTriangles) + ")");
            continue;
        }
        bakeEnd(fs, end, what, endTime, out);
    }
    out.bakeMs = cellTime.ms();
    return out;
}

template <class R>
void startResult(R& r, const ViewCell& cell, int end, FarSet& fs) {
    r.cell = cell.id;
    r.end = uint8_t(end);
    r.frame = fs.frame;
    r.hiddenTiles = std::move(fs.tiles);
    r.stats.tiles = r.hiddenTiles.size();
}

}  // namespace

PlacementPlan planPlacement(const BakeInput& in, const BakeParams& p, std::atomic<size_t>* done) {
    std::vector<std::vector<PlannedEnd>> perCell(in.cells.size());
    if (in.cityRays)
        tbb::parallel_for(size_t(0), in.cells.size(), size_t(1), [&](size_t ci) {
            const ViewCell& cell = in.cells[ci];
            for (int end = 0; end < 2; ++end) {
                const FarSet fs = selectFarSet(*in.city, in.tiles, cell, end, p.far);
                if (fs.soup.triangleCount() < std::max<size_t>(p.far.minTriangles, 1)) continue;
                PlannedEnd e;
                e.cell = cell.id;
                e.end = uint8_t(end);
                e.estimate = estimatePlacement(*in.cityRays, in.tileLookup, cell, fs, p.sampling, p.placement);
                e.predictedMb = predictedMb(e.estimate, p.placement);
                perCell[ci].push_back(e);
            }
            if (done) ++*done;
        });
    std::vector<PlannedEnd> ends;
    for (auto& v : perCell) ends.insert(ends.end(), v.begin(), v.end());
    return rankPlacement(std::move(ends), p.placement.budgetMb);
}

CellResult bakeCell(const BakeInput& in, const ViewCell& cell, const BakeParams& p) {
    if (p.representation == BakeRepresentation::Mesh)
        return forEachEnd(in, cell, p,
                          [&](FarSet& fs, int end, const std::string& what, const Stopwatch& endTime, CellResult& out) {
                              MeshResult r;
                              startResult(r, cell, end, fs);
                              if (Status st = bakeMeshEnd(fs.soup, cellInFrame(cell, r.frame), p, r); !st) {
                                  out.notes.push_back(what + st.message());
                                  return;
                              }
                              if (r.mesh.indices.empty()) {
                                  out.notes.push_back(what + "no visible far geometry");
                                  return;
                              }
                              r.stats.bakeMs = endTime.ms();
                              out.meshes.push_back(std::move(r));
                          });
    return forEachEnd(
        in, cell, p, [&](FarSet& fs, int end, const std::string& what, const Stopwatch& endTime, CellResult& out) {
            if (p.placement.byCost) {
                const PlannedEnd* planned = in.plan ? in.plan->find(cell.id, end) : nullptr;
                if (!in.cityRays) {
                    out.notes.push_back(what + "placement by cost: no city ray scene, placed");
                } else if (planned) {
                    out.notes.push_back(what + planned->describe());
                    if (!planned->inBudget) return;
                } else {
                    const PlacementEstimate est =
                        estimatePlacement(*in.cityRays, in.tileLookup, cell, fs, p.sampling, p.placement);
                    out.notes.push_back(what + (est.place ? "placed: " : "not placed: ") + est.describe());
                    if (!est.place) return;
                }
            }
            ImpostorResult r;
            const ImpostorFrame frame = fs.frame;
            startResult(r, cell, end, fs);
            std::function<std::vector<uint8_t>(const std::vector<glm::vec3>&)> keep;
            if (p.placement.byCost && in.cityRays)
                keep = [&](const std::vector<glm::vec3>& pts) {
                    return visibleFromCell(*in.cityRays, cell, frame, pts, outputPixelAngle(p.sampling), p.placement);
                };
            if (Status st =
                    bakeImpostor(fs.soup, cellInFrame(cell, r.frame), p, hashKeys(cell.id, uint64_t(end)), r, keep);
                !st) {
                out.notes.push_back(what + st.message());
                return;
            }
            if (r.data.positions.empty()) {
                out.notes.push_back(what + "no visible points");
                return;
            }
            r.stats.bakeMs = endTime.ms();
            out.impostors.push_back(std::move(r));
        });
}

}  // namespace vista
