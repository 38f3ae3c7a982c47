#!/usr/bin/env python3
"""The largest Rust files and functions of the workspace (lines, tests included in files, `fn`
bodies brace-matched, comments and strings skipped while matching).

Usage: scripts/sizes.py [N] [--over LINES]   (top N of each, default 15; --over lists every
function longer than LINES and exits 1 when there is one)
       scripts/sizes.py --figures               (lines per crate, files and functions over the
                                                 thresholds, `unsafe` blocks per folder)
       scripts/sizes.py --gate FILE_MAX FN_MAX  (the figures; exit 1 when a source file has more
                                                 than FILE_MAX lines or a function more than FN_MAX)
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
DIRS = ["src", "lab/src", "cli/src", "python/src", "build.rs"]
CRATES = [("umbra", ["src", "build.rs"]), ("umbra-lab", ["lab/src"]), ("umbra-cli", ["cli/src"]), ("umbra-python", ["python/src"])]
TESTS = ["tests", "lab/tests", "cli/tests", "examples"]
UNSAFE = re.compile(r"\bunsafe\s*\{")
FN = re.compile(r"^\s*(?:pub(?:\([a-z]+\))?\s+)?(?:const\s+)?(?:unsafe\s+)?fn\s+([A-Za-z0-9_]+)")


def files(dirs=None):
    for d in dirs or DIRS:
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


def line_count(f):
    return len(open(f, encoding="utf-8").read().split("\n")) - 1


def unsafe_blocks(f):
    state = {"block": False}
    return sum(len(UNSAFE.findall(code_only(l, state))) for l in open(f, encoding="utf-8"))


def figures(file_max=None, fn_max=None):
    rel = lambda p: os.path.relpath(p, ROOT)
    print("lines per crate (sources; tests apart):")
    for crate, dirs in CRATES:
        fs = list(files(dirs))
        print(f"  {crate:13} {sum(line_count(f) for f in fs):6} lines in {len(fs):3} files")
    ts = list(files(TESTS))
    print(f"  {'tests':13} {sum(line_count(f) for f in ts):6} lines in {len(ts):3} files")
    sizes = [(line_count(f), rel(f)) for f in files()]
    fns = [(ln, f"{rel(f)}:{at} {name}") for f in files() for ln, name, at in functions(f)]
    for t in (600, 800):
        print(f"source files over {t} lines: {sum(1 for s, _ in sizes if s > t)}")
    for t in (80, 100, 120):
        print(f"functions over {t} lines: {sum(1 for s, _ in fns if s > t)}")
    print("unsafe blocks per folder:")
    per = {}
    for f in files():
        n = unsafe_blocks(f)
        if n:
            d = os.path.dirname(rel(f)) or "."
            per[d] = per.get(d, 0) + n
    for d in sorted(per):
        print(f"  {per[d]:4} {d}")
    print(f"  {sum(per.values()):4} in all")
    bad = []
    if file_max is not None:
        bad += [f"{f}: {s} lines (gate {file_max})" for s, f in sorted(sizes, reverse=True) if s > file_max]
    if fn_max is not None:
        bad += [f"{f}: {s} lines (gate {fn_max})" for s, f in sorted(fns, reverse=True) if s > fn_max]
    for b in bad:
        print(f"over the gate: {b}")
    return 1 if bad else 0


def main():
    args = sys.argv[1:]
    if args[:1] == ["--figures"]:
        return figures()
    if args[:1] == ["--gate"]:
        return figures(int(args[1]), int(args[2]))
    over = None
    if "--over" in args:
        k = args.index("--over")
        over = int(args[k + 1])
        del args[k : k + 2]
    if any(a.startswith("-") for a in args) or (args and not args[0].isdigit()):
        print(__doc__.strip() if __doc__ else "usage: sizes.py [N] [--over L] | --figures | --gate FILE FN")
        return 2
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
