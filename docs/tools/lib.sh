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

# doc_replace_block DOC MARKER TABLE: replaces the block between
# <!-- MARKER:begin --> and <!-- MARKER:end --> of DOC (a path relative to the
# repository) with "Load average at the end of the run: ..." and TABLE's text,
# through DOC's directory/.NAME.tmp (list it in DOC_TMP_FILES) and a rename, so a failure leaves
# DOC as it was.
doc_replace_block() {
  local doc=$1 marker=$2 table=$3
  local tmp
  tmp="$(dirname "$doc")/.$(basename "$doc").tmp"
  grep -q "<!-- $marker:begin -->" "$doc" || die "$doc has no <!-- $marker:begin --> marker"
  python3 - "$doc" "$marker" "$table" "$(cut -d' ' -f1-3 /proc/loadavg)" > "$tmp" <<'PYEOF'
import sys
doc, marker, table, load = sys.argv[1:5]
text = open(doc).read()
begin, end = f"<!-- {marker}:begin -->", f"<!-- {marker}:end -->"
head, rest = text.split(begin, 1)
_, tail = rest.split(end, 1)
body = f"Load average at the end of the run: {load}.\n\n" + open(table).read()
print(head + begin + "\n" + body + end + tail, end="")
PYEOF
  mv "$tmp" "$doc"
}
