#include "citygen/generate.h"

#include <chrono>
#include <mutex>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "citygen/blocks.h"
#include "citygen/buildings.h"
#include "citygen/labels.h"
#include "citygen/mesh_builder.h"
#include "citygen/parked_cars.h"
#include "citygen/polygon.h"
#include "citygen/street_lights.h"
#include "citygen/streets.h"
#include "citygen/surfaces.h"
#include "citygen/traffic_signals.h"
#include "citygen/trees.h"

namespace vista {

namespace {

class StageTimer {
public:
    StageTimer(City& city, Progress* progress, const char* name) : _city(city), _progress(progress), _name(name) {
        if (_progress) _progress->begin(name);
        _t0 = std::chrono::steady_clock::now();
    }
    ~StageTimer() {
        double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - _t0).count();
        _city.stageTimes.push_back({_name, s});
        if (_progress) _progress->end();
    }

private:
    City& _city;
    Progress* _progress;
    const char* _name;
    std::chrono::steady_clock::time_point _t0;
};

}  // namespace

void meshTiles(City& city, const std::vector<int>& only, Progress* progress) {
    const CityParams& p = city.params;
    TileGrid grid(p);
    Lighting light(p);
    // Assign buildings and trees to tiles by anchor point (stable order).
    std::vector<std::vector<uint32_t>> buildingsOf(size_t(grid.count())), treesOf(size_t(grid.count()));
    for (uint32_t i = 0; i < city.buildings.size(); ++i)
        buildingsOf[size_t(grid.tileOf(centroid(city.buildings[i].footprint)))].push_back(i);
    for (uint32_t i = 0; i < city.trees.size(); ++i)
        treesOf[size_t(grid.tileOf(glm::dvec2(city.trees[i].position)))].push_back(i);
    std::vector<std::vector<uint32_t>> lightsOf(size_t(grid.count()));
    for (uint32_t i = 0; i < city.streetLights.size(); ++i)
        lightsOf[size_t(grid.tileOf(glm::dvec2(city.streetLights[i])))].push_back(i);

    const SurfaceIndex surfaceIndex = buildSurfaceIndex(city, grid);
    // Signals (traffic lights, stop and yield signs): the lane model's, each in the tile of its pole.
    const std::vector<SignalPlacement>& signals = surfaceIndex.lanes.signals;
    std::vector<std::vector<uint32_t>> carsOf(size_t(grid.count()));
    for (uint32_t i = 0; i < city.cars.size(); ++i)
        carsOf[size_t(grid.tileOf(glm::dvec2(city.cars[i].position)))].push_back(i);
    std::vector<std::vector<uint32_t>> signalsOf(size_t(grid.count()));
    for (uint32_t i = 0; i < signals.size(); ++i) signalsOf[size_t(grid.tileOf(signals[i].position))].push_back(i);
    std::vector<int> which = only;
    if (which.empty())
        for (int t = 0; t < grid.count(); ++t) which.push_back(t);
    for (int t : which) VISTA_CHECK(t >= 0 && t < grid.count());
    std::vector<Tile> tiles(which.size());
    std::mutex m;
    size_t done = 0;
    tbb::parallel_for(0, int(which.size()), [&](int k) {
        const int t = which[size_t(k)];
        Tile& tile = tiles[size_t(k)];
        tile.ix = grid.ix(t);
        tile.iy = grid.iy(t);
        tile.origin = grid.origin(t);
        meshSurfaces(city, grid, t, light, tile, &surfaceIndex);
        BuildingMeshes out{&tile.meshes[size_t(Material::Wall)], &tile.meshes[size_t(Material::Window)],
                           &tile.meshes[size_t(Material::Roof)]};
        for (uint32_t b : buildingsOf[size_t(t)]) meshBuilding(city.buildings[b], b, p, light, tile.origin, out);
        tile.trees = treesOf[size_t(t)];
        tile.streetLights = lightsOf[size_t(t)];
        for (uint32_t l : tile.streetLights)
            meshStreetLight(city.streetLights[l], tile.origin, light, tile.meshes[size_t(Material::Lamp)],
                            makeInstanceId(InstanceKind::StreetLight, l));
        for (uint32_t i : signalsOf[size_t(t)]) {
            const SignalPlacement& sp = signals[i];
            meshSignal(sp, p, tile.origin, light, tile.meshes[size_t(signalMaterial(sp.kind))],
                       makeInstanceId(signalInstanceKind(sp.kind), i));
        }
        for (uint32_t c : carsOf[size_t(t)])
            meshParkedCar(city.cars[c], tile.origin, light, tile.meshes[size_t(Material::Car)],
                          makeInstanceId(InstanceKind::Car, c));
        std::lock_guard<std::mutex> lock(m);
        ++done;
    });
    if (progress) progress->update(1.0);
    city.tiles.clear();
    for (auto& t : tiles) {
        bool any = !t.trees.empty();
        for (const auto& mesh : t.meshes) any = any || !mesh.empty();
        if (any) city.tiles.push_back(std::move(t));
    }
}

Result<City> generateCity(const CityParams& params, const GenerateOptions& options) {
    Status s = validateParams(params);
    if (!s) return s;
    VISTA_RETURN_IF_ERROR(checkSingleFileSize(params));
    int threads = params.threads > 0 ? params.threads : int(tbb::info::default_concurrency());
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, size_t(threads));

    City city;
    city.params = params;
    Progress* pr = options.progress;
    {
        StageTimer t(city, pr, "streets");
        city.streets = options.streets ? *options.streets : growStreets(params, pr);
    }
    {
        StageTimer t(city, pr, "blocks");
        city.blocks = extractBlocks(city.streets, params, pr);
    }
    {
        StageTimer t(city, pr, "lots");
        city.lots = subdivideLots(city.blocks, params, pr);
    }
    {
        StageTimer t(city, pr, "buildings");
        std::vector<Building> imported;
        if (options.osmBuildings) {
            city.osmBuildings = options.osmStats;
            city.osmBuildings.enabled = true;
            imported = resolveOsmBuildings(*options.osmBuildings, params, city.osmBuildings);
            city.osmBuildings.lotsDropped = dropCoveredLots(city.lots, imported);
            city.osmBuildings.onCarriageway = countOnCarriageway(imported, city.streets);
        }
        city.buildings = placeBuildings(city.lots, city.blocks, params, pr);
        for (auto& b : imported) city.buildings.push_back(std::move(b));
    }
    {
        StageTimer t(city, pr, "trees");
        city.treePrototypes = makeTreePrototypes(params, Lighting(params));
        city.trees = placeTrees(city, pr);
    }
    if (params.effects.night) {
        StageTimer t(city, pr, "street lights");
        city.streetLights = placeStreetLights(city);
    }
    if (params.parked_car_share > 0) {
        StageTimer t(city, pr, "parked cars");
        city.cars = placeParkedCars(city, buildLaneModel(city.streets, params, &city.blocks));
    }
    if (options.beforeMeshing) VISTA_RETURN_IF_ERROR(options.beforeMeshing(city));
    {
        StageTimer t(city, pr, "meshes");
        meshTiles(city, {}, pr);
    }
    return city;
}

size_t estimateStoredTriangles(const City& layout) {
    const TileGrid grid(layout.params);
    const int n = grid.count();
    if (n <= 0) return 0;
    const int want = std::min(n, std::clamp(n / 8, 16, 64));
    std::vector<int> sample;
    for (int k = 0; k < want; ++k) sample.push_back(int((int64_t(k) * n + n / (2 * want)) / want));
    City c = layout;  // meshTiles replaces the copy's tiles, not the layout's
    meshTiles(c, sample, nullptr);
    size_t tileTriangles = 0;
    for (const Tile& t : c.tiles)
        for (const Mesh& m : t.meshes) tileTriangles += m.indices.size() / 3;
    size_t prototypes = 0;
    for (const TreePrototype& p : layout.treePrototypes) prototypes += p.mesh.indices.size() / 3;
    return size_t(std::llround(double(tileTriangles) * double(n) / double(sample.size()))) + prototypes;
}

CityCounts countCity(const City& c) {
    CityCounts n;
    n.streetNodes = c.streets.nodes.size();
    n.streetEdges = c.streets.edges.size();
    n.blocks = c.blocks.size();
    n.lots = c.lots.size();
    n.buildings = c.buildings.size();
    n.trees = c.trees.size();
    for (const auto& t : c.tiles)
        for (const auto& m : t.meshes) {
            n.triangles += m.triangleCount();
            n.vertices += m.positions.size();
            n.drawCalls += m.empty() ? 0 : 1;
        }
    n.storedTriangles = n.triangles;
    for (const auto& p : c.treePrototypes) n.storedTriangles += p.mesh.triangleCount();
    // Trees are drawn instanced: one draw per (tile, prototype) pair.
    for (const auto& t : c.tiles) {
        std::vector<bool> u(c.treePrototypes.size(), false);
        for (uint32_t i : t.trees)
            if (c.trees[i].prototype < u.size() && !u[c.trees[i].prototype]) {
                u[c.trees[i].prototype] = true;
                ++n.drawCalls;
            }
    }
    for (const auto& tr : c.trees) {
        if (tr.prototype < c.treePrototypes.size()) {
            n.triangles += c.treePrototypes[tr.prototype].mesh.triangleCount();
            n.vertices += c.treePrototypes[tr.prototype].mesh.positions.size();
        }
    }
    return n;
}

}  // namespace vista
