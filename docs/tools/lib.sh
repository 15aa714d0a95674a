# Shared start of the scripts that regenerate a doc from measurements
# (effects.sh, raw_rays.sh, far_field_table.sh). Source it, then call
#   doc_setup NAME TMP_PREFIX SCREEN "$@"
# which sets START (for log), OUT (argument 1, or a new /tmp/vista-TMP_PREFIX.*
# directory removed at exit), VISTA (argument 2, default build/vista), REPO
# (and cd's there), XVFB (an xvfb-run command with screen SCREEN, e.g.
# 1280x1024x24, when no DISPLAY is set; else empty), checks the vista binary
# and python3, and installs the EXIT and ERR traps. Partial outputs the script
# writes (paths relative to the repository) go into DOC_TMP_FILES: they are
# removed at exit, so a failed run never leaves one behind.
# die MSG: error and exit 1. log MSG: progress with the seconds since START.
#
# Every generated block starts with a stamp (doc_stamp): the vista version and
# commit measured, the machine (CPU model, cores, RAM) and the load average at
# the start of the run (DOC_START_LOAD: read by doc_setup, or set by
# regenerate_all.sh for the step) and at its end. A 1-minute load average at
# the start above DOC_LOAD_LIMIT marks the block "Measured under load": other
# work shared the cores, and its times are not the machine's.
# tests/tools/check_docs.py reads the stamp (keep its STAMP_RE in step).

# The 1-minute load average above which a block is marked as measured under load.
DOC_LOAD_LIMIT=0.5

die() { echo "$DOC_NAME: error: $*" >&2; exit 1; }
log() { printf '[%s %4ds] %s\n' "$DOC_NAME" $((SECONDS - START)) "$*" >&2; }

doc_cleanup() {
  if [ "$KEEP_OUT" = 0 ]; then rm -rf "$OUT"; fi
  local f
  for f in "${DOC_TMP_FILES[@]}"; do rm -f "$REPO/$f"; done
}

doc_setup() {
  DOC_NAME=$1
  local prefix=$2 screen=$3
  shift 3
  START=$SECONDS
  DOC_START_LOAD=${DOC_START_LOAD:-$(cut -d' ' -f1-3 /proc/loadavg)}
  KEEP_OUT=1
  if [ -n "${1:-}" ]; then OUT=$(realpath -m "$1"); else OUT=$(mktemp -d "/tmp/vista-$prefix.XXXXXX"); KEEP_OUT=0; fi
  VISTA=$(realpath -m "${2:-build/vista}")
  REPO=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
  cd "$REPO"
  DOC_TMP_FILES=()
  trap doc_cleanup EXIT
  trap 'echo "$DOC_NAME: failed at line $LINENO: $BASH_COMMAND" >&2' ERR
  [ -x "$VISTA" ] || die "vista binary not found: $VISTA"
  command -v python3 >/dev/null || die "python3 is needed"
  XVFB=()
  if [ -z "${DISPLAY:-}" ]; then
    command -v xvfb-run >/dev/null || die "no DISPLAY and no xvfb-run"
    XVFB=(xvfb-run -a -s "-screen 0 $screen")
  fi
}

# doc_stamp: prints the stamp line of a generated block (one line, Markdown):
#   [**Measured under load** (...): ]Measured with vista X.Y.Z (commit C) on CPU,
#   N cores, M GB RAM; load average at start L1, L5, L15 (1, 5, 15 min), at the end ...
# The version is what $VISTA --version prints; the commit is the repository's
# HEAD, "+ local changes" when files outside docs/ differ from it.
doc_stamp() {
  local version commit cpu cores ram start end load1 under=""
  version=$("$VISTA" --version 2>/dev/null | sed -n 's/^vista \([0-9][0-9.]*\)$/\1/p')
  [ -n "$version" ] || die "$VISTA --version printed no version"
  commit=$(git -C "$REPO" rev-parse --short=10 HEAD 2>/dev/null || echo "unknown")
  if [ "$commit" != unknown ] && ! git -C "$REPO" diff --quiet HEAD -- . ':(exclude)docs' 2>/dev/null; then
    commit="$commit + local changes"
  fi
  cpu=$(sed -n 's/^model name[[:space:]]*: //p' /proc/cpuinfo | head -n1)
  cores=$(nproc)
  ram=$(awk '/^MemTotal:/ {printf "%.0f GB", $2 / 1048576}' /proc/meminfo)
  start=${DOC_START_LOAD:-?}
  end=$(cut -d' ' -f1-3 /proc/loadavg)
  load1=${start%% *}
  if [ "$load1" != "?" ] && awk -v l="$load1" -v m="$DOC_LOAD_LIMIT" 'BEGIN { exit !(l > m) }'; then
    under="**Measured under load** (1-minute load average $load1 at the start, above $DOC_LOAD_LIMIT: other work shared the cores, so the times run high): "
  fi
  echo "${under}Measured with vista $version (commit $commit) on ${cpu:-an unknown CPU}, $cores cores, $ram RAM;" \
       "load average at the start ${start// /, } (1, 5, 15 min), at the end ${end// /, }."
}

# doc_replace_block DOC MARKER TABLE: replaces the block between
# <!-- MARKER:begin --> and <!-- MARKER:end --> of DOC (a path relative to the
# repository) with the stamp (doc_stamp) and TABLE's text, through DOC's
# directory/.NAME.tmp (list it in DOC_TMP_FILES) and a rename, so a failure
# leaves DOC as it was.
doc_replace_block() {
  local doc=$1 marker=$2 table=$3
  local tmp stamp
  tmp="$(dirname "$doc")/.$(basename "$doc").tmp"
  grep -q "<!-- $marker:begin -->" "$doc" || die "$doc has no <!-- $marker:begin --> marker"
  [ -s "$table" ] || die "the table for $doc ($marker) is empty: $table"
  stamp=$(doc_stamp)
  python3 - "$doc" "$marker" "$table" "$stamp" > "$tmp" <<'PYEOF'
import sys
doc, marker, table, stamp = sys.argv[1:5]
text = open(doc).read()
begin, end = f"<!-- {marker}:begin -->", f"<!-- {marker}:end -->"
head, rest = text.split(begin, 1)
_, tail = rest.split(end, 1)
body = stamp + "\n\n" + open(table).read().rstrip("\n") + "\n"
print(head + begin + "\n" + body + end + tail, end="")
PYEOF
  mv "$tmp" "$doc"
}
