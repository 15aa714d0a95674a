// vista's release version, MAJOR.MINOR.PATCH.
//
// Contract: the text is the VERSION of the top-level CMake project() (the one
// source of the version number): `vista --version`, the Python module's
// __version__, the Debian package and the CMake package all report it.
// A static string; thread-safe.
#pragma once

namespace vista {

// The version as "MAJOR.MINOR.PATCH" (e.g. "0.6.0").
const char* version();

}  // namespace vista
