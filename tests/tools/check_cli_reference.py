#!/usr/bin/env python3
"""Fails when docs/reference/cli.md differs from what docs/tools/cli_reference.py
makes of the built tool's help, printing the first differences.

usage: check_cli_reference.py ROOT VISTA_BIN
"""
import difflib
import subprocess
import sys

root, vista = sys.argv[1], sys.argv[2]
made = subprocess.run([sys.executable, f"{root}/docs/tools/cli_reference.py", vista], check=True,
                      stdout=subprocess.PIPE, text=True).stdout
with open(f"{root}/docs/reference/cli.md", encoding="utf-8") as f:
    page = f.read()
if made != page:
    diff = list(difflib.unified_diff(page.splitlines(), made.splitlines(), "docs/reference/cli.md", "the tool's help",
                                     lineterm="", n=0))
    print("\n".join(diff[:40]))
    sys.exit("docs/reference/cli.md is not the tool's help; regenerate it: "
             "python3 docs/tools/cli_reference.py build/vista > docs/reference/cli.md")
print("docs/reference/cli.md is the tool's help")
