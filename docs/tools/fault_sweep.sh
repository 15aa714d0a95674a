#!/usr/bin/env bash
# Fault-injection sweep: every write of every command fails once, in turn.
#
# For each command (gen with every extra output, paged gen, bake, render,
# path, export, bench) on a 100 m city, the sweep first runs the command
# without a fault on a copy of its previous outputs, counting the write
# operations it makes on files in its output directory (create, mkdir, write,
# fsync, close of a written file, rename: tests/tools/fault_inject.c, an
# LD_PRELOAD library). Then for N = 1 .. that count it runs the command again
# with the Nth operation failing (ENOSPC unless --errno) and checks:
#   - exit code 2, and the cause ("No space left on device") on stderr;
#   - the previous outputs byte-identical, nothing new beside them except the
#     documented resumable state (bake's work directory of whole cell
#     results, render's OUT.partial, a paged city's whole regions), no empty
#     directory left by the run;
#   - no temporary file (*.tmp.*, *.stage.*, *.prev.*);
#   - a rerun without the fault exits 0 with the bytes of a clean run (files
#     whose bytes differ between two clean runs, such as timings, are compared
#     by name only).
# It prints per command the fault points exercised and the failures by kind
# (crash, wrong exit code, cause not named, previous outputs changed, partial
# output, temporary left, rerun differs) and exits 1 if there is any.
#
#   usage: docs/tools/fault_sweep.sh [--sample K] [--commands LIST] [--errno NAME]
#                                    [--vista PATH] [--shim PATH] [--tsv FILE] [-v]
#     --sample K       K fault points per command, spread evenly over 1 .. all
#                      (default: all of them)
#     --commands LIST  comma-separated subset of gen,paged,bake,render,path,export,bench
#     --errno NAME     ENOSPC (default) or EIO
#     --vista PATH     the vista binary (default build/vista)
#     --shim PATH      the fault library (default build/tests/libvista_fault_inject.so)
#     --tsv FILE       also write the per-command counts as TSV
#     -v               print every failing fault point with its operation and file
# Run from the repository root after building the targets vista and
# vista_fault_inject. render and bench need an X display; without DISPLAY the
# sweep runs itself under xvfb-run. The full sweep runs two commands per
# fault point (about 5,400 runs of vista): most of an hour on 2 busy cores;
# `--sample 6` (the Reliability.FaultSweepSample test) under a minute.
set -euo pipefail
cd "$(dirname "$0")/../.."
# A preloaded library (the sanitizer runtime of .ci/sanitize.sh) is for vista
# only: it comes first, the fault library after it; the sweep's own processes
# (python, Xvfb) run without it.
export VISTA_SWEEP_PRELOAD="${VISTA_SWEEP_PRELOAD:-${LD_PRELOAD:-}}"
unset LD_PRELOAD
if [ -z "${DISPLAY:-}" ] && [ -z "${VISTA_FAULT_SWEEP_XVFB:-}" ] && command -v xvfb-run >/dev/null; then
  VISTA_FAULT_SWEEP_XVFB=1 exec xvfb-run -a -s "-screen 0 640x480x24" "$0" "$@"
fi
exec python3 - "$@" <<'PY'
import argparse, hashlib, os, re, shutil, signal, subprocess, sys, tempfile
signal.signal(signal.SIGTERM, lambda *_: sys.exit(143))  # a stopped sweep removes its scratch directory too

ap = argparse.ArgumentParser(prog="fault_sweep.sh")
ap.add_argument("--sample", type=int, default=0)
ap.add_argument("--commands", default="gen,paged,bake,render,path,export,bench")
ap.add_argument("--errno", default="ENOSPC", choices=["ENOSPC", "EIO"])
ap.add_argument("--vista", default="build/vista")
ap.add_argument("--shim", default="build/tests/libvista_fault_inject.so")
ap.add_argument("--tsv", default="")
ap.add_argument("-v", action="store_true")
a = ap.parse_args()
VISTA, SHIM = os.path.abspath(a.vista), os.path.abspath(a.shim)
for f in (VISTA, SHIM):
    if not os.path.exists(f):
        sys.exit(f"fault_sweep: {f} not found (build the targets vista and vista_fault_inject)")
CAUSE = {"ENOSPC": "No space left on device", "EIO": "Input/output error"}[a.errno]
TEMP = re.compile(r"\.(tmp|stage|prev)\.\d+")

# name: (previous outputs: a command run first, or None; the command; the resumable state a
# failed run may leave, as a regular expression over paths relative to the output directory).
CITY = "{i}/city.osgb"
BAKE = "bake " + CITY + " --out-size 40 --min-triangles 1 --placement all --jobs 1 -q"
COMMANDS = {
    "gen": ("gen --size 100 --seed 4 --detail 0 -q -o {d}/c.osgb --stats {d}/c.json --geojson {d}/c.geojson"
            " --gltf {d}/c.glb --xodr {d}/c.xodr",
            "gen --size 100 --seed 3 --detail 0 -q -o {d}/c.osgb --stats {d}/c.json --geojson {d}/c.geojson"
            " --gltf {d}/c.glb --xodr {d}/c.xodr", None),
    "paged": (None, "gen --size 100 --region-size 250 --seed 3 --detail 0 -q -o {d}/c.paged --stats {d}/c.json",
              r"c\.paged(/records)?/(region_\d+_\d+(\.coarse)?\.osgb|region_\d+_\d+\.json)"),
    "bake": (BAKE + " --cells 0 -o {d}/b.osgb --stats {d}/b.json", BAKE + " -o {d}/b.osgb --stats {d}/b.json",
             r"b\.osgb\.work/cell_\d+\.vbc"),
    "render": (None, "render " + CITY + " --seed 1 --frames 3 --size 64x48 --mode hybrid --threads 1 -q --out {d}/gt",
               r"gt\.partial/.*"),
    "path": ("path " + CITY + " --seed 2 --duration 4 -o {d}/p.csv --xodr-positions {d}/p.pos.csv",
             "path " + CITY + " --seed 1 --duration 4 -o {d}/p.csv --xodr-positions {d}/p.pos.csv", None),
    "export": ("export {i}/other.osgb --xodr {d}/e.xodr -q", "export " + CITY + " --xodr {d}/e.xodr -q", None),
    "bench": ("bench " + CITY + " --seed 2 --frames 2 --size 64x48 --modes full,hybrid --threads 1 --save-frames"
              " --worst 1 -q --out {d}/bench",
              "bench " + CITY + " --seed 1 --frames 3 --size 64x48 --modes full,hybrid --threads 1 --save-frames"
              " --worst 1 -q --out {d}/bench", None),
}

def run(cmd, d, i, fault=0, count=None, log=None):
    env = dict(os.environ)
    env["LD_PRELOAD"] = (env.get("VISTA_SWEEP_PRELOAD", "") + " " + SHIM).strip()
    env.update(VISTA_FAULT_DIR=d, VISTA_FAULT_AT=str(fault), VISTA_FAULT_ERRNO=a.errno)
    if count: env["VISTA_FAULT_COUNT_FILE"] = count
    if log: env["VISTA_FAULT_LOG"] = log
    p = subprocess.run([VISTA] + cmd.format(d=d, i=i).split(), env=env, stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, timeout=600)
    return p.returncode, p.stderr.decode(errors="replace")

def tree(d):
    """relative path -> sha256 of a file, or '/' for a directory"""
    out = {}
    for root, dirs, files in os.walk(d):
        for n in dirs: out[os.path.relpath(os.path.join(root, n), d)] = "/"
        for n in files:
            p = os.path.join(root, n)
            out[os.path.relpath(p, d)] = hashlib.sha256(open(p, "rb").read()).hexdigest()
    return out

def sample(total, k):
    if k <= 0 or k >= total: return list(range(1, total + 1))
    return sorted({1 + round(j * (total - 1) / (k - 1)) for j in range(k)} if k > 1 else {1})

def sweep(name, work, inputs):
    prev, cmd, state = COMMANDS[name]
    state_re = re.compile(state) if state else None
    base = os.path.join(work, name + ".prev")
    os.makedirs(base)
    if prev:
        rc, err = run(prev, base, inputs)
        if rc != 0: sys.exit(f"fault_sweep: {name}: the previous run failed ({rc}): {err}")
    before = tree(base)
    refs = []
    for k in range(2):  # two clean runs: the reference bytes and which files differ between runs
        d = os.path.join(work, f"{name}.ref{k}")
        shutil.copytree(base, d)
        rc, err = run(cmd, d, inputs, count=os.path.join(work, name + ".count"))
        if rc != 0: sys.exit(f"fault_sweep: {name}: the clean run failed ({rc}): {err}")
        refs.append(tree(d))
    volatile = {p for p in refs[0] if refs[1].get(p) != refs[0][p]}
    total = int(open(os.path.join(work, name + ".count")).read().split()[1])
    kinds = ["crash", "exit code", "cause not named", "previous outputs changed", "partial output",
             "temporary left", "rerun differs", "fault absorbed"]
    fails = {k: [] for k in kinds}
    points = sample(total, a.sample)
    for n in points:
        d = os.path.join(work, f"{name}.f{n}")
        shutil.copytree(base, d)
        log = os.path.join(work, f"{name}.f{n}.log")
        rc, err = run(cmd, d, inputs, fault=n, log=log)
        what = open(log).read().strip() if os.path.exists(log) else f"{n} (not reached)"
        after = tree(d)
        def fail(kind, detail=""):
            fails[kind].append(f"{what}: {detail}".strip())
        if rc < 0 or rc >= 128: fail("crash", f"exit {rc}: {err[-300:]}")
        elif rc == 0:
            if after != refs[0] and {p for p in after if p not in volatile} != {p for p in refs[0] if p not in volatile}:
                fail("fault absorbed", "exit 0 with other outputs than a clean run")
        elif rc != 2: fail("exit code", f"exit {rc}: {err.strip()[-200:]}")
        elif CAUSE not in err: fail("cause not named", err.strip()[-200:])
        if rc != 0:
            changed = [p for p in before if after.get(p) != before[p]]
            if changed: fail("previous outputs changed", ", ".join(changed[:4]))
            new = [p for p in after if p not in before and not TEMP.search(p)]
            partial = [p for p in new if not (state_re and state_re.fullmatch(p) and after[p] != "/")]
            # a directory of the resumable state is fine when it holds some of it
            partial = [p for p in partial if not (after.get(p) == "/" and state_re and any(
                q.startswith(p + "/") and after[q] != "/" and state_re.fullmatch(q) for q in after))]
            if partial: fail("partial output", ", ".join(sorted(partial)[:4]))
        temps = [p for p in after if TEMP.search(p)]
        if temps: fail("temporary left", ", ".join(temps[:4]))
        rc2, err2 = run(cmd, d, inputs)
        again = tree(d)
        same = rc2 == 0 and set(again) == set(refs[0]) and all(again[p] == refs[0][p] for p in again if p not in volatile)
        if not same:
            diff = sorted(set(again) ^ set(refs[0])) or [p for p in again if p not in volatile and again[p] != refs[0].get(p)]
            fail("rerun differs", f"exit {rc2} {err2.strip()[-200:]} {', '.join(diff[:4])}")
        shutil.rmtree(d)
    return total, len(points), fails, kinds

work = tempfile.mkdtemp(prefix="vista_fault_sweep_")
try:
    inputs = os.path.join(work, "inputs")
    os.makedirs(inputs)
    for seed, f in (("3", "city.osgb"), ("4", "other.osgb")):
        env = dict(os.environ)
        if env.get("VISTA_SWEEP_PRELOAD"): env["LD_PRELOAD"] = env["VISTA_SWEEP_PRELOAD"]
        subprocess.run([VISTA, "gen", "--size", "100", "--seed", seed, "--detail", "0", "-q", "-o",
                        os.path.join(inputs, f)], check=True, env=env)
    rows, bad = [], 0
    print(f"| command | fault points | exercised | crashes | partial outputs | other failures |")
    print("|---|---|---|---|---|---|")
    for name in a.commands.split(","):
        total, n, fails, kinds = sweep(name, work, inputs)
        other = {k: len(v) for k, v in fails.items() if v and k not in ("crash", "partial output")}
        bad += sum(len(v) for v in fails.values())
        print(f"| {name} | {total} | {n} | {len(fails['crash'])} | {len(fails['partial output'])} | "
              + (", ".join(f"{k}: {c}" for k, c in other.items()) or "0") + " |", flush=True)
        rows.append((name, total, n, fails))
        if a.v:
            for k, v in fails.items():
                for x in v: print(f"    {name}: {k}: {x}", file=sys.stderr)
    if a.tsv:
        with open(a.tsv, "w") as f:
            f.write("command\tfault_points\texercised\tcrash\tpartial\tfailures\n")
            for name, total, n, fails in rows:
                f.write(f"{name}\t{total}\t{n}\t{len(fails['crash'])}\t{len(fails['partial output'])}\t"
                        f"{sum(len(v) for v in fails.values())}\n")
    sys.exit(1 if bad else 0)
finally:
    shutil.rmtree(work, ignore_errors=True)
PY
