#!/usr/bin/env bash
# Release artefacts and their checks, after the build (reuses the build directory):
#  1. the version: CMake's project VERSION (the one source) is what the built
#     `vista --version` prints and CHANGELOG.md's newest version heading;
#  2. the Debian package (`cpack -G DEB`): dpkg-deb -I gives Package vista and
#     Version VERSION, dpkg-deb -c lists the tool, the plugin, the CMake
#     package and the Python module; unpacked into a temporary root
#     (dpkg-deb -x), its `vista --version` prints VERSION, its plugin finds
#     every library, and its Python module's vista.__version__ is VERSION;
#  3. the source archive (`git archive` of HEAD, top folder vista-VERSION/):
#     it holds exactly the files git tracks at HEAD, and the unpacked tree
#     configures with CMake on its own. With VISTA_RELEASE_BUILD=1 the
#     unpacked tree is also built (the `vista` target) and its
#     `vista --version` checked; that takes about as long as the project's own
#     build, so CI configures only.
#
# usage: .ci/release.sh [OUT]
#   OUT  a new (or empty) directory that receives vista_VERSION_ARCH.deb,
#        vista-VERSION.tar.gz and SHA256SUMS; without it the artefacts are
#        checked in a temporary directory and removed (what CI runs).
# Environment: VISTA_BUILD_DIR (default build), VISTA_RELEASE_BUILD=1 (see 3),
# VISTA_CI_DEB_DIR (a directory holding the one .deb that .ci/package.sh made
# from this build, newer than its `vista`: checked instead of running cpack again).
# Exit codes: 0 all checks passed, 1 a check failed, 2 bad usage (OUT not
# empty, not a git checkout, no build). Nothing is installed on the machine and
# nothing is left in OUT when a check fails.
set -euo pipefail
cd "$(dirname "$0")/.."
SRC="$(pwd)"

step() { echo "release: $* (${SECONDS} s)"; }
fail() { echo "release: FAILED: $*" >&2; exit 1; }
usage_error() { echo "release: error: $*" >&2; exit 2; }

[ $# -le 1 ] || usage_error "usage: .ci/release.sh [OUT] (OUT: a new or empty directory for the artefacts)"
OUT_ARG="${1:-}"
BUILD_ARG="${VISTA_BUILD_DIR:-build}"
[ -x "$BUILD_ARG/vista" ] || usage_error "VISTA_BUILD_DIR: no built vista in '$BUILD_ARG' (run .ci/setup.sh or build the vista target first)"
BUILD="$(cd "$BUILD_ARG" && pwd)"
git -C "$SRC" rev-parse --verify -q HEAD >/dev/null || usage_error "$SRC is not a git checkout with a commit (the source archive is git archive HEAD)"
if [ -n "$OUT_ARG" ]; then
  if [ -e "$OUT_ARG" ] && { [ ! -d "$OUT_ARG" ] || [ -n "$(ls -A "$OUT_ARG")" ]; }; then
    usage_error "OUT '$OUT_ARG' exists and is not an empty directory (the release never overwrites files)"
  fi
fi

WORK="$(mktemp -d "${TMPDIR:-/tmp}/vista-release.XXXXXX")"
if [ -z "${VISTA_CI_KEEP:-}" ]; then trap 'rm -rf "$WORK"' EXIT; else echo "release: keeping $WORK"; fi

step "the version"
VERSION="$(sed -n 's/^[[:space:]]*project([[:space:]]*vista[[:space:]].*VERSION[[:space:]]\+\([0-9]\+\.[0-9]\+\.[0-9]\+\).*/\1/p' CMakeLists.txt | head -n1)"
[ -n "$VERSION" ] || fail "CMakeLists.txt: no project(vista VERSION MAJOR.MINOR.PATCH)"
cached="$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$BUILD/CMakeCache.txt")"
[ "$cached" = "$VERSION" ] || fail "the build in $BUILD was configured for version '$cached', the source says $VERSION (re-run cmake)"
built="$("$BUILD/vista" --version)"
[ "$built" = "vista $VERSION" ] || fail "the built vista --version prints '$built', expected 'vista $VERSION'"
newest="$(sed -n 's/^## \([0-9]\+\.[0-9]\+\.[0-9]\+\)\( .*\)\?$/\1/p' CHANGELOG.md | head -n1)"
[ "$newest" = "$VERSION" ] || fail "CHANGELOG.md's newest version heading is '$newest', expected $VERSION"
echo "release: version $VERSION"

made=()
[ -n "${VISTA_CI_DEB_DIR:-}" ] && made=("$VISTA_CI_DEB_DIR"/vista_*.deb)
if [ "${#made[@]}" -eq 1 ] && [ -f "${made[0]}" ] && [ "${made[0]}" -nt "$BUILD/vista" ]; then
  step "the Debian package (.ci/package.sh's cpack -G DEB of this build)"
  mkdir -p "$WORK/deb"
  cp "${made[0]}" "$WORK/deb/"
else
  step "the Debian package (cpack -G DEB)"
  (cd "$BUILD" && cpack -G DEB -B "$WORK/deb" >"$WORK/cpack.log" 2>&1) || { cat "$WORK/cpack.log"; fail "cpack -G DEB"; }
fi
debs=("$WORK"/deb/vista_*.deb)
[ "${#debs[@]}" -eq 1 ] && [ -f "${debs[0]}" ] || fail "expected one vista_*.deb in $WORK/deb"
DEB="${debs[0]}"
[ "$(basename "$DEB")" = "vista_${VERSION}_$(dpkg --print-architecture).deb" ] \
  || fail "the .deb is named $(basename "$DEB"), expected vista_${VERSION}_$(dpkg --print-architecture).deb"
dpkg-deb -I "$DEB" >"$WORK/deb-info.txt" || fail "dpkg-deb -I cannot read $(basename "$DEB")"
[ "$(dpkg-deb -f "$DEB" Package)" = vista ] || fail "the .deb's Package is not vista"
[ "$(dpkg-deb -f "$DEB" Version)" = "$VERSION" ] || fail "the .deb's Version is '$(dpkg-deb -f "$DEB" Version)', expected $VERSION"
contents="$(dpkg-deb -c "$DEB")"
for f in ./usr/bin/vista osgdb_vista.so /cmake/vista/vistaConfigVersion.cmake; do
  grep -qF -- "$f" <<<"$contents" || fail "the .deb lacks $f"
done

step "the .deb unpacked into a temporary root"
ROOT="$WORK/root"
dpkg-deb -x "$DEB" "$ROOT"
unpacked="$("$ROOT/usr/bin/vista" --version)" || fail "the unpacked vista does not run"
[ "$unpacked" = "vista $VERSION" ] || fail "the unpacked vista --version prints '$unpacked', expected 'vista $VERSION'"
plugin="$(cd "$ROOT" && find . -name osgdb_vista.so | head -n1)"
[ -n "$plugin" ] || fail "no osgdb_vista.so in the unpacked .deb"
if ldd "$ROOT/$plugin" | grep -q 'not found'; then ldd "$ROOT/$plugin"; fail "the packaged plugin misses libraries"; fi
cfgver="$(cd "$ROOT" && find . -name vistaConfigVersion.cmake | head -n1)"
grep -q "^set(PACKAGE_VERSION \"$VERSION\")" "$ROOT/$cfgver" || fail "the packaged vistaConfigVersion.cmake does not say $VERSION"
pyinit="$(cd "$ROOT" && find . -path "*/dist-packages/vista/__init__.py" | head -n1)"
if [ -n "$pyinit" ]; then
  pyver="$(PYTHONPATH="$ROOT/$(dirname "$(dirname "$pyinit")")" /usr/bin/python3 -c 'import vista; print(vista.__version__)')" \
    || fail "the packaged Python module does not import"
  [ "$pyver" = "$VERSION" ] || fail "the packaged Python module's __version__ is '$pyver', expected $VERSION"
  echo "release: the unpacked vista --version and the packaged Python module say $VERSION"
elif [ -e "$BUILD/python/vista/__init__.py" ]; then
  fail "the build has the Python module but the .deb does not"
fi

step "the source archive (git archive HEAD)"
TARBALL="$WORK/vista-$VERSION.tar.gz"
git -C "$SRC" archive --format=tar.gz --prefix="vista-$VERSION/" -o "$TARBALL" HEAD
git -C "$SRC" ls-tree -r --name-only HEAD | LC_ALL=C sort >"$WORK/tracked.txt"
tar -tzf "$TARBALL" | grep -v '/$' | sed "s|^vista-$VERSION/||" | LC_ALL=C sort >"$WORK/archived.txt"
if ! cmp -s "$WORK/tracked.txt" "$WORK/archived.txt"; then
  diff "$WORK/tracked.txt" "$WORK/archived.txt" | head -n 20
  fail "the source archive's files differ from the files git tracks at HEAD (< tracked only, > archived only)"
fi
if [ -n "$(git -C "$SRC" status --porcelain --untracked-files=no)" ]; then
  echo "release: note: the worktree has uncommitted changes; the archive holds HEAD without them"
fi
echo "release: the archive holds the $(wc -l <"$WORK/tracked.txt") files git tracks at HEAD"
tar -xzf "$TARBALL" -C "$WORK"
GEN=(); command -v ninja >/dev/null && GEN=(-G Ninja)
cmake -S "$WORK/vista-$VERSION" -B "$WORK/src-build" "${GEN[@]}" -DCMAKE_BUILD_TYPE=Release \
  -DPython3_EXECUTABLE=/usr/bin/python3 >"$WORK/src-configure.log" 2>&1 \
  || { tail -n 40 "$WORK/src-configure.log"; fail "the unpacked source archive does not configure"; }
srcver="$(sed -n 's/^CMAKE_PROJECT_VERSION:STATIC=//p' "$WORK/src-build/CMakeCache.txt")"
[ "$srcver" = "$VERSION" ] || fail "the source archive configures as version '$srcver', expected $VERSION"
if [ "${VISTA_RELEASE_BUILD:-0}" = 1 ]; then
  step "building the unpacked source archive (vista target)"
  cmake --build "$WORK/src-build" --target vista -j"$(nproc)" >"$WORK/src-build.log" 2>&1 \
    || { tail -n 40 "$WORK/src-build.log"; fail "the unpacked source archive does not build"; }
  [ "$("$WORK/src-build/vista" --version)" = "vista $VERSION" ] || fail "the source archive's vista --version is not $VERSION"
else
  echo "release: the source archive configures (set VISTA_RELEASE_BUILD=1 to build it too)"
fi

if [ -n "$OUT_ARG" ]; then
  mkdir -p "$WORK/out"
  cp "$DEB" "$TARBALL" "$WORK/out/"
  (cd "$WORK/out" && sha256sum -- * >SHA256SUMS)
  mkdir -p "$OUT_ARG"
  mv "$WORK/out/"* "$OUT_ARG/"
  step "ok: $(cd "$OUT_ARG" && pwd): $(basename "$DEB"), vista-$VERSION.tar.gz, SHA256SUMS"
else
  step "ok: $(basename "$DEB") ($(du -h "$DEB" | cut -f1)), vista-$VERSION.tar.gz ($(du -h "$TARBALL" | cut -f1)) checked"
fi
