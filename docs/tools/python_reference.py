#!/usr/bin/env python3
"""Writes docs/reference/python.md from the Python module's docstrings (stdout).

usage: PYTHONPATH=build/python python3 docs/tools/python_reference.py > docs/reference/python.md
"""
import inspect
import sys

import vista

HEADER = """# Python module reference

Every class and function of the Python module `vista`, from its docstrings (regenerate with
`PYTHONPATH=build/python python3 docs/tools/python_reference.py > docs/reference/python.md`;
the test Docs.PythonReferenceIsCurrent fails when this page and the docstrings differ). How to use
them together: [the Python guide](../guide/python.md). Type stubs: `vista/__init__.pyi` beside the
module.
"""


def doc(obj):
    d = inspect.getdoc(obj) or ""
    return d.strip()


def signature(name, obj):
    try:
        return f"{name}{inspect.signature(obj)}"
    except (TypeError, ValueError):
        return name


def strip_self(sig):
    return sig.replace("(self, ", "(").replace("(self)", "()")


def member_lines(cls):
    out = []
    for name, member in cls.__dict__.items():
        if name.startswith("_") and name not in ("__getitem__", "__len__", "__iter__"):
            continue
        if isinstance(member, property):
            out.append((f"`{cls.__name__}.{name}` (property)", doc(member)))
        elif inspect.isfunction(member):
            out.append((f"`{cls.__name__}.{strip_self(signature(name, member))}`", doc(member)))
    return out


def pose_section():
    # Pose is a native class: its constructor and properties are listed by hand from its docstring.
    p = vista.Pose
    lines = ["## `Pose(position, heading=0.0, pitch=0.0, t=0.0)`", "", doc(p), ""]
    lines.append("Properties: `t`, `position` (x, y, z), `heading`, `pitch`. `Path[i]` gives one; "
                 "`Renderer.render` takes one.")
    return "\n".join(lines) + "\n"


def main():
    parts = [HEADER, "## Module", "", doc(vista), ""]
    for name in vista.__all__:
        obj = getattr(vista, name)
        if name == "Pose":
            parts.append(pose_section())
            continue
        if inspect.isclass(obj):
            init = obj.__dict__.get("__init__")
            head = strip_self(signature(name, init)) if init else name
            if "(native)" in head:  # made by generate / load / path, not by the caller
                head = name
            parts += [f"## `{head}`", "", doc(obj), ""]
            for title, text in member_lines(obj):
                if title.startswith(f"`{name}.__init__"):
                    continue
                parts += [f"### {title}", "", text or "(no docstring)", ""]
        else:
            parts += [f"## `{signature(name, obj)}`", "", doc(obj), ""]
    sys.stdout.write("\n".join(parts).rstrip() + "\n")


if __name__ == "__main__":
    main()
