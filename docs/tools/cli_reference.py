#!/usr/bin/env python3
"""Writes docs/reference/cli.md from the built tool's own help: `vista help`
and `vista <command> --help` for every command it lists, so the page names
every command and flag exactly as the binary accepts them.

usage: docs/tools/cli_reference.py [VISTA_BIN] > docs/reference/cli.md
  VISTA_BIN defaults to build/vista. Takes a second.
"""
import re
import subprocess
import sys

vista = sys.argv[1] if len(sys.argv) > 1 else "build/vista"


def run(args):
    r = subprocess.run([vista] + args, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    return r.stdout.rstrip("\n")


top = run(["help"])
commands = []
for line in top.split("\n"):
    m = re.match(r"^\s{2,}([a-z][a-z0-9-]*)\s{2,}(\S.*)$", line)
    if m and m.group(1) != "help":
        commands.append((m.group(1), m.group(2)))
if not commands:
    sys.exit(f"cli_reference: `{vista} help` listed no commands")

out = []
out.append("# Command line: `vista`")
out.append("")
out.append("Every command and option of the `vista` executable (built as `build/vista`), as the")
out.append("tool itself prints them. Regenerate this page with")
out.append("`docs/tools/cli_reference.py build/vista > docs/reference/cli.md`.")
out.append("")
out.append("Conventions shared by every command: bad values (out of range, malformed, missing")
out.append("files) exit with code 2 and a message naming the option, the value and the allowed")
out.append("range, and leave no partial output; a missing display exits with code 1. Rendering")
out.append("commands (`bench`, `view`, `render`) need an X display: on a machine without one run")
out.append("them under `xvfb-run -a` (Mesa llvmpipe works). How to use the commands together:")
out.append("[the guide](../guide/README.md).")
out.append("")
out.append("| command | what it does |")
out.append("|---|---|")
for name, what in commands:
    out.append(f"| [`vista {name}`](#vista-{name}) | {what.replace('|', '/')} |")
out.append("")
out.append("```")
out.append(top)
out.append("```")
for name, _ in commands:
    out.append("")
    out.append(f"## vista {name}")
    out.append("")
    out.append("```")
    out.append(run([name, "--help"]))
    out.append("```")
print("\n".join(out))
