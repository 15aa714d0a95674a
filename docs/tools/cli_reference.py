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
out.append("files, an option given with an empty value such as `--rig \"\"`) exit with code 2 and a")
out.append("message naming the option, the value and the allowed range, and leave no partial output.")
out.append("")
out.append("| exit code | meaning |")
out.append("|---|---|")
out.append("| 0 | success |")
out.append("| 1 | the environment: no X display for a command that draws, or an internal failure |")
out.append("| 2 | bad input (options, files, paths, values), named in the message; nothing written |")
out.append("")
out.append("Rendering commands (`bench`, `view`, `render` without `--rig`) need an X display: without")
out.append("one (DISPLAY unset) they exit with code 1 before any work; on a machine without a screen run")
out.append("them under `xvfb-run -a` (Mesa llvmpipe works). `--frames` of `bench` and `render` (and of")
out.append("`view` with `--step`) is at most the path's sample count unless `--allow-repeated-frames`")
out.append("asks for samples rendered more than once; `--lht` applies to car paths made from a seed.")
out.append("How to use the commands together: [the guide](../guide/README.md).")
out.append("")
out.append('Files: no two outputs of one command may be the same file, and no output may be one of')
out.append('its inputs (compared after symlinks, `.` and `..`, and by device and inode where both')
out.append('exist): such a run is refused before anything is read or written, naming both options.')
out.append('`gen`, `bake`, `path` and `export` write all of their output files or none. Input files are read up to a stated')
out.append('limit per kind (parameter file 1 MiB, `--effects` value 64 KiB, path CSV 256 MiB, paged')
out.append('city manifest 64 MiB, ray set 1 GiB, OSM extract 8 GiB), and a device, pipe or directory')
out.append('where a file is expected is refused with a message that says so.')
out.append('')
out.append('Paths are resolved before any work: an input or output that is a symbolic link loop or')
out.append('a dangling link, or an output whose directory does not exist or cannot be reached, is')
out.append('refused with exit code 2 naming the option. An output that is a character or block device')
out.append('or a FIFO (`-o /dev/null`, a named pipe) is written in place and never replaced by a')
out.append('regular file; a failed write into it (`/dev/full`: "No space left on device") exits with')
out.append('code 2 naming the cause. A directory output (`--out`, `--work`, a paged city) refuses a')
out.append('device or pipe, and a socket is refused as any output. One writer per output: before any')
out.append('work a command locks each output it writes (an empty `OUTPUT.lock` beside it, removed when')
out.append('the command ends; one left by a killed run is taken over), and a second vista process')
out.append('writing the same output exits with code 2 at once, naming the lock file. The shards of one')
out.append('paged `gen` or one `bake` share the locks; an unsharded run or a merge holds them alone.')
out.append('')
out.append('Numbers, on the command line and in JSON and CSV files, follow one set of rules:')
out.append('integers are decimal (no sign where the range has no negatives, no hex, no fraction)')
out.append('and never wrap (`--seed -1` and `--seed 18446744073709551616` are refused); reals are')
out.append('decimal and finite; a value out of range is refused with the range and the text as')
out.append('written. Text echoed in a message is cut to 80 characters.')
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
