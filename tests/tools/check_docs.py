#!/usr/bin/env python3
"""Checks that vista's documentation stays a house for readers.

Over README.md, CHANGELOG.md and every docs/**/*.md:

1. Every relative Markdown link and image resolves: the file exists, and a
   #anchor names a heading of the target (GitHub's slug rule) or an explicit
   <a id="..."> / <a name="..."> in it.
2. Every `vista <command> --flag` written inside a code span or a fenced code
   block names a command that `vista help` lists and flags that
   `vista <command> --help` prints (the built binary is run).
3. No heading carries an issue number (the word issue and a number) or an
   ISO date (YYYY-MM-DD): history belongs in git and CHANGELOG.md.
4. Every generated block of docs/measurements (<!-- NAME:begin --> ...
   <!-- NAME:end -->, written by a docs/tools script) holds more than its
   stamp, and its first line is the stamp of docs/tools/lib.sh (doc_stamp)
   naming the current minor version (CMake's project VERSION): a release
   regenerates every table. Blocks listed in AWAITING_REGENERATION are let
   through until they are regenerated; a listed block that already carries the
   current version, or that no longer exists, is itself a problem, so the list
   only shrinks.
5. No internal notes: none of REJECTED_PHRASES (notes to the team, diary
   wording, binaries of one machine) appears; "this machine" is rejected in the
   guide, whose reader's machine is not the one the docs were measured on.
6. One source for the cities' sizes: a line outside
   docs/measurements/generation.md (and outside generated blocks and code)
   that gives a generated city's size (`--size S` or "S km") does not also
   state its triangle count; it links generation.md, whose table measures it,
   so two pages never quote two counts for one city.

Prints every problem as FILE:LINE: message and exits 1 if there is one;
exits 0 with a one-line summary otherwise.

Usage: check_docs.py --root SOURCE_DIR --vista VISTA_BINARY
       check_docs.py --self-test --vista VISTA_BINARY
  (--self-test writes a small broken docs tree into a temporary directory and
   fails unless the check finds each planted problem, then checks a clean one;
   it also runs docs/tools/lib.sh's doc_stamp and reads its lines back)
"""
import argparse
import os
import re
import subprocess
import sys
import tempfile

LINK_RE = re.compile(r"!?\[(?:[^\[\]]|\[[^\]]*\])*\]\(\s*<?([^)\s>]+)>?(?:\s+\"[^\"]*\")?\s*\)")
HTML_IMG_RE = re.compile(r"<img\s[^>]*src=\"([^\"]+)\"", re.IGNORECASE)
HTML_ANCHOR_RE = re.compile(r"<a\s+(?:id|name)=\"([^\"]+)\"", re.IGNORECASE)
HEADING_RE = re.compile(r"^(#{1,6})\s+(.*?)\s*#*\s*$")
FENCE_RE = re.compile(r"^\s*(```|~~~)")
CODE_SPAN_RE = re.compile(r"(`+)(.+?)\1")
BAD_HEADING_RES = [
    (re.compile(r"\bissues?\s*#?\s*\d+", re.IGNORECASE), "an issue number"),
    (re.compile(r"\b\d{4}-\d{2}-\d{2}\b"), "an ISO date"),
]
# The stamp line of a generated block (docs/tools/lib.sh, doc_stamp).
STAMP_RE = re.compile(r"^(?:\*\*Measured under load\*\* \([^)]*\): )?Measured with vista (\d+)\.(\d+)\.(\d+) "
                      r"\(commit [^)]+\) on .+; load average at the start ")
BLOCK_BEGIN_RE = re.compile(r"^<!-- ([A-Za-z0-9_-]+):begin -->\s*$")
BLOCK_END_RE = re.compile(r"^<!-- ([A-Za-z0-9_-]+):end -->\s*$")
PROJECT_VERSION_RE = re.compile(r"^\s*project\(\s*vista\b[^)]*\bVERSION\s+(\d+)\.(\d+)\.(\d+)", re.MULTILINE)

# Generated blocks whose current table has not been measured yet: (page, block)
# -> why. The tables need a quiet machine (nothing else running) and hours of
# both cores: docs/tools/regenerate_all.sh OUT build STEP regenerates each,
# and the entry goes once the block carries the current version's stamp.
_QUIET = "measured before the version stamp; needs a run on a quiet machine"
AWAITING_REGENERATION = {
    ("docs/measurements/bake.md", "whole-bake"): _QUIET,
    ("docs/measurements/bake.md", "whole-bake-seed2"): _QUIET,
    ("docs/measurements/bake.md", "splat-table"): _QUIET,
    ("docs/measurements/bake.md", "splat-table-seed2"): _QUIET,
    ("docs/measurements/effects.md", "effects"): _QUIET,
    ("docs/measurements/effects.md", "effects-haze"): _QUIET,
    ("docs/measurements/far-field.md", "far-field-table"): _QUIET,
    ("docs/measurements/farfield-compare.md", "farfield-compare"): _QUIET,
    ("docs/measurements/paging.md", "paged-generation"): _QUIET,
    ("docs/measurements/paging.md", "scale-table"): "empty: the 4-64 km cities were never measured "
                                                     "with the current paging; about an hour",
    ("docs/measurements/paging.md", "stream-table"): _QUIET,
    ("docs/measurements/paging.md", "stream-budget"): _QUIET,
    ("docs/measurements/paging.md", "paged-reach"): "empty: needs the 8 km paged city of the scale step",
}

# Internal notes a reader should not see: (regex, scope, why). Scope "all" is
# every checked file except CHANGELOG.md (history may quote them), "guide" is
# docs/guide/ only.
REJECTED_PHRASES = [
    (re.compile(r"\bbefore you stop\b", re.IGNORECASE), "all", "a note to the team"),
    (re.compile(r"\btwice more by hand\b|\b(?:were|was) (?:run|rerun|re-run|measured|repeated)\b[^.\n]{0,30}"
                r"\bby hand\b", re.IGNORECASE), "all",
     "a step the scripts do not do (make the script do it, or say what the script does)"),
    (re.compile(r"\bproven here\b", re.IGNORECASE), "all", "diary wording"),
    (re.compile(r"\bTODO\b|\bFIXME\b"), "all", "an open note"),
    (re.compile(r"\bvista2\b"), "all", "a binary of one machine (write build/vista)"),
    (re.compile(r"\bthis machine\b", re.IGNORECASE), "guide",
     "the reader's machine is not the measured one (name the machine, link the measurement page)"),
]

# `vista <command>` where vista is the tool (also build/vista), not osgdb_vista,
# vista_bake_report, vista::Type or a path like /tmp/vista-x.
VISTA_CMD_RE = re.compile(r"(?:^|(?<=[\s/(\[{'\"=]))vista[ \t]+([A-Za-z-][A-Za-z0-9_-]*)")
FLAG_RE = re.compile(r"(?<![\w-])(--[A-Za-z][A-Za-z0-9-]*)")
# Where a command written in a code block or span ends.
COMMAND_END_RE = re.compile(r"\s#|;|&&|\|\||\$\(|`")
# Programs that run the command after them.
WRAPPERS = {"$", "xvfb-run", "nice", "time", "/usr/bin/time", "env", "sudo", "exec", "timeout"}
# A shell comment in a code block: from a # at the start or after a blank.
SHELL_COMMENT_RE = re.compile(r"(^|\s)#.*$")


def slugify(heading):
    """GitHub's anchor for a heading: lower case, markup and punctuation
    dropped, spaces to hyphens."""
    text = re.sub(r"!?\[([^\]]*)\]\([^)]*\)", r"\1", heading)  # links: their text
    text = re.sub(r"<[^>]+>", "", text)  # inline HTML
    text = text.replace("`", "").lower()
    text = "".join(ch for ch in text if ch.isalnum() or ch in " -_")
    return text.replace(" ", "-")


class Doc:
    """One Markdown file: its lines split into prose and code, its anchors."""

    def __init__(self, path):
        self.path = path
        with open(path, encoding="utf-8") as f:
            self.lines = f.read().split("\n")
        self.code_line = []  # per line: True inside a fenced block (fences included)
        inside = None
        for line in self.lines:
            m = FENCE_RE.match(line)
            if inside is None and m:
                inside = m.group(1)
                self.code_line.append(True)
            elif inside is not None:
                self.code_line.append(True)
                if line.strip().startswith(inside):
                    inside = None
            else:
                self.code_line.append(False)
        self.anchors = set()
        self.headings = []  # (line number, text)
        seen = {}
        for i, line in enumerate(self.lines):
            if self.code_line[i]:
                continue
            for a in HTML_ANCHOR_RE.findall(line):
                self.anchors.add(a)
            m = HEADING_RE.match(line)
            if not m:
                continue
            text = m.group(2)
            self.headings.append((i + 1, text))
            slug = slugify(text)
            n = seen.get(slug, 0)
            seen[slug] = n + 1
            self.anchors.add(slug if n == 0 else f"{slug}-{n}")


def vista_help(vista):
    """The commands `vista help` lists and, per command, the flags of its --help."""
    def run(args):
        r = subprocess.run([vista] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           text=True, timeout=120)
        return r.stdout
    top = run(["help"])
    commands = {}
    for line in top.split("\n"):
        m = re.match(r"^\s{2,}([a-z][a-z0-9-]*)\s{2,}\S", line)
        if m:
            commands[m.group(1)] = None
    if not commands:
        sys.exit(f"check_docs: `{vista} help` listed no commands:\n{top}")
    for name in list(commands):
        text = run([name, "--help"])
        commands[name] = set(FLAG_RE.findall(text)) | {"--help"}
    top_flags = set(FLAG_RE.findall(top)) | {"--help"}
    return commands, top_flags


def code_fragments(doc):
    """(line number, text) of every code span in prose and every command of a
    fenced block (continuation lines joined)."""
    out = []
    i = 0
    n = len(doc.lines)
    while i < n:
        line = doc.lines[i]
        if doc.code_line[i]:
            if FENCE_RE.match(line):
                i += 1
                continue
            start = i
            text = SHELL_COMMENT_RE.sub("", line)
            while text.rstrip().endswith("\\") and i + 1 < n and doc.code_line[i + 1] \
                    and not FENCE_RE.match(doc.lines[i + 1]):
                i += 1
                text = text.rstrip()[:-1] + " " + SHELL_COMMENT_RE.sub("", doc.lines[i])
            if not text.lstrip().startswith("//"):
                out.append((start + 1, text))
        else:
            for m in CODE_SPAN_RE.finditer(line):
                out.append((i + 1, m.group(2)))
        i += 1
    return out


def invoked(before):
    """Whether `vista` starts a command here rather than being an argument of
    another program (docs/tools/x.sh build/vista OUT) or a word in a listing:
    only a command separator, environment assignments and wrappers such as
    xvfb-run, nice or /usr/bin/time (with their options) may come before it."""
    seg = re.split(r";|&&|\|\||\||\$\(|\(", before)[-1]
    seg = re.sub(r"\"[^\"]*\"|'[^']*'", "", seg)  # quoted wrapper options
    tokens = seg.split()
    if tokens and "/" in tokens[-1]:  # the path before vista (build/vista): its own token
        tokens[-1] = tokens[-1].rsplit("/", 1)[0]
        if tokens[-1] and not re.match(r"^[\w.$~-]*(/[\w.$~-]*)*$", tokens[-1]):
            return False
        tokens.pop()
    for t in tokens:
        if not (t in WRAPPERS or t.startswith("-") or re.match(r"^[A-Za-z_]\w*=\S*$", t)
                or re.match(r"^[0-9.]+$", t)):
            return False
    return True


def check_commands(doc, rel, commands, top_flags, problems):
    for lineno, text in code_fragments(doc):
        for m in VISTA_CMD_RE.finditer(text):
            if not invoked(text[:m.start()]):
                continue
            cmd = m.group(1)
            rest = text[m.end():]
            end = COMMAND_END_RE.search(rest)
            if end:
                rest = rest[:end.start()]
            if cmd.startswith("-"):
                if cmd not in top_flags:
                    problems.append(f"{rel}:{lineno}: `vista {cmd}`: `vista help` knows no such option")
                continue
            if cmd not in commands:
                problems.append(f"{rel}:{lineno}: `vista {cmd}`: no such command in `vista help`")
                continue
            for flag in FLAG_RE.findall(rest):
                if flag not in commands[cmd]:
                    problems.append(f"{rel}:{lineno}: `vista {cmd} {flag}`: not an option of `vista {cmd} --help`")


def check_links(doc, rel, docs_by_path, problems):
    for i, line in enumerate(doc.lines):
        if doc.code_line[i]:
            continue
        prose = CODE_SPAN_RE.sub("", line)
        targets = LINK_RE.findall(prose) + HTML_IMG_RE.findall(prose)
        for target in targets:
            if re.match(r"^[a-zA-Z][a-zA-Z0-9+.-]*:", target):  # http:, https:, mailto:
                continue
            path_part, _, anchor = target.partition("#")
            if path_part:
                dest = os.path.normpath(os.path.join(os.path.dirname(doc.path), path_part))
                if not os.path.exists(dest):
                    problems.append(f"{rel}:{i + 1}: link to {target}: {path_part} does not exist")
                    continue
            else:
                dest = doc.path
            if not anchor:
                continue
            if not dest.endswith(".md") or os.path.isdir(dest):
                problems.append(f"{rel}:{i + 1}: link to {target}: an anchor into a file that is not Markdown")
                continue
            target_doc = docs_by_path.get(dest) or Doc(dest)
            if anchor not in target_doc.anchors:
                problems.append(f"{rel}:{i + 1}: link to {target}: no heading #{anchor} in {os.path.basename(dest)}")


def check_headings(doc, rel, problems):
    for lineno, text in doc.headings:
        for regex, what in BAD_HEADING_RES:
            if regex.search(text):
                problems.append(f"{rel}:{lineno}: heading \"{text}\" carries {what}")


def check_phrases(doc, rel, problems):
    if rel == "CHANGELOG.md":
        return
    in_guide = rel.startswith(os.path.join("docs", "guide") + os.sep)
    for i, line in enumerate(doc.lines):
        for regex, scope, why in REJECTED_PHRASES:
            if scope == "guide" and not in_guide:
                continue
            m = regex.search(line)
            if m:
                problems.append(f"{rel}:{i + 1}: \"{m.group(0)}\": {why}")


CITY_SIZE_RE = re.compile(r"--size\s+\d+|\b\d+(?:\.\d+)?\s?km\b(?!\s?²)")
TRIANGLE_COUNT_RE = re.compile(r"\b\d+(?:\.\d+)?\s?M\s+(?:rendered\s+|stored\s+)?triangles\b")
SIZES_PAGE = "docs/measurements/generation.md"


def check_quoted_sizes(doc, rel, problems):
    """A city's triangle count is measured once (SIZES_PAGE); other pages link it."""
    if rel.replace(os.sep, "/") in (SIZES_PAGE, "CHANGELOG.md"):
        return
    in_block = set()
    for _, start, body in blocks(doc)[0]:
        in_block.update(range(start, start + len(body)))
    fence = False
    for i, line in enumerate(doc.lines):
        if FENCE_RE.match(line):
            fence = not fence
            continue
        if fence or i in in_block:
            continue
        count = TRIANGLE_COUNT_RE.search(line)
        if count and CITY_SIZE_RE.search(line):
            problems.append(f"{rel}:{i + 1}: states a city's triangle count ({count.group(0)}) beside its size: "
                            f"link {SIZES_PAGE}, which measures it, instead of quoting a second figure")


def project_minor(root):
    """(major, minor) of CMake's project VERSION, or None."""
    path = os.path.join(root, "CMakeLists.txt")
    if not os.path.exists(path):
        return None
    with open(path, encoding="utf-8") as f:
        m = PROJECT_VERSION_RE.search(f.read())
    return (int(m.group(1)), int(m.group(2))) if m else None


def blocks(doc):
    """[(name, begin line number, body lines)] of the generated blocks, and
    [(line number, message)] for unbalanced markers."""
    out, errors = [], []
    i = 0
    while i < len(doc.lines):
        m = BLOCK_BEGIN_RE.match(doc.lines[i])
        if m:
            name, start = m.group(1), i
            j = i + 1
            while j < len(doc.lines) and not BLOCK_END_RE.match(doc.lines[j]) \
                    and not BLOCK_BEGIN_RE.match(doc.lines[j]):
                j += 1
            end = BLOCK_END_RE.match(doc.lines[j]) if j < len(doc.lines) else None
            if not end or end.group(1) != name:
                errors.append((start + 1, f"block {name} has no <!-- {name}:end --> before the next marker"))
                i = j if j > i else i + 1
                continue
            out.append((name, start + 1, doc.lines[start + 1:j]))
            i = j + 1
            continue
        m = BLOCK_END_RE.match(doc.lines[i])
        if m:
            errors.append((i + 1, f"<!-- {m.group(1)}:end --> without its begin"))
        i += 1
    return out, errors


def check_blocks(docs, root, awaiting, problems):
    current = project_minor(root)
    seen = set()
    for doc in docs:
        rel = os.path.relpath(doc.path, root)
        found, errors = blocks(doc)
        problems.extend(f"{rel}:{n}: {msg}" for n, msg in errors)
        for name, lineno, body in found:
            key = (rel.replace(os.sep, "/"), name)
            seen.add(key)
            text = [line for line in body if line.strip()]
            stamp = STAMP_RE.match(text[0]) if text else None
            stamped = (int(stamp.group(1)), int(stamp.group(2))) if stamp else None
            if key in awaiting:
                if current and stamped == current:
                    problems.append(f"{rel}:{lineno}: block {name} carries the current version "
                                    f"{current[0]}.{current[1]}: take it off AWAITING_REGENERATION")
                continue
            if not text:
                problems.append(f"{rel}:{lineno}: block {name} is empty (regenerate it with its docs/tools script)")
            elif not stamp:
                problems.append(f"{rel}:{lineno}: block {name} starts without the stamp \"Measured with "
                                f"vista X.Y.Z (commit ...) on ...\" (docs/tools/lib.sh doc_stamp)")
            elif len(text) < 2:
                problems.append(f"{rel}:{lineno}: block {name} holds only its stamp")
            elif current is None:
                problems.append(f"{rel}:{lineno}: block {name}: no project(vista VERSION ...) in CMakeLists.txt "
                                "to compare its stamp with")
            elif stamped != current:
                problems.append(f"{rel}:{lineno}: block {name} was measured with vista "
                                f"{'.'.join(stamp.groups())}, the current version is {current[0]}.{current[1]}: "
                                "regenerate it (docs/tools/regenerate_all.sh)")
    for key in sorted(set(awaiting) - seen):
        problems.append(f"{key[0]}: AWAITING_REGENERATION lists block {key[1]}, which the page does not have")


def doc_files(root):
    files = [os.path.join(root, f) for f in ("README.md", "CHANGELOG.md")
             if os.path.exists(os.path.join(root, f))]
    for base, dirs, names in os.walk(os.path.join(root, "docs")):
        dirs.sort()
        files += [os.path.join(base, n) for n in sorted(names) if n.endswith(".md")]
    return files


def check(root, vista, awaiting=None):
    root = os.path.abspath(root)
    awaiting = AWAITING_REGENERATION if awaiting is None else awaiting
    commands, top_flags = vista_help(vista)
    docs = [Doc(p) for p in doc_files(root)]
    docs_by_path = {d.path: d for d in docs}
    problems = []
    for doc in docs:
        rel = os.path.relpath(doc.path, root)
        check_links(doc, rel, docs_by_path, problems)
        check_headings(doc, rel, problems)
        check_commands(doc, rel, commands, top_flags, problems)
        check_phrases(doc, rel, problems)
        check_quoted_sizes(doc, rel, problems)
    measured = [d for d in docs
                if os.path.relpath(d.path, root).startswith(os.path.join("docs", "measurements") + os.sep)]
    check_blocks(measured, root, awaiting, problems)
    return docs, commands, problems


def stamp_writer_agrees(vista):
    """docs/tools/lib.sh's doc_stamp, run with the built tool at a quiet and at a busy start, writes
    lines STAMP_RE reads, with the tool's version, marked under load only when busy."""
    lib = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "docs", "tools", "lib.sh")
    version = subprocess.run([vista, "--version"], stdout=subprocess.PIPE, text=True).stdout.split()[-1]
    failures = []
    for load, busy in (("0.10 0.20 0.30", False), ("3.50 2.00 1.00", True)):
        r = subprocess.run(["bash", "-c", 'set -euo pipefail; source "$0"; DOC_NAME=self-test; VISTA="$1"; '
                            'REPO="$(dirname "$0")/../.."; DOC_START_LOAD="$2"; doc_stamp', lib, vista, load],
                           stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        line = r.stdout.strip()
        m = STAMP_RE.match(line)
        if r.returncode != 0 or not m:
            failures.append(f"doc_stamp at load {load} wrote {line!r}, which STAMP_RE does not read")
        elif ".".join(m.groups()) != version:
            failures.append(f"doc_stamp names version {'.'.join(m.groups())}, the tool says {version}")
        elif line.startswith("**Measured under load**") != busy:
            failures.append(f"doc_stamp at load {load}: under-load mark {'missing' if busy else 'wrong'}: {line!r}")
    return failures


def self_test(vista):
    """The check must find each planted problem and pass a clean tree."""
    commands, _ = vista_help(vista)
    cmd = sorted(commands)[0]
    flag = sorted(commands[cmd] - {"--help"})[0] if len(commands[cmd]) > 1 else "--help"
    stamp = ("Measured with vista 3.4.0 (commit 0123456789) on Some CPU, 2 cores, 8 GB RAM; load average at "
             "the start 0.1, 0.1, 0.1 (1, 5, 15 min), at the end 1.0, 0.5, 0.2.")
    index, measured, guide = "index.md", os.path.join("measurements", "m.md"), os.path.join("guide", "g.md")
    planted = {
        "missing file": (index, "[a](guide/nowhere.md)"),
        "missing anchor": (index, "[b](other.md#no-such-heading)"),
        "missing image": (index, "![c](img/none.png)"),
        "unknown command": (index, "`vista no-such-command`"),
        "unknown flag": (index, f"`vista {cmd} --no-such-flag-anywhere`"),
        "issue heading": (index, "## " + "Issue" + " 7: a diary"),
        "date heading": (index, "## Run of " + "-".join(["2031", "01", "02"])),
        "team note": (index, "Before" + " you stop, run the guard."),
        "rows run by hand": (index, "The rows were run twice more " + "by hand."),
        "one machine's binary": (index, "`docs/tools/x.sh OUT " + "vista2`"),
        "this machine in the guide": (guide, "What it costs on " + "this machine."),
        "empty block": (measured, "<!-- e:begin -->\n<!-- e:end -->"),
        "unstamped block": (measured, "<!-- u:begin -->\n| a |\n<!-- u:end -->"),
        "stale block": (measured, "<!-- s:begin -->\n" + stamp.replace("3.4.0", "3.3.9") + "\n\n| a |\n<!-- s:end -->"),
        "stamp only": (measured, "<!-- o:begin -->\n" + stamp + "\n<!-- o:end -->"),
        "unbalanced block": (measured, "<!-- b:begin -->\n| a |"),
        "a city's size quoted twice": (guide, "The 2 km city (`vista gen --size 2000`): 6.73 M rendered triangles."),
    }
    clean = {
        index: (f"# Title\n\n[ok](other.md#a-heading) [self](#title) `vista {cmd} {flag}`\n\n"
                f"```\nvista {cmd} {flag} \\\n    {flag}   # vista {cmd} --anything-in-a-comment\n"
                f"xvfb-run -a -s \"-screen 0 64x64x24\" build/vista {cmd} {flag}\n"
                f"docs/tools/some_script.sh OUT build/vista --not-a-vista-flag\n```\n\n"
                f"Outside the guide, a page may name the machine it ran on: this machine.\n"),
        measured: (f"# Measured\n\n<!-- good:begin -->\n{stamp}\n\n| a |\n<!-- good:end -->\n\n"
                   f"<!-- loaded:begin -->\n**Measured under load** (1-minute load average 2.0 at the start, "
                   f"above 0.5: other work shared the cores): {stamp}\n\n| a |\n<!-- loaded:end -->\n"),
        guide: "# Guide\n\nThe figures of the measured machine are in the measurement pages.\n",
    }
    # (awaiting list, what it plants)
    awaiting_cases = {
        "an awaiting block that carries the current version": {("docs/measurements/m.md", "good"): "planted"},
        "an awaiting block that the page lacks": {("docs/measurements/m.md", "gone"): "planted"},
    }
    failures = []

    def write_tree(tmp, extra=None):
        for rel, text in clean.items():
            with open(os.path.join(tmp, "docs", rel), "w") as f:
                f.write(text + ("\n" + extra[1] + "\n" if extra and extra[0] == rel else ""))

    with tempfile.TemporaryDirectory() as tmp:
        for d in ("docs/measurements", "docs/guide"):
            os.makedirs(os.path.join(tmp, d))
        with open(os.path.join(tmp, "CMakeLists.txt"), "w") as f:
            f.write("project(vista VERSION 3.4.1 LANGUAGES CXX)\n")
        with open(os.path.join(tmp, "docs", "other.md"), "w") as f:
            f.write("# Other\n\n## A heading\n")
        for what, extra in planted.items():
            write_tree(tmp, extra)
            _, _, problems = check(tmp, vista, awaiting={})
            if len(problems) != 1:
                failures.append(f"planted {what} ({extra[1]!r}): expected 1 problem, got {problems}")
        write_tree(tmp)
        for what, awaiting in awaiting_cases.items():
            _, _, problems = check(tmp, vista, awaiting=awaiting)
            if len(problems) != 1:
                failures.append(f"planted {what}: expected 1 problem, got {problems}")
        _, _, problems = check(tmp, vista, awaiting={})
        if problems:
            failures.append(f"clean tree: expected no problem, got {problems}")
        write_tree(tmp, planted["stale block"])
        _, _, problems = check(tmp, vista, awaiting={("docs/measurements/m.md", "s"): "listed"})
        if problems:
            failures.append(f"a stale block listed as awaiting regeneration: expected no problem, got {problems}")
    failures += stamp_writer_agrees(vista)
    for f in failures:
        print(f"check_docs self-test: {f}")
    if failures:
        return 1
    print(f"check_docs self-test: {len(planted) + len(awaiting_cases)} planted problems found, "
          "the clean tree passes")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--root", help="the source tree (holds README.md and docs/)")
    ap.add_argument("--vista", required=True, help="the built vista binary")
    ap.add_argument("--self-test", action="store_true")
    args = ap.parse_args()
    if not os.access(args.vista, os.X_OK):
        sys.exit(f"check_docs: {args.vista} is not an executable (build the `vista` target first)")
    if args.self_test:
        return self_test(args.vista)
    if not args.root:
        ap.error("--root is required")
    docs, commands, problems = check(args.root, args.vista)
    for p in problems:
        print(p)
    if problems:
        print(f"check_docs: {len(problems)} problem(s) in {len(docs)} files")
        return 1
    print(f"check_docs: {len(docs)} files, links, headings and `vista` commands "
          f"({len(commands)} commands) all fine")
    return 0


if __name__ == "__main__":
    sys.exit(main())
