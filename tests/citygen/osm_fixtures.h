// Helpers shared by the OSM import tests: geodesic reference (Vincenty), a writer of small
// OSM files, an import of OSM text.
#pragma once

#include <gtest/gtest.h>
#include <sys/wait.h>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <random>
#include <nlohmann/json.hpp>
#include "citygen/footprint_repair.h"
#include "citygen/generate.h"
#include "citygen/geodesy.h"
#include "citygen/osm_buildings.h"
#include "citygen/polygon.h"
#include "citygen/streets.h"
#include "tests/common/temp_dir.h"

using namespace vista;

inline std::string fixture(const char* name) { return std::string(VISTA_TEST_DATA) + "/osm/" + name; }

constexpr double kD2R = 3.14159265358979323846 / 180.0;

// Vincenty's inverse formula on WGS84: geodesic distance in metres (independent of geodesy.cpp).
inline double vincenty(const GeoPoint& p, const GeoPoint& q) {
    const double a = 6378137.0, f = 1 / 298.257223563, b = a * (1 - f);
    const double L = std::remainder(q.lon_deg - p.lon_deg, 360.0) * kD2R;
    const double U1 = std::atan((1 - f) * std::tan(p.lat_deg * kD2R)),
                 U2 = std::atan((1 - f) * std::tan(q.lat_deg * kD2R));
    const double sU1 = std::sin(U1), cU1 = std::cos(U1), sU2 = std::sin(U2), cU2 = std::cos(U2);
    double lam = L, sinS = 0, cosS = 0, sig = 0, cos2A = 0, cos2Sm = 0;
    for (int i = 0; i < 200; ++i) {
        const double sl = std::sin(lam), cl = std::cos(lam);
        sinS = std::hypot(cU2 * sl, cU1 * sU2 - sU1 * cU2 * cl);
        if (sinS == 0) return 0;
        cosS = sU1 * sU2 + cU1 * cU2 * cl;
        sig = std::atan2(sinS, cosS);
        const double sinA = cU1 * cU2 * sl / sinS;
        cos2A = 1 - sinA * sinA;
        cos2Sm = cos2A != 0 ? cosS - 2 * sU1 * sU2 / cos2A : 0;
        const double C = f / 16 * cos2A * (4 + f * (4 - 3 * cos2A));
        const double prev = lam;
        lam = L + (1 - C) * f * sinA * (sig + C * sinS * (cos2Sm + C * cosS * (-1 + 2 * cos2Sm * cos2Sm)));
        if (std::abs(lam - prev) < 1e-13) break;
    }
    const double u2 = cos2A * (a * a - b * b) / (b * b);
    const double A = 1 + u2 / 16384 * (4096 + u2 * (-768 + u2 * (320 - 175 * u2)));
    const double B = u2 / 1024 * (256 + u2 * (-128 + u2 * (74 - 47 * u2)));
    const double dS = B * sinS *
                      (cos2Sm + B / 4 *
                                    (cosS * (-1 + 2 * cos2Sm * cos2Sm) -
                                     B / 6 * cos2Sm * (-3 + 4 * sinS * sinS) * (-3 + 4 * cos2Sm * cos2Sm)));
    return b * A * (sig - dS);
}

// Point at `dist` metres and `bearing` degrees from p on a sphere (only to place test points).
inline GeoPoint destination(const GeoPoint& p, double bearingDeg, double dist) {
    const double d = dist / 6371000.0, t = bearingDeg * kD2R, f1 = p.lat_deg * kD2R;
    const double f2 = std::asin(std::sin(f1) * std::cos(d) + std::cos(f1) * std::sin(d) * std::cos(t));
    const double l2 = p.lon_deg * kD2R +
                      std::atan2(std::sin(t) * std::sin(d) * std::cos(f1), std::cos(d) - std::sin(f1) * std::sin(f2));
    return {f2 / kD2R, std::remainder(l2 / kD2R, 360.0)};
}

// The largest city an OSM import may span (a paged city).
inline double maxCitySize() { return kMaxPagedSizeM; }

// A synthetic .osm file; coordinates are written with 7 decimals (OSM's resolution) and
// remembered as written.
class OsmWriter {
public:
    int64_t node(const GeoPoint& p) {
        char buf[128];
        std::snprintf(buf, sizeof buf, "lat=\"%.7f\" lon=\"%.7f\"", p.lat_deg, p.lon_deg);
        GeoPoint written{std::round(p.lat_deg * 1e7) / 1e7, std::round(p.lon_deg * 1e7) / 1e7};
        const int64_t id = rawNode(buf);
        _geo[id] = written;
        return id;
    }
    int64_t rawNode(const std::string& attrs) {
        const int64_t id = _next++;
        _nodes += "  <node id=\"" + std::to_string(id) + "\" " + attrs + "/>\n";
        return id;
    }
    void way(const std::vector<int64_t>& refs, const char* highway = "residential") {
        _ways += "  <way id=\"" + std::to_string(_nextWay++) + "\">";
        for (int64_t r : refs) _ways += "<nd ref=\"" + std::to_string(r) + "\"/>";
        _ways += std::string("<tag k=\"highway\" v=\"") + highway + "\"/></way>\n";
    }
    // A grid of n x n crossing straight roads (no shared nodes) of side `side` metres about `centre`.
    void grid(const GeoPoint& centre, double side, int n) {
        for (int i = 0; i < n; ++i) {
            const double off = -0.5 * side + side * (i + 0.5) / n;
            const GeoPoint ew = destination(centre, 0, off), ns = destination(centre, 90, off);
            way({node(destination(ew, 270, 0.5 * side)), node(destination(ew, 90, 0.5 * side))});
            way({node(destination(ns, 180, 0.5 * side)), node(destination(ns, 0, 0.5 * side))});
        }
    }
    const GeoPoint& at(int64_t id) const { return _geo.at(id); }
    std::string text(const std::string& header = "") const {
        return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<osm version=\"0.6\" generator=\"vista-test\">\n" + header +
               _nodes + _ways + "</osm>\n";
    }
    std::string write(const test::TempDir& dir, const std::string& name, const std::string& header = "") const {
        const std::string path = dir.file(name);
        std::ofstream(path, std::ios::binary) << text(header);
        return path;
    }

private:
    int64_t _next = 1, _nextWay = 1;
    std::string _nodes, _ways;
    std::map<int64_t, GeoPoint> _geo;
};
