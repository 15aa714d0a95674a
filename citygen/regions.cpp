#include "citygen/regions.h"
#include "foundation/format.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include "citygen/blocks.h"
#include "citygen/buildings.h"
#include "citygen/generate.h"
#include "citygen/lanes.h"
#include "citygen/lighting.h"
#include "citygen/parked_cars.h"
#include "citygen/polygon.h"
#include "citygen/street_lights.h"
#include "citygen/streets.h"
#include "citygen/trees.h"

namespace vista {

namespace {

// The worker limit of params.threads (0 = all), for the scope of one call.
tbb::global_control threadLimit(const CityParams& p) {
    const int threads = p.threads > 0 ? p.threads : int(tbb::info::default_concurrency());
    return tbb::global_control(tbb::global_control::max_allowed_parallelism, size_t(threads));
}

// Regions whose rectangle, grown by the halo, meets the box [lo, hi].
template <class F>
void forRegionsNear(const RegionGrid& grid, double half, double regionSize, glm::dvec2 lo, glm::dvec2 hi, F&& f) {
    lo -= kRegionHaloM;
    hi += kRegionHaloM;
    const int n = grid.countX();
    auto cell = [&](double v) { return std::clamp(int(std::floor((v + half) / regionSize)), 0, n - 1); };
    if (!std::isfinite(lo.x + lo.y + hi.x + hi.y)) return;
    for (int y = cell(lo.y); y <= cell(hi.y); ++y)
        for (int x = cell(lo.x); x <= cell(hi.x); ++x) f(y * n + x);
}

}  // namespace

Status validateRegionSize(const CityParams& p, double r) {
    const double lo = std::max(kMinRegionSizeM, p.tile_size_m);
    const std::string range = " (metres; allowed: " + exactDecimal(lo) + " .. " + exactDecimal(kMaxRegionSizeM) +
                              ", a whole multiple of tile_size_m = " + exactDecimal(p.tile_size_m) + ")";
    if (!std::isfinite(r) || r < lo || r > kMaxRegionSizeM)
        return Status::error("parameter 'region_size_m' = " + exactDecimal(r) + " is out of range" + range);
    const double k = r / p.tile_size_m;
    if (std::abs(k - std::round(k)) > 1e-9 * k)
        return Status::error("parameter 'region_size_m' = " + exactDecimal(r) + " is not a whole number of tiles" +
                             range);
    return Status::ok();
}

RegionGrid::RegionGrid(const CityParams& p, double regionSizeM)
    : _tiles(p), _half(0.5 * p.size_m), _tileSize(p.tile_size_m), _tileCount(_tiles.countX()) {
    _k = std::max(1, int(std::lround(regionSizeM / p.tile_size_m)));
    _n = (_tileCount + _k - 1) / _k;
}

int RegionGrid::regionOfTile(int tile) const { return (_tiles.iy(tile) / _k) * _n + _tiles.ix(tile) / _k; }

std::vector<int> RegionGrid::tilesOf(int region) const {
    VISTA_CHECK(region >= 0 && region < count());
    std::vector<int> out;
    const int x0 = ix(region) * _k, y0 = iy(region) * _k;
    for (int y = y0; y < std::min(y0 + _k, _tileCount); ++y)
        for (int x = x0; x < std::min(x0 + _k, _tileCount); ++x) out.push_back(y * _tileCount + x);
    return out;
}

void RegionGrid::bounds(int region, glm::dvec2& lo, glm::dvec2& hi) const {
    VISTA_CHECK(region >= 0 && region < count());
    const double side = _k * _tileSize;
    lo = glm::dvec2(-_half + ix(region) * side, -_half + iy(region) * side);
    hi = glm::min(lo + side, glm::dvec2(_half));
}

Result<RegionalCity> RegionalCity::create(const CityParams& params, double regionSizeM, Progress* progress,
                                          const RegionalInputs& inputs) {
    VISTA_RETURN_IF_ERROR(validateParams(params));
    VISTA_RETURN_IF_ERROR(validateRegionSize(params, regionSizeM));
    RegionalCity rc(params, regionSizeM);
    const auto limit = threadLimit(params);
    if (progress) progress->begin("streets");
    rc._streets = inputs.streets ? *inputs.streets : growStreets(params, progress);
    if (progress) progress->end();
    if (inputs.osmBuildings) {
        rc._osmStats.enabled = true;
        rc._imported = resolveOsmBuildings(*inputs.osmBuildings, params, rc._osmStats);
    }
    if (progress) progress->begin("blocks");
    rc._blocks = extractBlocks(rc._streets, params, progress);
    if (progress) progress->end();
    rc._prototypes = makeTreePrototypes(params, Lighting(params));

    const RegionGrid& grid = rc._grid;
    const double half = 0.5 * params.size_m, side = grid.tilesPerRegion() * params.tile_size_m;
    rc._edgesNear.resize(size_t(grid.count()));
    rc._blocksNear.resize(size_t(grid.count()));
    rc._importedNear.resize(size_t(grid.count()));
    const StreetGraph& g = rc._streets;
    for (uint32_t e = 0; e < g.edges.size(); ++e) {
        const glm::dvec2 a = g.nodes[g.edges[e].a], b = g.nodes[g.edges[e].b];
        forRegionsNear(grid, half, side, glm::min(a, b), glm::max(a, b),
                       [&](int r) { rc._edgesNear[size_t(r)].push_back(e); });
    }
    for (uint32_t i = 0; i < rc._blocks.size(); ++i) {
        const Polygon2& o = rc._blocks[i].outline;
        if (o.empty()) continue;
        glm::dvec2 lo = o[0], hi = o[0];
        for (const auto& q : o) lo = glm::min(lo, q), hi = glm::max(hi, q);
        forRegionsNear(grid, half, side, lo, hi, [&](int r) { rc._blocksNear[size_t(r)].push_back(i); });
    }
    for (uint32_t i = 0; i < rc._imported.size(); ++i) {
        const Polygon2& o = rc._imported[i].footprint;
        if (o.empty()) continue;
        glm::dvec2 lo = o[0], hi = o[0];
        for (const auto& q : o) lo = glm::min(lo, q), hi = glm::max(hi, q);
        forRegionsNear(grid, half, side, lo, hi, [&](int r) { rc._importedNear[size_t(r)].push_back(i); });
    }
    // Node -> incident edges.
    rc._nodeEdgeStart.assign(g.nodes.size() + 1, 0);
    for (const auto& e : g.edges) ++rc._nodeEdgeStart[e.a + 1], ++rc._nodeEdgeStart[e.b + 1];
    for (size_t i = 1; i < rc._nodeEdgeStart.size(); ++i) rc._nodeEdgeStart[i] += rc._nodeEdgeStart[i - 1];
    rc._nodeEdges.resize(rc._nodeEdgeStart.back());
    std::vector<uint32_t> fill(rc._nodeEdgeStart.begin(), rc._nodeEdgeStart.end() - 1);
    for (uint32_t e = 0; e < g.edges.size(); ++e) {
        rc._nodeEdges[fill[g.edges[e].a]++] = e;
        rc._nodeEdges[fill[g.edges[e].b]++] = e;
    }
    return rc;
}

City RegionalCity::region(int r) const {
    VISTA_CHECK(r >= 0 && r < _grid.count());
    const auto limit = threadLimit(_params);
    City c;
    c.params = _params;
    c.treePrototypes = _prototypes;

    // Streets: the edges near the region and every edge at their end nodes.
    std::vector<uint32_t> edges = _edgesNear[size_t(r)];
    for (uint32_t e : _edgesNear[size_t(r)])
        for (uint32_t n : {_streets.edges[e].a, _streets.edges[e].b})
            for (uint32_t k = _nodeEdgeStart[n]; k < _nodeEdgeStart[n + 1]; ++k) edges.push_back(_nodeEdges[k]);
    std::sort(edges.begin(), edges.end());
    edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
    std::vector<uint32_t> nodes;
    for (uint32_t e : edges) nodes.push_back(_streets.edges[e].a), nodes.push_back(_streets.edges[e].b);
    std::sort(nodes.begin(), nodes.end());
    nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
    auto newIndex = [&](uint32_t n) {
        return uint32_t(std::lower_bound(nodes.begin(), nodes.end(), n) - nodes.begin());
    };
    for (uint32_t n : nodes) c.streets.nodes.push_back(_streets.nodes[n]);
    for (uint32_t e : edges) {
        StreetEdge se = _streets.edges[e];
        se.a = newIndex(se.a);
        se.b = newIndex(se.b);
        c.streets.edges.push_back(se);
    }
    for (uint32_t b : _blocksNear[size_t(r)]) c.blocks.push_back(_blocks[b]);

    c.lots = subdivideLots(c.blocks, _params, nullptr);
    std::vector<Building> imported;
    for (uint32_t i : _importedNear[size_t(r)]) imported.push_back(_imported[i]);
    if (!imported.empty()) dropCoveredLots(c.lots, imported);
    c.buildings = placeBuildings(c.lots, c.blocks, _params, nullptr);
    for (auto& b : imported) c.buildings.push_back(std::move(b));
    c.trees = placeTrees(c, nullptr);
    if (_params.effects.night) c.streetLights = placeStreetLights(c);
    if (_params.parked_car_share > 0) c.cars = placeParkedCars(c, buildLaneModel(c.streets, _params, &c.blocks));

    // Keep what is anchored in the region.
    const TileGrid tiles(_params);
    auto inRegion = [&](const glm::dvec2& p) { return _grid.regionOfTile(tiles.tileOf(p)) == r; };
    std::vector<Building> buildings;
    for (auto& b : c.buildings)
        if (inRegion(centroid(b.footprint))) buildings.push_back(std::move(b));
    c.buildings = std::move(buildings);
    std::vector<TreeInstance> trees;
    for (const auto& t : c.trees)
        if (inRegion(glm::dvec2(t.position))) trees.push_back(t);
    c.trees = std::move(trees);
    std::vector<glm::dvec3> lights;
    for (const auto& l : c.streetLights)
        if (inRegion(glm::dvec2(l))) lights.push_back(l);
    c.streetLights = std::move(lights);
    std::vector<ParkedCar> cars;
    for (const auto& car : c.cars)
        if (inRegion(glm::dvec2(car.position))) cars.push_back(car);
    c.cars = std::move(cars);

    meshTiles(c, _grid.tilesOf(r), nullptr);
    return c;
}

City RegionalCity::coarse(const City& region) {
    City k;
    k.params = region.params;
    k.params.detail = 0;
    k.treePrototypes = region.treePrototypes;
    k.trees = region.trees;  // drawn as impostors (tree_impostor.h)
    k.treeImpostors = true;
    const TileGrid grid(k.params);
    const Lighting light(k.params);
    std::map<std::pair<int, int>, std::vector<uint32_t>> buildingsOf;
    for (uint32_t b = 0; b < region.buildings.size(); ++b) {
        const int t = grid.tileOf(centroid(region.buildings[b].footprint));
        buildingsOf[{grid.ix(t), grid.iy(t)}].push_back(b);
    }
    for (const Tile& t : region.tiles) {
        Tile out;
        out.ix = t.ix;
        out.iy = t.iy;
        out.origin = t.origin;
        out.trees = t.trees;
        for (Material m : {Material::Ground, Material::Grass, Material::Road})
            out.meshes[size_t(m)] = t.meshes[size_t(m)];
        BuildingMeshes bm{&out.meshes[size_t(Material::Wall)], &out.meshes[size_t(Material::Window)],
                          &out.meshes[size_t(Material::Roof)]};
        auto it = buildingsOf.find({t.ix, t.iy});
        if (it != buildingsOf.end())
            for (uint32_t b : it->second) meshBuilding(region.buildings[b], b, k.params, light, out.origin, bm);
        bool any = !out.trees.empty();
        for (const auto& m : out.meshes) any = any || !m.empty();
        if (any) k.tiles.push_back(std::move(out));
    }
    return k;
}

}  // namespace vista
