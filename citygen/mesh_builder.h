// TileGrid and MeshBuilder: put city-frame geometry into tile-local meshes.
//
// Contract: TileGrid covers the square [-size/2, size/2]^2 with tiles of
// params.tile_size_m (the last row/column may be partial); tile (ix, iy) has
// its origin at its south-west corner at z = 0 (city frame, double).
// tileOf() clamps positions outside the city to the border tiles.
// MeshBuilder appends flat-shaded, prelit triangles to one Mesh whose
// positions are relative to `origin`; input is city-frame double. A builder is
// not thread-safe; give each thread its own target Mesh.
#pragma once
#include <vector>

#include <glm/glm.hpp>

#include "citygen/lighting.h"
#include "citygen/mesh.h"
#include "citygen/params.h"

namespace vista {

class TileGrid {
public:
    explicit TileGrid(const CityParams& p);
    int countX() const { return _n; }
    int countY() const { return _n; }
    int count() const { return _n * _n; }
    int tileOf(const glm::dvec2& p) const;  // row-major index iy * countX + ix
    glm::dvec3 origin(int tile) const;
    int ix(int tile) const { return tile % _n; }
    int iy(int tile) const { return tile / _n; }

private:
    double _half, _size;
    int _n;
};

class MeshBuilder {
public:
    MeshBuilder(Mesh& target, const glm::dvec3& origin, Material material, const Lighting& light,
                double variation = 0.0);
    void setMaterial(Material m) { _material = m; }
    void setVariation(double v) { _variation = v; }
    // Ground-truth label of the following vertices (labels.h); 0 until set.
    void setId(uint32_t id) { _id = id; }
    // Materials effect: this albedo (linear RGB) instead of the material's palette x variation.
    void setAlbedo(const glm::dvec3& albedo) {
        _albedo = albedo;
        _hasAlbedo = true;
    }
    // Flat triangle/quad, counter-clockwise seen from the side the normal points to.
    void triangle(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c);
    void quad(const glm::dvec3& a, const glm::dvec3& b, const glm::dvec3& c, const glm::dvec3& d);
    // Planar polygon (counter-clockwise around `normal`), triangulated by ear
    // clipping in its plane. Degenerate polygons add nothing.
    void polygon(const std::vector<glm::dvec3>& pts, const glm::dvec3& normal);
    // Axis-aligned-in-yaw box: footprint quad (4 corners, CCW) extruded from z0 to z1, with top; no bottom.
    void prism(const std::vector<glm::dvec2>& footprint, double z0, double z1, bool top = true);

private:
    uint32_t vertex(const glm::dvec3& p, const glm::vec3& n, const glm::u8vec4& c);
    // The prelit colour of a face with unit normal n and centre c (night: lit windows glow).
    glm::u8vec4 faceColor(const glm::dvec3& n, const glm::dvec3& c) const;
    // One flat face of `count` (3 or 4) vertices with normal direction n (any length; degenerate faces are dropped).
    void face(glm::dvec3 n, const glm::dvec3* v, int count);
    Mesh& _mesh;
    glm::dvec3 _origin;
    Material _material;
    const Lighting& _light;
    double _variation;
    glm::dvec3 _albedo{0.0};
    bool _hasAlbedo = false;
    uint32_t _id = 0;
};

}  // namespace vista
