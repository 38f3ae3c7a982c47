#!/usr/bin/env python3
"""The module import graph of umbra's crates: which file uses which (through `crate::`, `super::`,
`self::` and the other workspace crates' names), its import cycles (strongly connected components
of more than one module) and the edges that cross a layer the wrong way.

Usage: scripts/imports.py [--edges]   (exit status 1 when there is a cycle)
"""
import os
import re
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CRATES = {"umbra": "src", "umbra_lab": "lab/src", "umbra_cli": "cli/src"}


def modules(crate, src):
    """Map module path tuples (crate, a, b) to files."""
    out = {}
    base = os.path.join(ROOT, src)
    if not os.path.isdir(base):
        return out
    for dirpath, _, files in os.walk(base):
        for f in files:
            if not f.endswith(".rs"):
                continue
            rel = os.path.relpath(os.path.join(dirpath, f), base)[:-3].split(os.sep)
            if rel[-1] in ("mod", "lib", "main"):
                rel = rel[:-1]
            out[(crate, *rel)] = os.path.join(dirpath, f)
    return out


def resolve(mods, path):
    """Longest prefix of `path` that names a module file."""
    for n in range(len(path), 0, -1):
        if tuple(path[:n]) in mods:
            return tuple(path[:n])
    return None


PATH = re.compile(r"\b((?:crate|super|self|umbra|umbra_lab|umbra_cli)(?:::[A-Za-z_][A-Za-z0-9_]*)+)")
GROUP = re.compile(r"\b(crate|super|umbra|umbra_lab|umbra_cli)((?:::[a-z_][a-z0-9_]*)*)::\{([^;]*?)\};", re.S)


ITEM = re.compile(r"^pub\s+(?:struct|enum|fn|type|const|static|trait)\s+([A-Za-z_][A-Za-z0-9_]*)", re.M)
PUB_USE = re.compile(r"\bpub(?:\([a-z]+\))?\s+use\s+([^;]+);", re.S)


def absolute(mod, p):
    """The path `p` (split on ::) written in module `mod`, from its crate's root."""
    if p[0] == "crate":
        return [mod[0], *p[1:]]
    if p[0] == "super":
        ups = len(p) - len([x for x in p if x != "super"])
        return [*mod[: len(mod) - ups], *[x for x in p if x != "super"]]
    if p[0] == "self":
        return [*mod, *p[1:]]
    if p[0] in CRATES:
        return p
    # A path relative to the module itself (`pub use types::Scene;` in a mod.rs).
    return [*mod, *p]


def reexports(mods):
    """(module, name) -> the absolute path it re-exports (`pub use` lists and single items, and
    `pub use m::*` for the public items defined in m)."""
    out, globs = {}, {}
    for mod, f in mods.items():
        text = strip_comments(open(f, encoding="utf-8").read())
        for body in PUB_USE.findall(text):
            body = re.sub(r"\s+", "", body)
            m = re.match(r"^(.*?)::\{(.*)\}$", body)
            items = [(m.group(1), i) for i in m.group(2).split(",") if i] if m else [(body.rsplit("::", 1) + [""])[0:2]]
            for prefix, item in items:
                if item == "*":
                    globs.setdefault(mod, []).append(absolute(mod, prefix.split("::")))
                    continue
                if item == "self" or "{" in item:
                    continue
                alias = item.split(" as ")[-1].split("as")[-1] if " as " in item else item
                path = absolute(mod, prefix.split("::") + item.split(" as ")[0].split("::"))
                out[(mod, alias.split("::")[-1])] = path
    for mod, sources in globs.items():
        for src in sources:
            target = resolve(mods, src)
            if not target:
                continue
            text = strip_comments(open(mods[target], encoding="utf-8").read())
            for name in ITEM.findall(text):
                out.setdefault((mod, name), [*target, name])
    return out


def follow(mods, reexp, full):
    """The module `full` names, through re-exports: `crate::scene::Scene`, re-exported by
    scene/mod.rs from scene::types, is a use of scene::types."""
    for _ in range(8):
        target = resolve(mods, full)
        if not target or len(full) <= len(target):
            return target
        origin = reexp.get((target, full[len(target)]))
        if not origin:
            return target
        full = [*origin, *full[len(target) + 1 :]]
    return resolve(mods, full)


def strip_comments(text):
    text = re.sub(r"//[^\n]*", "", text)
    return re.sub(r"/\*.*?\*/", "", text, flags=re.S)


def main():
    mods = {}
    for crate, src in CRATES.items():
        mods.update(modules(crate, src))
    edges, code_edges = set(), set()
    reexp = reexports(mods)
    for mod, f in mods.items():
        text = strip_comments(open(f, encoding="utf-8").read())
        # Where a unit-test module starts (by convention the end of the file): the layering is
        # judged on the code before it, so a test may check a low layer with a higher one.
        test_at = re.search(r"#\[cfg\(test\)\]\s*mod tests\b", text)
        test_at = test_at.start() if test_at else len(text)
        paths = [(m.start(), m.group(1).split("::")) for m in PATH.finditer(text)]
        for g in GROUP.finditer(text):
            head, mid, body = g.groups()
            for item in re.split(r"[,\s{}]+", body):
                if item and item[0].islower():
                    paths.append((g.start(), [head, *[p for p in mid.split("::") if p], item.split("::")[0]]))
        for at, p in paths:
            target = follow(mods, reexp, absolute(mod, p))
            if target and target != mod and not (target == mod[: len(target)] and len(target) < len(mod)):
                # a module naming its own ancestor's re-export is not a dependency on a sibling
                if len(target) == 1 and target[0] == mod[0]:
                    continue
                edges.add((mod, target))
                if at < test_at:
                    code_edges.add((mod, target))
    # Tarjan's strongly connected components.
    graph = {m: sorted({t for s, t in edges if s == m}) for m in mods}
    index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph[v]:
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                comps.append(sorted(comp))

    sys.setrecursionlimit(10000)
    for m in sorted(mods):
        if m not in index:
            visit(m)
    name = lambda m: "::".join(m)
    if "--edges" in sys.argv:
        for s, t in sorted(edges):
            print(f"{name(s)} -> {name(t)}")
    print(f"{len(mods)} modules, {len(edges)} edges, {len(comps)} cycles")
    for c in comps:
        print("cycle: " + ", ".join(name(m) for m in c))
    bad = [(s, t) for s, t in edges if s[1:2] == ("reference",) and t[1:2] == ("render",)]
    bad += [(s, t) for s, t in edges if s[0] == "umbra" and t[0] != "umbra"]
    # The engine's layers, one way: math -> scene -> gpu -> plan -> render -> golden (the plan never sees
    # the device: its device facts are plain inputs, its shader constants ash-free).
    order = ["math", "scene", "gpu", "plan", "render", "golden"]
    rank = lambda m: order.index(m[1]) if m[0] == "umbra" and len(m) > 1 and m[1] in order else None
    bad += [
        (s, t)
        for s, t in code_edges
        if rank(s) is not None and rank(t) is not None and rank(t) > rank(s)
    ]
    # The plan needs no device: it does not import the GPU layer at all.
    bad += [(s, t) for s, t in code_edges if s[:2] == ("umbra", "plan") and t[:2] == ("umbra", "gpu")]
    for s, t in sorted(bad):
        print(f"layering broken: {name(s)} -> {name(t)}")
    # Nor Vulkan's types (a device fact enters the plan as a plain value).
    for mod, f in sorted(mods.items()):
        if mod[:2] == ("umbra", "plan"):
            text = strip_comments(open(f, encoding="utf-8").read())
            if re.search(r"\b(ash|vk)::", text):
                bad.append((mod, ("ash",)))
                print(f"layering broken: {name(mod)} uses ash")
    return 1 if comps or bad else 0


if __name__ == "__main__":
    sys.exit(main())
