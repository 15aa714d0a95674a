// Units and constants: metres, seconds and radians inside vista; degrees only
// at the user interface (command-line values, CSV and JSON files for people).
// Every conversion goes through these functions; pi is defined once, here.
#pragma once

namespace vista {

constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kHalfPi = 0.5 * kPi;

constexpr double degToRad(double deg) { return deg * (kPi / 180.0); }
constexpr double radToDeg(double rad) { return rad * (180.0 / kPi); }

// Wraps an angle (radians) into [-pi, pi].
inline double wrapAngle(double a) {
    while (a > kPi) a -= kTwoPi;
    while (a < -kPi) a += kTwoPi;
    return a;
}

}  // namespace vista
