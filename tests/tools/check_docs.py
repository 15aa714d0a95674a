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

Prints every problem as FILE:LINE: message and exits 1 if there is one;
exits 0 with a one-line summary otherwise.

Usage: check_docs.py --root SOURCE_DIR --vista VISTA_BINARY
       check_docs.py --self-test --vista VISTA_BINARY
  (--self-test writes a small broken docs tree into a temporary directory and
   fails unless the check finds each planted problem, then checks a clean one)
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


def doc_files(root):
    files = [os.path.join(root, f) for f in ("README.md", "CHANGELOG.md")
             if os.path.exists(os.path.join(root, f))]
    for base, dirs, names in os.walk(os.path.join(root, "docs")):
        dirs.sort()
        files += [os.path.join(base, n) for n in sorted(names) if n.endswith(".md")]
    return files


def check(root, vista):
    root = os.path.abspath(root)
    commands, top_flags = vista_help(vista)
    docs = [Doc(p) for p in doc_files(root)]
    docs_by_path = {d.path: d for d in docs}
    problems = []
    for doc in docs:
        rel = os.path.relpath(doc.path, root)
        check_links(doc, rel, docs_by_path, problems)
        check_headings(doc, rel, problems)
        check_commands(doc, rel, commands, top_flags, problems)
    return docs, commands, problems


def self_test(vista):
    """The check must find each planted problem and pass a clean tree."""
    commands, _ = vista_help(vista)
    cmd = sorted(commands)[0]
    flag = sorted(commands[cmd] - {"--help"})[0] if len(commands[cmd]) > 1 else "--help"
    planted = {
        "missing file": "[a](guide/nowhere.md)",
        "missing anchor": "[b](other.md#no-such-heading)",
        "missing image": "![c](img/none.png)",
        "unknown command": "`vista no-such-command`",
        "unknown flag": f"`vista {cmd} --no-such-flag-anywhere`",
        "issue heading": "## " + "Issue" + " 7: a diary",
        "date heading": "## Run of " + "-".join(["2031", "01", "02"]),
    }
    clean = (f"# Title\n\n[ok](other.md#a-heading) [self](#title) `vista {cmd} {flag}`\n\n"
             f"```\nvista {cmd} {flag} \\\n    {flag}   # vista {cmd} --anything-in-a-comment\n"
             f"xvfb-run -a -s \"-screen 0 64x64x24\" build/vista {cmd} {flag}\n"
             f"docs/tools/some_script.sh OUT build/vista --not-a-vista-flag\n```\n")
    failures = []
    with tempfile.TemporaryDirectory() as tmp:
        os.makedirs(os.path.join(tmp, "docs"))
        with open(os.path.join(tmp, "docs", "other.md"), "w") as f:
            f.write("# Other\n\n## A heading\n")
        index = os.path.join(tmp, "docs", "index.md")
        for what, text in planted.items():
            with open(index, "w") as f:
                f.write(clean + "\n" + text + "\n")
            _, _, problems = check(tmp, vista)
            if len(problems) != 1:
                failures.append(f"planted {what} ({text!r}): expected 1 problem, got {problems}")
        with open(index, "w") as f:
            f.write(clean)
        _, _, problems = check(tmp, vista)
        if problems:
            failures.append(f"clean tree: expected no problem, got {problems}")
    for f in failures:
        print(f"check_docs self-test: {f}")
    if failures:
        return 1
    print(f"check_docs self-test: {len(planted)} planted problems found, the clean tree passes")
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
