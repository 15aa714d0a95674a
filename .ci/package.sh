#!/usr/bin/env bash
# Packaging check, after the build and the tests (reuses the build directory):
#  1. `cmake --install` into a fresh prefix; examples/consumer, a standalone
#     CMake project, finds vista there (find_package(vista CONFIG)), builds
#     and runs (it exits non-zero when its rays hit nothing);
#  2. `cpack -G DEB`; the .deb's contents and Depends are checked, it is
#     unpacked with dpkg-deb -x into a clean directory, the consumer is built
#     against that tree, and the packaged `vista gen` writes a tiny city with
#     the packaged osgDB plugin on OSG's plugin path, and the packaged Python
#     module imports and generates a city.
# Nothing is installed on the machine; everything goes to a temporary directory.
# With VISTA_CI_DEB_DIR set (an existing directory; .ci/run sets it) the .deb is
# also copied there, and .ci/release.sh checks that one instead of packaging the
# same build a second time.
set -euo pipefail
cd "$(dirname "$0")/.."
SRC="$(pwd)"
BUILD="$(cd "${VISTA_BUILD_DIR:-build}" && pwd)"
WORK="$(mktemp -d "${TMPDIR:-/tmp}/vista-package.XXXXXX")"
if [ -z "${VISTA_CI_KEEP:-}" ]; then trap 'rm -rf "$WORK"' EXIT; else echo "package: keeping $WORK"; fi
GEN=(); command -v ninja >/dev/null && GEN=(-G Ninja)

step() { echo "package: $* (${SECONDS} s)"; }
fail() { echo "package: FAILED: $*" >&2; exit 1; }

# consumer NAME PREFIX: configure, build and run examples/consumer against PREFIX only.
consumer() {
  local dir="$WORK/$1" prefix="$2"
  cmake -S "$SRC/examples/consumer" -B "$dir" "${GEN[@]}" -DCMAKE_BUILD_TYPE=Release \
    -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_FIND_USE_PACKAGE_REGISTRY=OFF >"$dir.configure.log" 2>&1 \
    || { cat "$dir.configure.log"; fail "configuring the consumer against $prefix"; }
  local found
  found="$(sed -n 's/^vista_DIR:PATH=//p' "$dir/CMakeCache.txt")"
  case "$found" in "$prefix"/*) ;; *) fail "the consumer found vista in '$found', not under $prefix" ;; esac
  cmake --build "$dir" -j"$(nproc)" || fail "building the consumer against $prefix"
  "$dir/vista_consumer" 300 || fail "running the consumer built against $prefix"
}

step "cmake --install into a fresh prefix"
cmake --install "$BUILD" --prefix "$WORK/prefix" >/dev/null
consumer consumer-install "$WORK/prefix"

step "cpack -G DEB"
(cd "$BUILD" && cpack -G DEB -B "$WORK/deb" >/dev/null) || fail "cpack -G DEB"
debs=("$WORK"/deb/vista_*.deb)
[ "${#debs[@]}" -eq 1 ] && [ -f "${debs[0]}" ] || fail "expected one vista_*.deb in $WORK/deb"
DEB="${debs[0]}"
if [ -n "${VISTA_CI_DEB_DIR:-}" ]; then cp "$DEB" "$VISTA_CI_DEB_DIR/" || fail "copying the .deb to VISTA_CI_DEB_DIR"; fi
dpkg-deb -f "$DEB" Package Version Architecture Depends
depends="$(dpkg-deb -f "$DEB" Depends)"
for p in libopenscenegraph-dev libembree-dev libtbb-dev libcgal-dev libc6; do
  case ", $depends," in *", $p"[,\ ]*) ;; *) fail "Depends lacks $p" ;; esac
done
contents="$(dpkg-deb -c "$DEB")"
osgver="$(sed -n 's/^OPENSCENEGRAPH_VERSION:INTERNAL=//p' "$BUILD/CMakeCache.txt")"
for f in ./usr/bin/vista "osgPlugins-$osgver/osgdb_vista.so" /cmake/vista/vistaConfig.cmake \
         /cmake/vista/vistaConfigVersion.cmake /cmake/vista/vistaTargets.cmake ./usr/include/vista/citygen/generate.h \
         ./usr/include/vista/runtime/engine/ray_scene.h libvista_citygen.a libvista_engine.a; do
  grep -qF -- "$f" <<<"$contents" || fail "the .deb lacks $f"
done

step "dpkg-deb -x into a clean directory"
ROOT="$WORK/root"
dpkg-deb -x "$DEB" "$ROOT"
consumer consumer-deb "$ROOT/usr"

step "the packaged vista gen"
plugin="$(cd "$ROOT" && find . -path "*/osgPlugins-$osgver/osgdb_vista.so" | head -n1)"
[ -n "$plugin" ] || fail "no osgdb_vista.so in the unpacked .deb"
plugin_dir="$ROOT/$(dirname "$(dirname "$plugin")")"
if ldd "$ROOT/$plugin" | grep -q 'not found'; then ldd "$ROOT/$plugin"; fail "the packaged plugin misses libraries"; fi
OSG_LIBRARY_PATH="$plugin_dir" "$ROOT/usr/bin/vista" gen --size 300 --seed 3 -o "$WORK/city.osgb" --quiet \
  || fail "the packaged vista gen"
[ -s "$WORK/city.osgb" ] || fail "the packaged vista gen wrote no $WORK/city.osgb"
step "the packaged Python module"
pydir="$(cd "$ROOT" && find . -path "*/dist-packages/vista/__init__.py" | head -n1)"
[ -n "$pydir" ] || fail "no Python package vista in the unpacked .deb"
PYTHONPATH="$ROOT/$(dirname "$(dirname "$pydir")")" OSG_LIBRARY_PATH="$plugin_dir" /usr/bin/python3 -c '
import vista
city = vista.generate(seed=3, size_m=300)
edges = len(city.streets["edges"])
assert edges > 0, "no street edges"
print("package: the packaged module generated a city of", edges, "street edges")
' || fail "importing the packaged Python module and generating a city"
step "ok: $(basename "$DEB") ($(du -h "$DEB" | cut -f1)), city.osgb $(du -h "$WORK/city.osgb" | cut -f1)"
