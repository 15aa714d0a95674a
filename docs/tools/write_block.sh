#!/usr/bin/env bash
# Writes a table that a docs/tools script printed (perf_table.sh, sweep.sh,
# bake_results.sh, paged_rss_table.sh) into its page's generated block, between
# <!-- MARKER:begin --> and <!-- MARKER:end --> of DOC, below the stamp of
# docs/tools/lib.sh (doc_stamp: version and commit of VISTA, the machine, the
# load average). regenerate_all.sh runs each such step this way and sets
# DOC_START_LOAD to the load average at the step's start; run alone, set it
# before the measuring script starts:
#   DOC_START_LOAD="$(cut -d' ' -f1-3 /proc/loadavg)"; docs/tools/perf_table.sh > t.md
#   DOC_START_LOAD="$DOC_START_LOAD" docs/tools/write_block.sh docs/measurements/generation.md generation-table t.md
# usage: docs/tools/write_block.sh DOC MARKER TABLE [VISTA]   (VISTA default build/vista)
# DOC is replaced atomically; on any error it stays as it was.
set -euo pipefail
[ $# -ge 3 ] && [ $# -le 4 ] || { echo "usage: $0 DOC MARKER TABLE [VISTA]" >&2; exit 2; }
DOC=$1 MARKER=$2 TABLE=$(realpath -m "$3")
VISTA=$(realpath -m "${4:-build/vista}")
source "$(dirname "$0")/lib.sh"
DOC_NAME=write_block.sh
REPO=$(cd "$(dirname "$0")/../.." && pwd)
cd "$REPO"
[ -x "$VISTA" ] || die "vista binary not found: $VISTA"
[ -f "$DOC" ] || die "DOC: no such page: $DOC"
[ -s "$TABLE" ] || die "TABLE: missing or empty: $TABLE"
: "${DOC_START_LOAD:=?}"
trap 'rm -f "$(dirname "$DOC")/.$(basename "$DOC").tmp"' EXIT
doc_replace_block "$DOC" "$MARKER" "$TABLE"
