#!/usr/bin/env bash
# Per-frame cost of rendering through the Python module against `vista render`: the same
# city, path, frames, size and mode, side by side (rgb only, files not counted on either side:
# the command's summary.json median rgb ms against the module's per-frame render time).
#
# ROUNDS (default 5) alternate the two sides; the figure is the median of the rounds' ratios, so
# load that comes and goes hits both sides alike.
#
# usage: docs/tools/python_overhead.sh CITY.osgb [FRAMES=60] [MODE=hybrid] [SIZE=640x480]
# Run on a quiet machine, under xvfb-run -a without a display; build/ holds vista and python/.
# PYTHON (default python3) is the interpreter the module was built for.
set -euo pipefail
cd "$(dirname "$0")/../.."
city=$1 frames=${2:-60} mode=${3:-hybrid} size=${4:-640x480}
BUILD="${VISTA_BUILD_DIR:-build}"
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
PY="${PYTHON:-python3}"
rounds=${ROUNDS:-5}
ratios=()
for round in $(seq "$rounds"); do
rm -rf "$out/cli"
"$BUILD/vista" render "$city" --frames "$frames" --sampling consecutive --size "$size" --mode "$mode" \
  --channels rgb --out "$out/cli" -q
cli_ms=$("$PY" -c "import json,sys; print(json.load(open(sys.argv[1]))['median_ms']['rgb'])" "$out/cli/summary.json")
line=$(PYTHONPATH="$BUILD/python" "$PY" - "$city" "$frames" "$mode" "$size" "$cli_ms" "$out/cli/cameras.json" <<'PY'
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
print(f"{cli_ms:.2f} {py_ms:.2f} {statistics.median(mode_ms):.2f} {py_ms / cli_ms:.4f}")
PY
)
read -r cli py mode_frame ratio <<<"$line"
echo "round $round: vista render median rgb $cli ms, python render() median $py ms (the mode's own frame $mode_frame ms), ratio $ratio"
ratios+=("$ratio")
done
"$PY" - "$frames" "$mode" "$size" "${ratios[@]}" <<'PY'
import statistics, sys
frames, mode, size, ratios = sys.argv[1], sys.argv[2], sys.argv[3], [float(r) for r in sys.argv[4:]]
m = statistics.median(ratios)
print(f"frames {frames}, {mode}, {size}, {len(ratios)} rounds: python/cli median ratio {m:.3f} "
      f"(overhead {100 * (m - 1):+.1f} %; rounds {min(ratios):.3f} .. {max(ratios):.3f})")
PY
