#!/usr/bin/env python3
"""The largest Rust files and functions of the workspace (lines, tests included in files, `fn`
bodies brace-matched, comments and strings skipped while matching).

Usage: scripts/sizes.py [N] [--over LINES]   (top N of each, default 15; --over lists every
function longer than LINES and exits 1 when there is one)
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DIRS = ["src", "lab/src", "cli/src", "build.rs"]
FN = re.compile(r"^\s*(?:pub(?:\([a-z]+\))?\s+)?(?:const\s+)?(?:unsafe\s+)?fn\s+([A-Za-z0-9_]+)")


def files():
    for d in DIRS:
        p = os.path.join(ROOT, d)
        if os.path.isfile(p):
            yield p
        for dirpath, _, names in os.walk(p):
            for n in names:
                if n.endswith(".rs"):
                    yield os.path.join(dirpath, n)


def code_only(line, state):
    """The line with comments and string contents removed; `state` carries a block comment."""
    out, i = [], 0
    while i < len(line):
        if state["block"]:
            j = line.find("*/", i)
            if j < 0:
                return "".join(out)
            state["block"], i = False, j + 2
        elif line.startswith("//", i):
            break
        elif line.startswith("/*", i):
            state["block"], i = True, i + 2
        elif line[i] == '"':
            j = i + 1
            while j < len(line) and line[j] != '"':
                j += 2 if line[j] == "\\" else 1
            i = j + 1
        elif line[i] == "'" and i + 2 < len(line) and (line[i + 2] == "'" or line[i + 1] == "\\"):
            j = line.find("'", i + 2)
            i = (j + 1) if j > 0 else i + 1
        else:
            out.append(line[i])
            i += 1
    return "".join(out)


def functions(path):
    lines = open(path, encoding="utf-8").read().split("\n")
    state = {"block": False}
    code = [code_only(l, state) for l in lines]
    out = []
    for i, l in enumerate(code):
        m = FN.match(l)
        if not m:
            continue
        depth, opened = 0, False
        for j in range(i, len(code)):
            for ch in code[j]:
                if ch == "{":
                    depth, opened = depth + 1, True
                elif ch == "}":
                    depth -= 1
                elif ch == ";" and not opened and depth == 0:
                    break
            else:
                if opened and depth == 0:
                    out.append((j - i + 1, m.group(1), i + 1))
                    break
                continue
            break
    return out


def main():
    args = sys.argv[1:]
    over = None
    if "--over" in args:
        k = args.index("--over")
        over = int(args[k + 1])
        del args[k : k + 2]
    n = int(args[0]) if args else 15
    rel = lambda p: os.path.relpath(p, ROOT)
    sizes = sorted(((len(open(f).read().split("\n")) - 1, rel(f)) for f in files()), reverse=True)
    fns = sorted(((ln, f"{rel(f)}:{at} {name}") for f in files() for ln, name, at in functions(f)), reverse=True)
    print(f"{sum(s for s, _ in sizes)} lines in {len(sizes)} files; {len(fns)} functions")
    print("largest files:")
    for s, f in sizes[:n]:
        print(f"  {s:5} {f}")
    print("longest functions:")
    for s, f in fns[:n]:
        print(f"  {s:5} {f}")
    if over is not None:
        long = [(s, f) for s, f in fns if s > over]
        print(f"{len(long)} functions over {over} lines")
        for s, f in long:
            print(f"  {s:5} {f}")
        return 1 if long else 0
    return 0


if __name__ == "__main__":
    sys.exit(main())
