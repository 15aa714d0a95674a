#!/usr/bin/env bash
# Regenerates the table "Sensor rigs" in docs/measurements/ground-truth.md: `vista render --rig`
# with 1, 4 and 6 pinhole cameras (640x480, every channel: rgb, depth, semantic, instance, flow,
# boxes) plus one 64-beam x 2048-column LiDAR, on the 2 km city (data/default.json) and an 8 km
# city of the same params, and the shipped example rig (data/rigs/car_4cam_lidar64.json: 2
# pinholes + 2 fisheyes, every channel, the same LiDAR) on the 2 km city, along a car path
# (seed 3, 12 frames spread over it, so every sensor fires on every frame: the table says how
# many fired per frame). Per sensor kind: the median ms per firing (ray casting, boxes and
# writing its files); the boxes share of a camera firing (its boxes stage over the whole firing:
# per camera the median over its firings, the largest of the cameras); the LiDAR's cast alone
# (summary.json stage_median_ms.cast: the sweep's rays and labels, without writing its files or
# its sightings) next to its whole firing; the rig frames per second (frames / the sum of the
# frames' wall times).
#
# usage: docs/tools/rig_table.sh [OUT_DIR] [VISTA_BIN]
# Needs python3. About 15 minutes on 2 cores (the 8 km city's generation included).
set -euo pipefail
source "$(dirname "$0")/lib.sh"
doc_setup rig_table.sh rig-table 1280x1024x24 "$@"
DOC=docs/measurements/ground-truth.md
mkdir -p "$OUT"
# The rigs: cameras around the car (yaw 0, 180, +-60, +-120 degrees), the example rig's LiDAR.
for n in 1 4 6; do
  python3 - "$n" "$OUT/rig$n.json" <<'PY'
import json, sys
n, out = int(sys.argv[1]), sys.argv[2]
lidar = [s for s in json.load(open("data/rigs/car_4cam_lidar64.json"))["sensors"] if s["type"] == "lidar"]
yaws = [0, 180, 60, -60, 120, -120][:n]
cams = [{"name": f"cam{i}", "type": "pinhole", "pose": {"x": 0.3, "y": 0.0, "z": 0.45, "yaw_deg": y},
         "rate_hz": 10, "intrinsics": {"width": 640, "height": 480, "fx": 500, "fy": 500, "cx": 319.5, "cy": 239.5},
         "channels": ["rgb", "depth", "semantic", "instance", "flow", "boxes"]} for i, y in enumerate(yaws)]
json.dump({"sensors": cams + lidar}, open(out, "w"), indent=1)
PY
done
ROWS=()
for size in 2000 8000; do
  city="$OUT/city$size.osgb"
  [ -s "$city" ] || { log "generating the ${size} m city"; "$VISTA" gen --params data/default.json --size "$size" -o "$city" -q; }
  for n in 1 4 6; do
    log "${size} m city: $n cameras + LiDAR"
    rm -rf "$OUT/r${size}_$n"
    "$VISTA" render "$city" --seed 3 --kind car --frames 12 --sampling spread --rig "$OUT/rig$n.json" \
      --out "$OUT/r${size}_$n" -q >/dev/null
    ROWS+=("$size|$n|$OUT/r${size}_$n/summary.json")
  done
done
log "2000 m city: the shipped rig (data/rigs/car_4cam_lidar64.json)"
rm -rf "$OUT/r2000_shipped"
"$VISTA" render "$OUT/city2000.osgb" --seed 3 --kind car --frames 12 --sampling spread \
  --rig data/rigs/car_4cam_lidar64.json --out "$OUT/r2000_shipped" -q >/dev/null
ROWS+=("2000|2 + 2 fisheye (shipped rig)|$OUT/r2000_shipped/summary.json")
python3 - "${ROWS[@]}" > "$OUT/table.md" <<'PY'
import json, statistics, sys
print("| city | cameras | sensors fired per frame | camera ms per firing, median | boxes share of a camera firing (median per camera, the largest) | LiDAR ms per sweep, median | LiDAR cast ms per sweep, median | LiDAR points per sweep | rig frames per second |")
print("|---|---|---|---|---|---|---|---|---|")
for row in sys.argv[1:]:
    size, n, path = row.split("|")
    j = json.load(open(path))
    cam_names = [k for k, v in j["sensors"].items() if "points" not in v]
    cams = [j["sensors"][k]["median_ms"] for k in cam_names]
    lidar = [v for k, v in j["sensors"].items() if "points" in v][0]
    shares = [j["sensors"][k]["boxes_share_median"] for k in cam_names if j["sensors"][k].get("boxes_share_median") is not None]
    share = f"{100 * max(shares):.0f} %" if shares else "-"
    print(f"| {int(size) // 1000} km | {n} | {j['sensors_fired_per_frame']:.0f} | {statistics.median(cams):.1f} | {share} | "
          f"{lidar['median_ms']:.1f} | {lidar['stage_median_ms']['cast']:.1f} | {lidar['points'] / lidar['firings']:.0f} | "
          f"{j['rig_frames_per_second']:.2f} |")
PY
cat "$OUT/table.md"
DOC_TMP_FILES=("$(dirname "$DOC")/.$(basename "$DOC").tmp")
doc_replace_block "$DOC" rig-table "$OUT/table.md"
log "wrote $DOC"
