#include "citygen/mesh_builder.h"

#include <algorithm>
#include <cmath>

#include "citygen/polygon.h"

namespace vista {

TileGrid::TileGrid(const CityParams& p) : _half(p.size_m * 0.5), _size(p.tile_size_m) {
    _n = std::max(1, int(std::ceil(p.size_m / p.tile_size_m - 1e-9)));
}

int TileGrid::tileOf(const glm::dvec2& p) const {
    int x = std::clamp(int(std::floor((p.x + _half) / _size)), 0, _n - 1);
    int y = std::clamp(int(std::floor((p.y + _half) / _size)), 0, _n - 1);
    return y * _n + x;
}

glm::dvec3 TileGrid::origin(int tile) const { return {-_half + ix(tile) * _size, -_half + iy(tile) * _size, 0.0}; }

MeshBuilder::MeshBuilder(Mesh& target, const glm::dvec3& origin, Material material, const Lighting& light,
                         double variation)
    : _mesh(target), _origin(origin), _material(material), _light(light), _variation(variation) {}

uint32_t MeshBuilder::vertex(const glm::dvec3& p, const glm::vec3& n, const glm::u8vec4& c) {
    _mesh.positions.push_back(glm::vec3(p - _origin));
    _mesh.normals.push_back(n);
    _mesh.colors.push_back(c);
    if (_mesh.ids.size() + 1 != _mesh.positions.size()) _mesh.ids.resize(_mesh.positions.size() - 1, 0u);
    _mesh.ids.push_back(_id);
    return uint32_t(_mesh.positions.size() - 1);
}

glm::u8vec4 MeshBuilder::faceColor(const glm::dvec3& n, const glm::dvec3& c) const {
    if (_material == Material::Window && _light.night && windowLit(c, _light)) return litWindowColor();
    if (!_hasAlbedo) return prelitColor(_material, n, _light, _variation);
    const uint8_t alpha = _light.glass && _material == Material::Window ? kGlassAlpha : 255;
    return prelitAlbedo(_albedo, n, _light, alpha);
}

void MeshBuilder::triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c) {
    const glm::dvec3 v[3] = {a, b, c};
    face(glm::cross(b - a, c - a), v, 3);
}

void MeshBuilder::quad(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d) {
    const glm::dvec3 v[4] = {a, b, c, d};
    face(glm::cross(c - a, d - b), v, 4);
}

void MeshBuilder::face(glm::dvec3 n, const glm::dvec3* v, int count) {
    const double len = glm::length(n);
    if (!(len > 1e-12)) return;
    n /= len;
    glm::dvec3 centre(0.0);
    for (int k = 0; k < count; ++k) centre += v[k];
    const auto col = faceColor(n, centre / double(count));
    const glm::vec3 nf(n);
    uint32_t i[4];
    for (int k = 0; k < count; ++k) i[k] = vertex(v[k], nf, col);
    if (count == 3) _mesh.indices.insert(_mesh.indices.end(), {i[0], i[1], i[2]});
    else _mesh.indices.insert(_mesh.indices.end(), {i[0], i[1], i[2], i[0], i[2], i[3]});
}

void MeshBuilder::polygon(const std::vector<glm::dvec3>& pts, const glm::dvec3& normal) {
    if (pts.size() < 3) return;
    glm::dvec3 n = glm::normalize(normal);
    glm::dvec3 u = std::abs(n.z) < 0.9 ? glm::normalize(glm::cross(glm::dvec3(0, 0, 1), n)) : glm::dvec3(1, 0, 0);
    glm::dvec3 v = glm::cross(n, u);
    std::vector<glm::dvec2> p2;
    p2.reserve(pts.size());
    for (const auto& p : pts) p2.emplace_back(glm::dot(p - pts[0], u), glm::dot(p - pts[0], v));
    auto tris = triangulate(p2);
    if (tris.empty()) return;
    glm::dvec3 centre(0.0);
    for (const auto& p : pts) centre += p;
    auto col = faceColor(n, centre / double(pts.size()));
    glm::vec3 nf(n);
    uint32_t base = uint32_t(_mesh.positions.size());
    for (const auto& p : pts) vertex(p, nf, col);
    for (uint32_t t : tris) _mesh.indices.push_back(base + t);
}

void MeshBuilder::prism(const std::vector<glm::dvec2>& fp, double z0, double z1, bool top) {
    size_t n = fp.size();
    if (n < 3 || !(z1 > z0)) return;
    bool ccw = signedArea(fp) > 0;
    for (size_t i = 0; i < n; ++i) {
        glm::dvec2 a = fp[ccw ? i : n - 1 - i], b = fp[ccw ? (i + 1) % n : (2 * n - 2 - i) % n];
        quad({a, z0}, {b, z0}, {b, z1}, {a, z1});
    }
    if (top) {
        std::vector<glm::dvec3> t;
        for (size_t i = 0; i < n; ++i) t.emplace_back(fp[ccw ? i : n - 1 - i], z1);
        polygon(t, {0, 0, 1});
    }
}

}  // namespace vista
