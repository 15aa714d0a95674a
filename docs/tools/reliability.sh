#!/usr/bin/env bash
# Regenerates docs/measurements/reliability.md: the regression tests of every finding, the
# fuzz targets' executions and findings (.ci/fuzz.sh), the sanitizer run of the
# test suite (.ci/sanitize.sh), the fault-injection sweep (docs/tools/fault_sweep.sh)
# and the soak memory curve.
#   usage: docs/tools/reliability.sh [FUZZ_SECONDS=600] [SOAK_FRAMES=100000]
# (run from the repository root; needs the normal build in build/ and an X
# display or xvfb-run; the full run takes about 2 hours on 2 cores: 7 fuzz
# targets x FUZZ_SECONDS, a sanitizer build and test run, the fault sweep, the soak).
# Reuse results of a step run separately (the doc says which were reused):
#   FUZZ_TSV=summary.tsv (from .ci/fuzz.sh), SANITIZE_LOG=log (of .ci/sanitize.sh), RACE_TSV=race.tsv
#   (of docs/tools/race_trials.sh),
#   FAULT_TSV=tsv (of fault_sweep.sh --tsv), SOAK_CSV=csv (of soak).
set -euo pipefail
cd "$(dirname "$0")/../.."
FUZZ_SECONDS="${1:-600}"
SOAK_FRAMES="${2:-100000}"
OUT="$(mktemp -d)"
trap 'rm -rf "$OUT"' EXIT
XVFB=(xvfb-run -a -s "-screen 0 1280x1024x24")
[ -n "${DISPLAY:-}" ] && XVFB=()

echo "== regression tests of the findings" >&2
"${XVFB[@]}" ctest --test-dir build -R 'Hostile|Huge|BadInput|Kill|Stale|OutputBatch|Malformed|BadScene|BadEffects|Unwritable|Osm|Geodesy|Params|Paths|CellResult|Damaged|Corrupt|Faults|LookingOut|KeepsTheReaderBusy|FaultSweep|CreatedDirectories|MemoryBudget|Netconvert|OutputRule|BoundedReads|NumbersAsWritten|NumberText|InputFile|OutputPaths|EffectsOption|BakedFlags|OsmLargerThanTheCity|Options.EffectsOptionRules|Options.SeedOptionNeverWraps|OsmRoadTags.GraphJson|ValuesCli|PagedManifest|FocalLengths|SpecialOutputs|OutputPlaces|OutputLocks|ResolvedPaths|PagedStream\.|TheManifestsGeneration|CarriesTheManifestsGeneration|AResumeRendersDamagedFramesAgain|CannotHoldTheRegionsAtTheCamera' \
  --output-on-failure -j2 > "$OUT/regression.txt" 2>&1 || true

if [ -n "${FUZZ_TSV:-}" ]; then
  cp "$FUZZ_TSV" "$OUT/fuzz.tsv"
else
  echo "== fuzzing, $FUZZ_SECONDS s per target" >&2
  FUZZ_SECONDS="$FUZZ_SECONDS" FUZZ_OUT="$OUT/fuzz" ./.ci/fuzz.sh > "$OUT/fuzz.txt" 2>&1 || true
  cp "$OUT/fuzz/summary.tsv" "$OUT/fuzz.tsv" 2>/dev/null || printf "target\tseconds\texecutions\tcorpus\tresult\n" > "$OUT/fuzz.tsv"
fi

if [ -n "${SANITIZE_LOG:-}" ]; then
  cp "$SANITIZE_LOG" "$OUT/sanitize.txt"
else
  echo "== sanitizer build and test suite" >&2
  ./.ci/sanitize.sh > "$OUT/sanitize.txt" 2>&1 || true
fi

if [ -n "${FAULT_TSV:-}" ]; then
  cp "$FAULT_TSV" "$OUT/faults.tsv"
else
  echo "== fault sweep: every write of every command fails once" >&2
  docs/tools/fault_sweep.sh --tsv "$OUT/faults.tsv" > "$OUT/faults.txt" 2>&1 || true
fi

if [ -n "${RACE_TSV:-}" ]; then
  cp "$RACE_TSV" "$OUT/race.tsv"
else
  echo "== two writers racing on one output, 50 trials per command" >&2
  docs/tools/race_trials.sh 50 build/vista > "$OUT/race.tsv" 2>"$OUT/race.txt" || true
fi

if [ -n "${SOAK_CSV:-}" ]; then
  cp "$SOAK_CSV" "$OUT/soak.csv"
else
  echo "== soak: $SOAK_FRAMES hybrid frames at 64x48" >&2
  build/vista gen --params data/default.json -q -o "$OUT/soak.osgb"
  "${XVFB[@]}" build/tests/bench/soak "$OUT/soak.osgb" "$SOAK_FRAMES" 64x48 > "$OUT/soak.csv"
fi

python3 - "$OUT" "$FUZZ_SECONDS" "$SOAK_FRAMES" "${FUZZ_TSV:+fuzz }${SANITIZE_LOG:+sanitizer }${FAULT_TSV:+fault-sweep }${SOAK_CSV:+soak}" > docs/measurements/reliability.md.tmp <<'PY'
import csv, os, re, sys, datetime, subprocess
out, fuzz_s, soak_n, reused = sys.argv[1], sys.argv[2], sys.argv[3], sys.argv[4].split()
def read(n):
    p = os.path.join(out, n)
    return open(p, errors="replace").read() if os.path.exists(p) else ""
def tests_summary(text):
    m = re.search(r"(\d+)% tests passed, (\d+) tests failed out of (\d+)", text)
    return (int(m.group(3)) - int(m.group(2)), int(m.group(3))) if m else (0, 0)
print("# Reliability: fuzzing, sanitizers, faults, soak")
print()
print("Regenerate with `docs/tools/reliability.sh [FUZZ_SECONDS] [SOAK_FRAMES]` (this run: "
      f"up to {fuzz_s} s per fuzz target (FUZZ_RUNS stops a target earlier), {soak_n} soak frames; 2 cores, no GPU, Mesa llvmpipe)."
      + (f" Results of the {', '.join(reused)} step(s) were run separately and passed in (FUZZ_TSV / SANITIZE_LOG / FAULT_TSV / SOAK_CSV)." if reused else ""))
print()
print("## Findings and their regression tests")
print()
print("| input | fault found | behaviour | regression test |")
print("|---|---|---|---|")
rows = [
 ("params JSON", "`1e999` or a 400-digit number aborted (uncaught exception)", "exit 2: 'number overflow ... (numbers must fit a double)'", "Params.HostileJsonIsRefusedCleanlyAndTheFullSeedRangeAccepted"),
 ("params JSON", "deep nesting overflowed the stack", "exit 2: 'JSON nested deeper than 16 levels' (line:col), before parsing", "same"),
 ("params JSON", "`seed` 18446744073709551615 (in range) rejected", "accepted (0 .. 2^64-1)", "same"),
 ("params JSON", "duplicate keys accepted silently", "exit 2: 'key ... appears twice in one object' (any depth, effects too)", "same"),
 ("path CSV", "coordinates ~1e20 hit an Embree assertion", "exit 2: field and range named (|x|,|y| <= 2e7 m, |z| <= 1e5 m, |heading| <= 36000 deg, |t| <= 1e9 s)", "Paths.BadInput"),
 ("outputs", "`gen -o c.osgb --stats c.osgb` left the stats JSON as the city; `--geojson c.osgb` left GeoJSON in it; `-o c.osgb --geojson x.glb --gltf x.glb` wrote both; `bake c.osgb -o c.osgb` and `path c.osgb -o c.osgb` replaced their input; `bake -o b.osgb --stats b.osgb`", "one rule in one place for every command: two outputs that are one file, or an output that is an input (after symlinks, `..`, hard links), exit 2 naming both options, before anything is read; gen, bake and path commit all outputs or none", "OutputRule.*, OutputPaths.SameFileAfterDotDotSymlinksAndHardLinks"),
 ("reads", "`gen --params /dev/zero` (4.5 GB in 10 s, never ending), `--params /dev/urandom`, `bench --path /dev/zero` (3 GB in 8 s, and an empty output folder); a directory as `--params` said 'unexpected end of input'", "every reader of a user file has a limit per kind (below) and refuses a device, pipe or directory by name, before any output folder is made", "BoundedReads.DevicesDirectoriesAndOversizedFilesAreRefused, InputFile.DevicesDirectoriesAndOversizedFilesAreRefused, Paths.BadInput"),
 ("numbers", "`--seed -1` and `--seed 18446744073709551616` became 18446744073709551615 (gen, path); seed 2^64 in JSON said 'got 1.8446744073709552e+19'; `1.5abc` in a path CSV said 'expected 6 fields'; a BOM header said 'field 1 not a finite number'; a 1e308 coordinate was printed with 309 digits; a 1 MB key was echoed whole", "one parser for the command line, JSON and CSV: decimal, in range, never wrapped; the message names the field, the range and the text as written (cut to 80 characters); a UTF-8 BOM before a CSV header is skipped", "NumbersAsWritten.SeedsOutsideTheRangeAreRefusedWithTheTextAsWritten, NumberText.*, Params.HostileJsonIsRefusedCleanlyAndTheFullSeedRangeAccepted, Options.SeedOptionNeverWraps, OsmRoadTags.GraphJsonRoundTripsTheFieldsAndRefusesBadValues"),
 ("--effects", "duplicate keys and any nesting accepted; `--effects haze,haze` and `--effects ''` accepted; `bench --effects sun_shadows` ignored without a word", "the parameter file's JSON rules (duplicate keys, 16 levels); an empty value or a repeated name refused; a baked effect asked for at run time refused with exit 2", "EffectsOption.EmptyDuplicateAndDeepValuesAreRefused, Options.EffectsOptionRules"),
 ("bake", "`--cells \"\"` baked every cell; `--cells 45` on a city with edges 0..44 said '0..45'", "an empty list refused; the range printed is the city's", "OutputRule.BakeCommitsTheBakedFileAndItsStatsTogether"),
 ("baked files", "a points bake given as `--baked-mesh` (and a mesh bake as `--baked` for mode impostor) exit 1", "exit 2 naming the flag and the representation, before anything is drawn", "BakedFlags.APointsBakeAsBakedMeshAndAMeshBakeAsBakedAreRefused"),
 ("OSM", "a truncated `.osm.bz2` said 'read failed: -7'; an extract larger than `--size` gave streets outside the city square, and `render` then refused the city's own seeded paths", "libbz2's errors in words ('the bzip2 data ends early (the file is truncated or incomplete)'); roads clipped to the city square, the count on stderr", "OsmImport.TruncatedBzip2IsNamedInWords, OsmImport.RoadsBeyondTheCitySquareAreClipped, OsmLargerThanTheCity.SeededPathsStayInsideTheCitySquare"),
 ("scene file", "a malformed payload with a matching trailer crashed inside OSG's reader", "trust model below; `VISTA_UNTRUSTED_FILES=1` decodes in a child process first", "CityFile.MalformedPayloadWithAValidTrailerIsRefused"),
 ("OSM", "one zigzag way of a few thousand nodes: minutes and > 11 GB", "ways simplified (min segment, 0.5 m Douglas-Peucker); a way crossing itself > 16 times dropped and counted; > 100,000 crossings refused: 5,000 nodes in 0.10 s / 7.8 MB", "OsmImport.LongZigzagWaysAreBounded"),
 ("OSM", "one far node or `lon=\"1e300\"`: a network thousands of km long, exit 0; signed overflow inside libosmium", "coordinates pre-scanned as text and blanked before libosmium parses them; invalid, missing and outlier nodes (> 22.6 km from the median) dropped with a count; extents beyond the largest city (16 km) refused", "OsmImport.InvalidMissingAndOutlierNodesAreDroppedAndCounted, OsmImport.ExtentBeyondTheLargestCityIsRefused, OsmImport.UnsafeXmlIsRefused"),
 ("OSM", "an extract across ±180° became a city spanning the globe", "WGS84 transverse Mercator about the data (equal to PROJ's tmerc to 1 µm), continuous across 180° and at the poles; the geo reference stored in the scene file; lon/lat round trip < 1 cm (about 6 nm)", "OsmImport.ExtractAcrossTheAntimeridianHasItsRealExtent, Geodesy.RoundTripWithinOneCentimetre, Geodesy.ProjectedDistancesMatchVincentyAnywhere"),
 ("faults", "kill -9 left `*.tmp.<pid>` files of 100-340 MB", "the next write of the same output removes temporaries of dead processes", "AtomicFile.StaleTemporariesOfKilledRunsAreRemovedAndLiveOnesKept, GenCli.KillNineKeepsTheOldOutputAndTheNextRunCleansUp"),
 ("faults", "disk full said only 'osgb writer failed'", "the errno text ('No space left on device'; the writer's errno was lost before it was read)", "GenFaults.DiskFullGivesTheCauseAndLeavesTheOldOutputAndNoTemporary, BakeFaults.DiskFullGivesTheCauseAndLeavesNoPartialOutput"),
 ("faults", "`--gltf` failure left .osgb and .geojson written", "all outputs of `vista gen` are staged and renamed together, or none", "AtomicFile.OutputBatchCommitsAllOrNothing, GenCli.KillNine..."),
 ("faults", "`vista path` exited 1 on a write failure", "exit 2 like every user-facing failure", "(code path shared with reportBadInput)"),
 ("faults", "`vista bench` left an empty output folder for a bad scene file", "every `--out` directory this run created is removed when it wrote nothing", "GenCli.BenchOfABadSceneLeavesNoOutputFolder"),
 ("faults", "`vista bake --work` and `vista bench --out` (read-only, or a file) were refused only after the scene was loaded (bench: exit 1)", "refused before the input is read, exit 2, naming the option", "BakeFaults.UnwritableOutputWorkOrStatsIsRefusedBeforeTheInputIsRead, BakeFaults.ReadOnlyDirectoryIsRefusedBeforeTheInputIsRead, BenchFaults.*"),
 ("scene file", "fuzz_scene_file: libFuzzer's comparison tracing forged the 64-bit trailer hash, and a 3.8 KB payload kept OSG's osgb reader busy for 9 s (45 s under ASan)", "untrusted mode (`VISTA_UNTRUSTED_FILES=1`) gives the child decode a time limit (5 s + 1 s per 10 MB, `VISTA_UNTRUSTED_DECODE_SECONDS`); the default target leaves forged trailers to the trusted-trailer mode", "CityFile.PayloadThatKeepsTheReaderBusyIsRefusedInUntrustedMode (the input is tests/data/fuzz_findings/scene_slow_reader.osgb)"),
 ("faults", "horizon stage: a column with nothing in view gave a NaN limit and culled nothing (every sky pixel at a city's edge was traced)", "all sky", "Horizon.LookingOutOfTheCityIsAllSky"),
 ("faults", "a write failing during `vista render` or `vista bench` (disk full): exit 1; bench left its frames and first images behind", "exit 2 with the cause; bench stages every output file and commits them together at the end; render keeps only whole frames in OUT.partial, which the rerun resumes", "Reliability.FaultSweepSample"),
 ("faults", "paged `vista gen` on a full disk left an empty `records/` (and DIR.paged)", "directories a failed run leaves empty are removed; whole regions stay for the rerun", "AtomicFile.CreatedDirectoriesThatStayEmptyAreRemoved, Reliability.FaultSweepSample"),
 ("faults", "a rename failing in the middle of a multi-output commit left the outputs renamed before it replaced; `--stats` of `vista gen` was written after the commit", "the renames before it are undone (each previous output kept as a hard link until the last rename); `--stats` is staged with the other outputs", "AtomicFile.OutputBatchUndoesItsRenamesWhenOneFails, Reliability.FaultSweepSample"),
 ("faults", "`vista bake`: the work directory that could not be created was reported without the cause", "the errno text", "Reliability.FaultSweepSample"),
 ("sanitizers", "the netconvert tests failed under `.ci/sanitize.sh`: the preloaded ASan runtime reported leaks of netconvert's own libproj", "netconvert (not ours, not instrumented) runs without the preloaded runtime (`env -u LD_PRELOAD`)", "OpenDrive.Netconvert*"),
 ("sanitizers", "`GenCli.MemoryBudgetRefusesUpFrontWithNothingWritten` assumed a peak that ASan's shadow memory and quarantine double", "the test states the sanitizer bound (peak up to 4x the estimate under ASan, 2x otherwise)", "GenCli.MemoryBudgetRefusesUpFrontWithNothingWritten"),
 ("values", "`render --rig \"\"` ran a plain render; `path --xodr-positions \"\"` wrote nothing with exit 0", "an option given with an empty value is refused by every command (one check in the option parsing), exit 2 naming it", "ValuesCli.AnOptionGivenEmptyIsRefusedNamingIt"),
 ("values", "`--frames` above the path's sample count repeated frames (5,000 frames from 31 samples, each timestamp 167 times)", "exit 2 naming the sample count unless `--allow-repeated-frames` asks for the repeats (bench, render, view --step)", "ValuesCli.FramesBeyondThePathsSamplesAreRefusedUnlessAsked"),
 ("values", "a path sample far outside the city between two rendered frames bent a LiDAR sweep (662 points instead of about 2,000), exit 0", "every sample of a render's path lies within the city square grown by 50 m, else exit 2 naming the sample (index and time) and the bounds", "ValuesCli.APathSampleOutsideTheCityIsRefusedEvenBetweenFrames"),
 ("values", "`--lht` with walk or fly paths ignored", "exit 2: it applies to car paths made from a seed (not walk, fly or a --path file)", "ValuesCli.LeftHandTrafficIsRefusedWhereNoLaneIsDriven"),
 ("paged manifest", "`bytes: -5` read as 18446744073709551611; `region_size_m` 0 or negative, region 0 listed twice (region 1 dropped) and every region `empty` accepted", "every field the reader uses is checked with its range ([formats](../formats.md) \"Paged city\"), entry i must be region i, no file shared by two regions, at least one non-empty region; exit 2 naming the manifest, the field and the value", "PagedManifest.*"),
 ("rig file", "`fx = 1e-300` passed its range (0, 1e6] and made every depth +inf", "a lower bound derived from the field of view: a pinhole image spans at most 179 degrees, a fisheye's edge lies at most 180 degrees off the axis", "Rig.FocalLengthsHaveAFieldOfViewLowerBound"),
 ("OSM", "`maxspeed=DE:zone99999999999999999999` became 250 km/h; `lanes=1` with `lanes:forward=5` counted as used while the .xodr had 5 lanes; a tag value over libosmium's 1024 bytes said only 'OSM tag value is too long'", "values beyond plausible ranges (5 .. 250 km/h, 8 lanes a direction, 16 in total) fall back to the class default and are counted; the directional lane tags win over a contradicting `lanes` (counted as inconsistent); the long value is refused naming the tag, the way and the line", "OsmRoadTags.ImplausibleAndInconsistentTagsFallBackAndAreCounted, OsmRoadTags.AnOverLongTagValueNamesTheTagAndTheWay"),
 ("messages", "lane positions on an OSM city of one-way streets said 'the path has none' and named `pos.csv.stage.NNNN`", "the reason (no lane network a car can keep driving: one-way dead ends) and the user's file, before anything is staged", "ValuesCli.LanePositionsOfACityWithoutDrivableLanesNameTheReasonAndTheUsersFile"),
 ("exit codes", "no display: `render` and `bench` exited 2 while the CLI reference says 1", "exit 1 before any work, nothing left behind (bad input stays 2; `render --rig` casts rays and needs no display)", "ValuesCli.NoDisplayExitsOneAndLeavesNothing"),
]
for r in rows: print("| " + " | ".join(r) + " |")
ok, n = tests_summary(read("regression.txt"))
print()
print(f"This run of the regression tests (`ctest -R ...` in the script): **{ok} of {n} passed**.")
print()
print("## Files, reads and numbers")
print()
print("One rule for every command's files, checked in one place (foundation/output_paths.h) before anything is read or written: no two outputs of a command are the same file, and no output is one of its inputs. Paths are compared after symlinks, `.` and `..` (the real path of the parent directory plus the name) and, where both exist, by device and inode. A refusal exits with code 2 and names both options. `vista gen` (city, GeoJSON, glTF, OpenDRIVE, stats), `vista bake` (baked file, stats) and `vista path` (CSV, lane positions) stage their outputs and rename them together: all appear, or none.")
print()
race = list(csv.DictReader(read("race.tsv").splitlines(), delimiter="\t"))
if race:
    print("Two writers racing on one output (`docs/tools/race_trials.sh 50`: two seeds started together into one output; right when exactly one exits 0, the other exits 2, and the output is the winner's alone):")
    print()
    print("| command | trials | one winner, its output whole | mixed outputs | other outcomes |")
    print("|---|---|---|---|---|")
    for r in race:
        print(f"| {r['command']} | {r['trials']} | {r['one_winner']} | {r['mixed']} | {r['other']} |")
else:
    print("Two writers racing on one output: **not run** (no docs/tools/race_trials.sh table in this run).")
print()
print("Every reader of a user file reads through foundation/input_file.h, which refuses a directory ('is a directory, expected a file'), a device, pipe or socket ('is not a regular file') and a file above the limit of its kind:")
print()
print("| input | limit |")
print("|---|---|")
print("| parameter file (JSON) | 1 MiB |")
print("| `--effects` value (names or JSON) | 64 KiB |")
print("| walkthrough path (CSV) | 256 MiB |")
print("| paged city manifest.json | 64 MiB |")
print("| ray set (.rays) | 1 GiB |")
print("| OpenStreetMap extract (.osm, .osm.pbf, .osm.bz2) | 8 GiB (decompressed XML: 4 GiB) |")
print("| scene and baked files (.osgb) | a regular file; size checked by the integrity trailer |")
print()
print("Numbers a person writes (command-line values, JSON, CSV) go through one parser (foundation/number_text.h): integers are decimal digits with a '-' only where the range has negatives, no hex, fraction or exponent, and never wrap or saturate; reals are decimal and finite; a value out of range is refused with the range and the text as written. JSON integers are parsed from their text, so 2^64 is out of range rather than a double near 1.8e19. Text echoed in a message is cut to 80 characters.")
print()
print("## Fuzzing (libFuzzer, ASan + UBSan)")
print()
print("Targets in tests/fuzz (`-DVISTA_FUZZ=ON`, Clang), seed corpora in tests/fuzz/corpus/<target>/, run by "
      "`.ci/fuzz.sh` (`FUZZ_SECONDS` per target, or `FUZZ_RUNS` executions with FUZZ_SECONDS as a cap; seconds = the "
      "time it took). A crash, a sanitizer report or a broken round-trip fails the target. `.ci/run` runs every target "
      "for 15 s on each CI run.")
print()
print("| target | input | seconds | executions | corpus after | result |")
print("|---|---|---|---|---|---|")
what = {"fuzz_params": "parameter file JSON (with effects)", "fuzz_street_graph": "street graph JSON in scene files",
        "fuzz_osm": "OSM XML extract", "fuzz_path_csv": "walkthrough path CSV", "fuzz_scene_file": "scene file (.osgb + trailer)",
        "fuzz_cell_result": "bake work-directory cell result", "fuzz_baked_file": "baked scene file",
        "fuzz_ray_set": "ray-set file (bench_raw_rays)"}
for row in csv.DictReader(read("fuzz.tsv").splitlines(), delimiter="\t"):
    print(f"| {row['target']} | {what.get(row['target'], '')} | {row['seconds']} | {int(row['executions'] or 0):,} | {row['corpus']} | {row['result']} |")
print()
print("## Sanitizers")
print()
ok, n = tests_summary(read("sanitize.txt"))
result = f"**{ok} of {n} tests passed**" if n else "**did not run to completion in this run** (no ctest summary in its log)"
print(f"`.ci/sanitize.sh` (GCC, `-fsanitize=address,undefined -fno-sanitize-recover=all`, leak detection on): "
      f"{result}. Suppressions (tests/sanitizers/): UBSan `vptr` inside CGAL's Arrangement_2 "
      "(header-only system library; its handle casts are by design); LSan: process-lifetime singletons of "
      "OpenSceneGraph, Mesa/LLVM, X11, fontconfig. Each with its reason in the file. Programs that are not ours "
      "(netconvert) run without the preloaded runtime (`env -u LD_PRELOAD`): its leak checker would report their "
      "libraries' allocations. Tests whose figures ASan distorts state their sanitizer bound "
      "(GenCli.MemoryBudgetRefusesUpFrontWithNothingWritten: the measured peak may be 4x the estimate, 2x otherwise).")
fails = re.findall(r"\d+ - (\S+) \(Failed\)", read("sanitize.txt"))
if fails: print("\nFailing under sanitizers: " + ", ".join(fails))
print()
print("## Trust model for scene and baked files")
print()
print("The 32-byte trailer (size + 64-bit hash of the payload) proves a file is whole: truncation and damage are "
      "refused before OSG sees a byte (`fuzz_scene_file`, `fuzz_baked_file` above, and the test that damages a file "
      "at every offset). It does not prove the payload is a well-formed osgb graph: a file crafted with a matching "
      "trailer reaches OpenSceneGraph's osgb reader, which is not hardened against hostile input. vista trusts scene "
      "files as it trusts its own outputs; for files from elsewhere set `VISTA_UNTRUSTED_FILES=1`: the payload is then "
      "decoded once in a child process, and one that crashes the reader, or keeps it busy beyond a time limit, is "
      "refused with exit 2 (the load takes about twice as long). The trailer's hash is an integrity check, not an "
      "authentication: the fuzzer forges it. `VISTA_FUZZ_TRUSTED_TRAILER=1 build-fuzz/tests/fuzz/fuzz_scene_file` fuzzes the reader "
      "itself; its findings are OSG's.")
print()
print("## Faults")
print()
print("- kill -9 at five points of `vista gen --geojson --gltf` (150 ms .. 3.5 s into a 2 km city): each time the "
      "older .osgb stays byte-identical and no .geojson/.glb appears; the next run leaves no temporary file "
      "(GenCli.KillNineKeepsTheOldOutputAndTheNextRunCleansUp).")
print("- kill -9 at four points of `vista bake` (loading, first cell result, 10 cell results later, during the output "
      "write), each triggered by the event, not a delay: the older output stays byte-identical and the work directory "
      "holds only whole cell results; the next run reuses them all and writes the bytes of an uninterrupted bake "
      "(BakeFaults.KillNineLeavesTheOldOutputOrTheWholeNewOneAndTheNextRunResumes).")
print("- kill -9 of `vista render` after N finished frames (test hook `VISTA_RENDER_KILL_AFTER_FRAMES`, and a real "
      "SIGKILL from the test once two frame records exist): no `DIR` appears, `DIR.partial` holds whole frames; "
      "rerunning the command writes the bytes of an uninterrupted run, full and hybrid with its cache rebuilt "
      "(GroundTruth.FullResumesAfterKillByteIdentical, HybridResumesAfterKillByteIdentical, ExternalKillThenResume); "
      "other parameters are refused naming the field, or discarded with `--restart` "
      "(ResumeWithOtherParametersIsRefusedOrRestarted).")
print("- Disk full (a 2 MB tmpfs; the tests run as root, else they skip and say why): `vista gen` (also with a .glb that "
      "does not fit after the city and GeoJSON did) and `vista bake` (output or work directory on the full disk) exit 2 "
      "with 'No space left on device'; the older output stays, no output or temporary file is left, and whole cell "
      "results stay for the next run (GenFaults.DiskFull..., BakeFaults.DiskFull...).")
print()
print("### Injected faults at every write")
print()
print("`docs/tools/fault_sweep.sh` (the full sweep; `Reliability.FaultSweepSample` runs 6 fault points per command "
      "in the test suite) preloads tests/tools/fault_inject.c into `vista`, counts every create, mkdir, write, fsync, "
      "close of a written file and rename on the files of the command's output directory in a clean run, then for "
      "N = 1 .. that count runs the command with the Nth operation failing with ENOSPC. After each run it checks exit "
      "code 2 with 'No space left on device' on stderr, the previous outputs byte-identical, nothing new beside them "
      "but the documented resumable state (bake's whole cell results, render's OUT.partial, a paged city's whole "
      "regions), no empty directory, no temporary file, and that a rerun without the fault exits 0 with the bytes of "
      "a clean run (files whose bytes differ between two clean runs, timings, by name only). The commands, on a "
      "100 m city: `gen` with `--stats --geojson --gltf --xodr` over the outputs of another seed; paged `gen -o "
      "DIR.paged --region-size 250 --stats`; `bake --placement all --stats` over a bake of one cell; `render --mode "
      "hybrid` (3 frames, 64x48); `path --xodr-positions` over another seed's; `export --xodr` over another city's; "
      "`bench --modes full,hybrid --save-frames --worst 1` (3 frames) over a bench of another seed.")
print()
print("| command | fault points | exercised | crashes | partial outputs | failures (any kind) |")
print("|---|---|---|---|---|---|")
fault_rows = list(csv.DictReader(read("faults.tsv").splitlines(), delimiter="\t"))
for row in fault_rows:
    print(f"| {row['command']} | {int(row['fault_points']):,} | {int(row['exercised']):,} | {row['crash']} | {row['partial']} | {row['failures']} |")
total = lambda k: sum(int(r[k]) for r in fault_rows)
if fault_rows:
    print()
    print(f"The full sweep, `docs/tools/fault_sweep.sh --tsv faults.tsv`: {total('exercised'):,} fault points, each one "
          f"failed run and one rerun; {total('crash')} crashes, {total('partial')} partial outputs, "
          f"{total('failures')} failures of any kind.")
print()
print("- An unwritable output (missing directory, a file, a directory, read-only) is refused before the input is read, "
      "exit 2 naming the option: `vista gen`, `path`, `view --screenshot`, `bake -o/--work/--stats`, `bench --out` "
      "(checkWritablePath / checkWritableDirectory; the tests give a junk input that must not be reported).")
print()
print("## Soak")
print()
rows = [l for l in read("soak.csv").splitlines() if l and l[0].isdigit()]
last = [l for l in read("soak.csv").splitlines() if l.startswith("#")]
print(f"`build/tests/bench/soak CITY {soak_n} 64x48`: a `hybrid` walkthrough of the default city back and forth "
      "along a 2-minute car path, resident memory every 1,000 frames (goal: growth under 1 %).")
print()
print("| frame | RSS MB | ms/frame (last 1,000) |")
print("|---|---|---|")
step = max(1, len(rows) // 20)
for l in rows[::step] + ([rows[-1]] if rows and (len(rows) - 1) % step else []):
    f, r, ms = l.split(",")
    print(f"| {int(f):,} | {r} | {ms} |")
if last: print("\n" + last[0].lstrip("# "))
PY
# The section docs/tools/far_precision.sh writes is kept as it is.
python3 - docs/measurements/reliability.md >> docs/measurements/reliability.md.tmp <<'PY'
import sys
text = open(sys.argv[1]).read()
begin, end = "<!-- far-precision -->", "<!-- /far-precision -->"
if begin in text: print("\n" + text[text.index(begin):text.index(end) + len(end)])
PY
mv docs/measurements/reliability.md.tmp docs/measurements/reliability.md
echo "wrote docs/measurements/reliability.md" >&2
