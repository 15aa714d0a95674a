#!/usr/bin/env python3
"""Fails when docs/reference/python.md differs from what docs/tools/python_reference.py
makes of the built module's docstrings, printing the first differences.

usage: check_python_reference.py ROOT (with PYTHONPATH holding the built module)
"""
import difflib
import subprocess
import sys

root = sys.argv[1]
made = subprocess.run([sys.executable, f"{root}/docs/tools/python_reference.py"], check=True,
                      stdout=subprocess.PIPE, text=True).stdout
with open(f"{root}/docs/reference/python.md", encoding="utf-8") as f:
    page = f.read()
if made != page:
    diff = list(difflib.unified_diff(page.splitlines(), made.splitlines(), "docs/reference/python.md",
                                     "the module's docstrings", lineterm="", n=0))
    print("\n".join(diff[:40]))
    sys.exit("docs/reference/python.md is not the module's docstrings; regenerate it: "
             "PYTHONPATH=build/python python3 docs/tools/python_reference.py > docs/reference/python.md")
print("docs/reference/python.md is the module's docstrings")
