// Geodesy: WGS84 latitude/longitude <-> the local metric frame of a city.
//
// A city with a geo reference has its frame (x metres east, y metres north,
// (0,0) at the reference point) in the transverse Mercator projection of the
// WGS84 ellipsoid (a = 6378137 m, f = 1/298.257223563) with central meridian
// lon0, origin latitude lat0, scale 1 on the central meridian, no false
// easting or northing: PROJ's
//   +proj=tmerc +lat_0=<lat0> +lon_0=<lon0> +k_0=1 +x_0=0 +y_0=0 +ellps=WGS84
// (stored as projection "tmerc" in the parameter JSON, see params.h).
// Krueger series to 6th order in the third flattening (Karney 2011), all in
// double: the round trip is exact to well under 1 mm within 1,000 km of the
// reference point; the scale error at distance d from the central meridian
// is d^2 / (2 R^2) (1.5e-6 at 11 km), so projected distances inside a city
// agree with geodesic distances to about 1e-6.
// Holds anywhere on Earth: at the poles (lat +-90 included) and across the
// antimeridian (longitudes are taken relative to lon0 modulo 360, so lon
// 179.99 and -179.99 are 2.2 km apart at the equator, not a globe apart).
// Domain: projectToLocal() takes lat in [-90, 90] and any finite lon; it is
// meant for points within a few thousand km of the reference (it diverges
// 90 degrees away from the central meridian on the equator). localToGeo()
// takes |x|, |y| <= kGeoMaxLocal_m and returns lat in [-90, 90], lon in
// [-180, 180]. Out-of-domain arguments are contract violations (VISTA_CHECK).
// Pure functions, thread-safe.
#pragma once
#include <glm/glm.hpp>

namespace vista {

constexpr const char* kGeoProjection = "tmerc";  // the one projection (name stored with the city)
constexpr double kGeoMaxLocal_m = 4.0e6;         // localToGeo() domain: |x|, |y| up to this

struct GeoPoint {
    double lat_deg = 0.0;  // -90 .. 90, north positive
    double lon_deg = 0.0;  // east positive
};

// The reference point of a city frame: (0,0) of the frame.
struct GeoReference {
    double lat0_deg = 0.0;  // -90 .. 90
    double lon0_deg = 0.0;  // -180 .. 180
};

glm::dvec2 projectToLocal(const GeoReference& ref, const GeoPoint& p);
GeoPoint localToGeo(const GeoReference& ref, const glm::dvec2& xy);

}  // namespace vista
