// Transverse Mercator on the WGS84 ellipsoid after Karney, "Transverse
// Mercator with an accuracy of a few nanometers", J. Geodesy 85 (2011):
// conformal latitude via tau' (no loss of precision near the poles), the
// Krueger alpha/beta series to n^6, and a Newton inversion of tau'(tau).
#include "citygen/geodesy.h"

#include <cmath>
#include <limits>

#include "foundation/status.h"
#include "foundation/units.h"

namespace vista {

namespace {

constexpr double kA = 6378137.0;
constexpr double kF = 1.0 / 298.257223563;

struct TmConstants {
    double e = 0, e2m = 0;            // eccentricity, 1 - e^2
    double a1 = 0;                    // rectifying radius A (scale 1 on the central meridian)
    double alp[7] = {}, bet[7] = {};  // Krueger series, index 1..6

    TmConstants() {
        const double n = kF / (2 - kF), n2 = n * n, n3 = n2 * n, n4 = n3 * n, n5 = n4 * n, n6 = n5 * n;
        const double e2 = kF * (2 - kF);
        e = std::sqrt(e2);
        e2m = 1 - e2;
        a1 = kA / (1 + n) * (1 + n2 / 4 + n4 / 64 + n6 / 256);
        alp[1] = n / 2 - 2 * n2 / 3 + 5 * n3 / 16 + 41 * n4 / 180 - 127 * n5 / 288 + 7891 * n6 / 37800;
        alp[2] = 13 * n2 / 48 - 3 * n3 / 5 + 557 * n4 / 1440 + 281 * n5 / 630 - 1983433 * n6 / 1935360;
        alp[3] = 61 * n3 / 240 - 103 * n4 / 140 + 15061 * n5 / 26880 + 167603 * n6 / 181440;
        alp[4] = 49561 * n4 / 161280 - 179 * n5 / 168 + 6601661 * n6 / 7257600;
        alp[5] = 34729 * n5 / 80640 - 3418889 * n6 / 1995840;
        alp[6] = 212378941 * n6 / 319334400;
        bet[1] = n / 2 - 2 * n2 / 3 + 37 * n3 / 96 - n4 / 360 - 81 * n5 / 512 + 96199 * n6 / 604800;
        bet[2] = n2 / 48 + n3 / 15 - 437 * n4 / 1440 + 46 * n5 / 105 - 1118711 * n6 / 3870720;
        bet[3] = 17 * n3 / 480 - 37 * n4 / 840 - 209 * n5 / 4480 + 5569 * n6 / 90720;
        bet[4] = 4397 * n4 / 161280 - 11 * n5 / 504 - 830251 * n6 / 7257600;
        bet[5] = 4583 * n5 / 161280 - 108847 * n6 / 3991680;
        bet[6] = 20648693 * n6 / 638668800;
    }
};

const TmConstants& tm() {
    static const TmConstants k;
    return k;
}

double eatanhe(double x) { return tm().e * std::atanh(tm().e * x); }

// tan of the conformal latitude from tau = tan(latitude).
double taupf(double tau) {
    const double tau1 = std::hypot(1.0, tau), sig = std::sinh(eatanhe(tau / tau1));
    return std::hypot(1.0, sig) * tau - sig * tau1;
}

// Inverse of taupf (Newton; converges in 2-3 steps).
double tauf(double taup) {
    const double eps = std::numeric_limits<double>::epsilon();
    const double e2m = tm().e2m, tol = std::sqrt(eps) / 10, taumax = 2 / std::sqrt(eps);
    double tau = std::abs(taup) > 70 ? taup * std::exp(eatanhe(1.0)) : taup / e2m;
    if (!(std::abs(tau) < taumax)) return tau;
    const double stol = tol * std::max(1.0, std::abs(taup));
    for (int i = 0; i < 5; ++i) {
        const double taupa = taupf(tau);
        const double dtau =
            (taup - taupa) * (1 + e2m * tau * tau) / (e2m * std::hypot(1.0, tau) * std::hypot(1.0, taupa));
        tau += dtau;
        if (!(std::abs(dtau) >= stol)) break;
    }
    return tau;
}

// (xi', eta') on the conformal sphere <-> (xi, eta) = (northing, easting) / A.
void series(const double* c, double sign, double xi0, double eta0, double& xi, double& eta) {
    xi = xi0;
    eta = eta0;
    for (int j = 1; j <= 6; ++j) {
        xi += sign * c[j] * std::sin(2 * j * xi0) * std::cosh(2 * j * eta0);
        eta += sign * c[j] * std::cos(2 * j * xi0) * std::sinh(2 * j * eta0);
    }
}

// Tangent of a latitude given in degrees; finite at +-90 (cos rounds to ~6e-17, not 0).
double tanLat(double latDeg) {
    const double phi = degToRad(latDeg);
    return std::sin(phi) / std::cos(phi);
}

// Scaled northing xi of a point on the central meridian (the origin latitude).
double xiOfLatitude(double latDeg) {
    double xi = 0, eta = 0;
    series(tm().alp, 1.0, std::atan(taupf(tanLat(latDeg))), 0.0, xi, eta);
    return xi;
}

bool validReference(const GeoReference& r) { return std::abs(r.lat0_deg) <= 90 && std::abs(r.lon0_deg) <= 180; }

}  // namespace

glm::dvec2 projectToLocal(const GeoReference& ref, const GeoPoint& p) {
    VISTA_CHECK(validReference(ref));
    VISTA_CHECK(std::abs(p.lat_deg) <= 90 && std::isfinite(p.lon_deg));
    const double lam = degToRad(std::remainder(p.lon_deg - ref.lon0_deg, 360.0));
    const double taup = taupf(tanLat(p.lat_deg));
    const double xip = std::atan2(taup, std::cos(lam));
    const double etap = std::asinh(std::sin(lam) / std::hypot(taup, std::cos(lam)));
    double xi = 0, eta = 0;
    series(tm().alp, 1.0, xip, etap, xi, eta);
    return {tm().a1 * eta, tm().a1 * (xi - xiOfLatitude(ref.lat0_deg))};
}

GeoPoint localToGeo(const GeoReference& ref, const glm::dvec2& xy) {
    VISTA_CHECK(validReference(ref));
    VISTA_CHECK(std::abs(xy.x) <= kGeoMaxLocal_m && std::abs(xy.y) <= kGeoMaxLocal_m);
    const double xi = xy.y / tm().a1 + xiOfLatitude(ref.lat0_deg), eta = xy.x / tm().a1;
    double xip = 0, etap = 0;
    series(tm().bet, -1.0, xi, eta, xip, etap);
    const double s = std::sinh(etap), c = std::cos(xip), r = std::hypot(s, c);
    GeoPoint out;
    if (r > 0) {
        out.lat_deg = radToDeg(std::atan(tauf(std::sin(xip) / r)));
        out.lon_deg = std::remainder(ref.lon0_deg + radToDeg(std::atan2(s, c)), 360.0);
    } else {  // exactly at a pole
        out.lat_deg = std::sin(xip) >= 0 ? 90.0 : -90.0;
        out.lon_deg = ref.lon0_deg;
    }
    return out;
}

}  // namespace vista
