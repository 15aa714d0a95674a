#!/usr/bin/env bash
# Per-frame cost of rendering through the Python module against `vista render`: the same
# city, path, frames, size and mode, side by side (rgb only, files not counted on either side:
# the command's summary.json median rgb ms against the module's per-frame render time).
#
# usage: docs/tools/python_overhead.sh CITY.osgb [FRAMES=60] [MODE=hybrid] [SIZE=640x480]
# Run on a quiet machine, under xvfb-run -a without a display; build/ holds vista and python/.
set -euo pipefail
cd "$(dirname "$0")/../.."
city=$1 frames=${2:-60} mode=${3:-hybrid} size=${4:-640x480}
BUILD="${VISTA_BUILD_DIR:-build}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$BUILD/vista" render "$city" --frames "$frames" --sampling consecutive --size "$size" --mode "$mode" \
  --channels rgb --out "$out/cli" -q
cli_ms=$(python3 -c "import json,sys; print(json.load(open(sys.argv[1]))['median_ms']['rgb'])" "$out/cli/summary.json")
PYTHONPATH="$BUILD/python" python3 - "$city" "$frames" "$mode" "$size" "$cli_ms" "$out/cli/cameras.json" <<'PY'
import json, statistics, sys, time
import vista
city_file, frames, mode, size, cli_ms, cameras = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4], float(sys.argv[5]), sys.argv[6]
w, h = (int(v) for v in size.split("x"))
city = vista.load(city_file)
path = vista.path(city)
r = vista.Renderer(city, mode=mode, size=(w, h), channels=["rgb"])
mode_ms, call_ms = [], []
for f in json.load(open(cameras))["frames"]:
    t0 = time.perf_counter()
    got = r.render(path[f["path_index"]])
    call_ms.append(1000 * (time.perf_counter() - t0))
    mode_ms.append(got["frame_ms"])
py_ms = statistics.median(call_ms)
print(f"frames {frames}, {mode}, {w}x{h}")
print(f"vista render  median rgb ms        {cli_ms:8.2f}")
print(f"python        median render() ms   {py_ms:8.2f}  (the mode's own frame: {statistics.median(mode_ms):.2f})")
print(f"overhead      {100 * (py_ms / cli_ms - 1):+.1f} %")
PY
