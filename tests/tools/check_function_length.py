#!/usr/bin/env python3
"""Lists every function longer than the limit (120 lines) in vista's sources.

Scans the .cpp and .h files under the rooms' folders (foundation, citygen,
runtime, nodes, bake, cmd); test files (tests/, test_*) are not scanned. A
function's length counts the lines from the first line of its signature to its
closing brace. The scan blanks comments, string and character literals and
preprocessor lines, then matches braces: a brace at namespace or class scope
opens a function body when the text before it has a parameter list and no
top-level '=' (which marks a data initializer). Braces of a constructor's member
initializers (`_a{a}`) belong to the signature. Lambdas and local classes count
toward the function that holds them.

Prints `path:line: name is N lines (limit L)` for each long function and exits 1
if there is one; exits 0 with a one-line summary otherwise. `--self-test` plants
functions in a scratch tree and fails unless the scan measures them right.

Usage: check_function_length.py [--limit N] SOURCE_DIR
       check_function_length.py --self-test
"""
import os
import re
import sys
import tempfile

ROOM_FOLDERS = ["foundation", "citygen", "runtime", "nodes", "bake", "cmd"]
EXTENSIONS = (".cpp", ".h", ".hpp", ".cc")
DEFAULT_LIMIT = 120


def blank_non_code(text):
    """Returns text with comments, literals and preprocessor lines replaced by
    spaces; newlines stay, so offsets and line numbers are unchanged."""
    out = list(text)
    i, n = 0, len(text)
    at_line_start = True

    def blank(a, b):
        for k in range(a, b):
            if out[k] != "\n":
                out[k] = " "

    while i < n:
        c = text[i]
        if c == "\n":
            at_line_start = True
            i += 1
            continue
        if c in " \t\r":
            i += 1
            continue
        if at_line_start and c == "#":  # preprocessor line, with continuations
            j = i
            while j < n and not (text[j] == "\n" and text[j - 1] != "\\"):
                if text.startswith("/*", j):  # a block comment may span lines
                    end = text.find("*/", j + 2)
                    j = n if end < 0 else end + 2
                    continue
                j += 1
            blank(i, j)
            i = j
            continue
        at_line_start = False
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            blank(i, j)
            i = j
        elif text.startswith("/*", i):
            j = text.find("*/", i + 2)
            j = n if j < 0 else j + 2
            blank(i, j)
            i = j
        elif c == "R" and text.startswith('"', i + 1) and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
            m = re.match(r'R"([^()\\\s]{0,16})\(', text[i:])
            if not m:
                i += 1
                continue
            end = text.find(")" + m.group(1) + '"', i + m.end())
            j = n if end < 0 else end + len(m.group(1)) + 2
            blank(i + 1, j)
            i = j
        elif c == '"' or (c == "'" and not (i > 0 and (text[i - 1].isalnum()))):
            # a ' after a digit or letter is a digit separator (1'000) or part of u8'x'
            j = i + 1
            while j < n and text[j] != c and text[j] != "\n":
                j += 2 if text[j] == "\\" else 1
            blank(i + 1, min(j, n))
            i = j + 1
        else:
            i += 1
    return "".join(out)


def top_level(header):
    """Returns header as a list of (char, depth), where depth counts the ()
    and [] that enclose the char."""
    depth = 0
    result = []
    for ch in header:
        if ch in "([":
            depth += 1
        elif ch in ")]":
            depth = max(0, depth - 1)
        result.append((ch, depth))
    return result


def classify(header):
    """Returns 'scope' (namespace, class, extern block), 'function' or 'data'
    for the text that precedes an opening brace at namespace or class scope."""
    h = " ".join(header.split())
    if re.search(r"\bnamespace\b", h) or re.match(r'^extern\s*""$', h) or re.match(r"^extern\s+\"", h):
        return "scope"
    flat = "".join(ch if d == 0 else "" for ch, d in top_level(h))
    if "(" not in h:
        if re.search(r"\b(class|struct|union|enum)\b", h) and "=" not in flat:
            return "scope"
        return "data"
    no_operator = re.sub(r"\boperator\s*(==|!=|<=|>=|=|[-+*/%^&|<>!]=?)", "operator", flat)
    if "=" in no_operator:
        return "data"
    if re.search(r"\b(class|struct|union|enum)\b", flat) and not flat.rstrip().endswith(")") and ")" not in flat:
        return "scope"
    return "function"


def function_name(header):
    """Returns the qualified name before the parameter list of a signature."""
    h = " ".join(header.split())
    m = re.search(r"(operator\s*\(\s*\)|operator\s*[^\s(]+|~?[A-Za-z_][\w:<>,~ ]*?)\s*\(", h)
    if not m:
        return h[:60]
    name = m.group(1).strip()
    return name.split(" ")[-1] if not name.startswith("operator") else name


def in_initializer_list(header):
    """True when the signature so far ends in a constructor's member
    initializer list (a ':' after the parameter list), so that a brace after
    a member name initializes the member rather than opening the body."""
    h = " ".join(header.split())
    depth = 0
    closed = False
    i = 0
    while i < len(h):
        ch = h[i]
        if ch == "(":
            depth += 1
        elif ch == ")":
            depth -= 1
            if depth == 0:
                closed = True
        elif depth == 0 and closed and ch == ":":
            if h.startswith("::", i):
                i += 2
                continue
            return True
        i += 1
    return False


def scan_file(path):
    with open(path, encoding="utf-8", errors="replace") as f:
        return list(find_functions(f.read()))


def find_functions(text):
    """Yields (start_line, end_line, name) for each function body at namespace
    or class scope in source text."""
    code = blank_non_code(text)
    line_of = []
    line = 1
    for ch in code:
        line_of.append(line)
        if ch == "\n":
            line += 1
    stack = []
    header_start = 0
    i, n = 0, len(code)
    while i < n:
        ch = code[i]
        outer = not stack or stack[-1][0] == "scope"
        if ch == "{" and outer:
            header = code[header_start:i]
            stripped = header.rstrip()
            prev = stripped[-1:] if stripped else ""
            if in_initializer_list(header) and (prev.isalnum() or prev in "_>"):
                depth = 0
                while i < n:
                    if code[i] == "{":
                        depth += 1
                    elif code[i] == "}":
                        depth -= 1
                        if depth == 0:
                            break
                    i += 1
                i += 1
                continue
            kind = classify(header)
            if kind == "function":
                offset = header_start + (len(header) - len(header.lstrip()))
                stack.append(("function", line_of[min(offset, n - 1)], function_name(header)))
            else:
                stack.append((kind,))
                header_start = i + 1
        elif ch == "{":
            stack.append(("inner",))
        elif ch == "}":
            if stack:
                opened = stack.pop()
                if opened[0] == "function":
                    yield opened[1], line_of[i], opened[2]
                if not stack or stack[-1][0] == "scope":
                    header_start = i + 1
        elif ch == ";" and outer:
            header_start = i + 1
        elif ch == ":" and outer and re.match(r"\s*(public|private|protected)\s*$", code[header_start:i]):
            header_start = i + 1
        i += 1


def source_files(root):
    for folder in ROOM_FOLDERS:
        base = os.path.join(root, folder)
        for dirpath, dirnames, filenames in os.walk(base):
            dirnames[:] = sorted(d for d in dirnames if d not in ("tests", "test"))
            for name in sorted(filenames):
                if name.endswith(EXTENSIONS) and not name.startswith("test_"):
                    yield os.path.join(dirpath, name)


def long_functions(root, limit):
    found = []
    for path in source_files(root):
        for start, end, name in scan_file(path):
            length = end - start + 1
            if length > limit:
                found.append((os.path.relpath(path, root), start, name, length))
    return found


def self_test():
    """Plants functions of known length in a scratch tree; fails unless the
    scan reports exactly the long ones."""
    def body(lines):
        return "".join("  x += %d;\n" % k for k in range(lines))

    source = (
        "#include <vector>\n"
        "#define BRACE {\n"
        "namespace vista {\n"
        "namespace {\n"
        "const int kTable[] = {1, 2, 3};\n"
        "// a comment with a { brace\n"
        "int shortOne(int x) {\n" + body(118) + "}\n"          # 120 lines: allowed
        "int longOne(int x) {\n" + body(119) + "}\n"           # 121 lines: reported
        "}  // namespace\n"
        "struct Holder {\n"
        "  Holder(int a) : _a{a}, _b(a) {\n" + body(119) + "  }\n"  # 121 lines: reported
        "  int member() const {\n"
        "    const char* s = \"}}}\"; char c = '{';\n"
        "    return 0;\n"
        "  }\n"
        "  int _a, _b;\n"
        "};\n"
        "int spanning(\n    int x)\n{\n" + body(110) + "  /* } */\n  auto f = [] { return 1; };\n}\n"
        "}  // namespace vista\n"
    )
    with tempfile.TemporaryDirectory() as tmp:
        os.makedirs(os.path.join(tmp, "citygen"))
        os.makedirs(os.path.join(tmp, "runtime"))
        with open(os.path.join(tmp, "citygen", "planted.cpp"), "w") as f:
            f.write(source)
        with open(os.path.join(tmp, "runtime", "test_planted.cpp"), "w") as f:
            f.write("void testLong() {\n" + body(200) + "}\n")
        found = long_functions(tmp, DEFAULT_LIMIT)
        measured = {name: length for _, _, name, length in found}
        expected = {"longOne": 121, "Holder": 121}
        all_found = {name: end - start + 1 for start, end, name in scan_file(os.path.join(tmp, "citygen", "planted.cpp"))}
    ok = measured == expected and all_found.get("shortOne") == 120 and all_found.get("member") == 4 \
        and all_found.get("spanning") == 116
    if not ok:
        print("self-test failed: long %s (expected %s), all %s" % (measured, expected, all_found))
        return 1
    print("self-test passed: the scan measures planted functions and skips test files")
    return 0


def main(argv):
    args = argv[1:]
    if args == ["--self-test"]:
        return self_test()
    limit = DEFAULT_LIMIT
    if len(args) >= 2 and args[0] == "--limit":
        if not args[1].isdigit() or int(args[1]) < 1:
            print("--limit must be a whole number of lines >= 1, got %r" % args[1], file=sys.stderr)
            return 2
        limit = int(args[1])
        args = args[2:]
    if len(args) != 1 or not os.path.isdir(args[0]):
        print(__doc__.strip().splitlines()[-2].strip(), file=sys.stderr)
        return 2
    found = long_functions(args[0], limit)
    for path, line, name, length in found:
        print("%s:%d: %s is %d lines (limit %d)" % (path, line, name, length, limit))
    if found:
        print("%d function(s) over %d lines" % (len(found), limit))
        return 1
    print("no function over %d lines" % limit)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))
