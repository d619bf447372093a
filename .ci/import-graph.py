#!/usr/bin/env python3
"""The import graph of each library crate of the workspace (crates/diffbvp, crates/rheometer):
every `crate::`, `super::` and `self::` path in the code (use statements and paths in
expressions, comments and strings left out), resolved to the file it names, checked against
the Layers section of that crate's src/lib.rs. (That the toolkit never imports the rheometer
the compiler keeps: `diffbvp` does not depend on `rheometer`.)

The units of the check are the modules the Layers section names: a top-level module
(`fit`), or a module inside one (`report::format`) when the modules of a folder sit on
different layers; every module belongs to the longest of them that is a prefix of its path.
A folder whose modules are listed one by one (`report`) is a unit of none: it only declares
them and may import nothing.

Checks:
  1. the Layers section covers every module of the crate (each belongs to a listed unit or is
     a folder of listed units that imports nothing; none listed that does not exist);
  2. no upward arrow: a module imports only from its own layer or the layers below it;
  3. no circle: no two files import each other, directly or through others;
  4. (report) the import circles between modules of the same layer.

    python3 .ci/import-graph.py           # checks; exit 1 with the findings
    python3 .ci/import-graph.py --dot     # the graph of modules (Graphviz) on stdout
"""
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
CRATES = ["crates/diffbvp", "crates/rheometer"]


def module_files(src):
    """{module path tuple: file} for the library crate whose sources are in `src`."""
    mods = {}
    for dirpath, _, files in os.walk(src):
        for f in files:
            if not f.endswith(".rs"):
                continue
            rel = os.path.relpath(os.path.join(dirpath, f), src)[:-3].split(os.sep)
            if rel == ["lib"]:
                path = ()
            elif rel[-1] == "mod":
                path = tuple(rel[:-1])
            else:
                path = tuple(rel)
            mods[path] = os.path.join(dirpath, f)
    return mods


def strip(text):
    """The code without comments, strings and char literals (so that docs do not count)."""
    text = re.sub(r"//[^\n]*", "", text)
    text = re.sub(r"/\*.*?\*/", "", text, flags=re.S)
    text = re.sub(r'r#*"(?:.|\n)*?"#*', '""', text)
    text = re.sub(r'"(\\.|[^"\\])*"', '""', text)
    text = re.sub(r"'(\\.|[^'\\])'", "' '", text)
    return text


def expand_use(body):
    """`a::{b::C, d}` -> ['a::b::C', 'a::d'] (nested braces too)."""
    body = body.strip()
    m = re.match(r"^(.*?)\{(.*)\}$", body, flags=re.S)
    if not m:
        return [body]
    prefix, inner = m.group(1), m.group(2)
    items, depth, cur = [], 0, ""
    for ch in inner:
        if ch == "{":
            depth += 1
        elif ch == "}":
            depth -= 1
        if ch == "," and depth == 0:
            items.append(cur)
            cur = ""
        else:
            cur += ch
    items.append(cur)
    out = []
    for it in items:
        it = it.strip()
        if not it:
            continue
        if it == "self":
            out.append(prefix.rstrip(":"))
        else:
            out.extend(expand_use(prefix + it))
    return out


def paths_of(code):
    """Every crate/super/self path in the code."""
    out = []
    for m in re.finditer(r"\buse\s+([^;]+);", code):
        out.extend(expand_use(m.group(1)))
    code_wo_use = re.sub(r"\buse\s+[^;]+;", "", code)
    for m in re.finditer(r"\b((?:crate|super|self)(?:::\w+)+)", code_wo_use):
        out.append(m.group(1))
    return [re.sub(r"\s+as\s+\w+$", "", p.strip()) for p in out if p.strip()]


def resolve(path, here, mods):
    """The module a path names (the longest existing module prefix), from module `here`."""
    parts = [p for p in path.replace(" ", "").split("::") if p]
    if not parts:
        return None
    if parts[0] == "crate":
        base, parts = (), parts[1:]
    elif parts[0] in ("super", "self"):
        base = here
        while parts and parts[0] in ("super", "self"):
            if parts[0] == "super":
                base = base[:-1]
            parts = parts[1:]
    else:
        return None
    best = base if base in mods else None
    for i in range(1, len(parts) + 1):
        cand = base + tuple(parts[:i])
        if cand in mods:
            best = cand
        else:
            break
    return best


def layers(src):
    """{unit: layer} from the Layers section of the crate's src/lib.rs (units are module paths:
    `fit`, `report::format`)."""
    text = open(os.path.join(src, "lib.rs"), encoding="utf-8").read()
    doc = "\n".join(l[4:] if l.startswith("//! ") else l[3:] for l in text.splitlines() if l.startswith("//!"))
    sec = doc.split("## Layers", 1)[1].split("\n## ", 1)[0]
    out = {}
    for m in re.finditer(r"^(\d+)\.\s+(.*?)(?=^\d+\.|\Z)", sec, flags=re.S | re.M):
        layer = int(m.group(1))
        # the names outside parentheses ("`fit` (inside: ...)" explains, links
        # "[`solve`](mod@solve)" point): nested parentheses removed innermost first
        body = m.group(2).split("\n\n", 1)[0]
        while True:
            stripped = re.sub(r"\([^()]*\)", "", body)
            if stripped == body:
                break
            body = stripped
        for n in re.findall(r"`([\w:]+)`", body):
            out[tuple(n.split("::"))] = layer
    return out


def unit_of(mod, lay):
    """The longest module path listed in the Layers section that is a prefix of `mod`."""
    for k in range(len(mod), 0, -1):
        if mod[:k] in lay:
            return mod[:k]
    return None


def is_folder(mod, lay):
    """A module that only holds listed units (`report` when `report::format` is listed)."""
    return bool(mod) and any(len(u) > len(mod) and u[: len(mod)] == mod for u in lay)


def check(crate):
    """The findings of one crate, printed; 0 when clean, 1 otherwise."""
    src = os.path.join(ROOT, crate, "src")
    mods = module_files(src)
    lay = layers(src)
    problems = []
    units = {unit_of(m, lay) for m in mods if unit_of(m, lay)}
    for m in sorted(mods):
        if m and unit_of(m, lay) is None and not is_folder(m, lay):
            problems.append(f"module {'::'.join(m)} is not in the Layers section of {crate}/src/lib.rs")
    for u in sorted(lay):
        if u not in mods:
            problems.append(f"the Layers section lists {'::'.join(u)}, which does not exist")
    edges, to_parent = {}, {}
    for mod, f in mods.items():
        code = strip(open(f, encoding="utf-8").read())
        # test modules may reach anywhere
        code = code.split("#[cfg(test)]", 1)[0]
        for p in paths_of(code):
            t = resolve(p, mod, mods)
            if t is None or t == mod:
                continue
            if t and mod[: len(t)] == t:
                # the module's own folder: not a circle, but an upward arrow if the folder is a
                # unit of a higher layer (`workflow` from `workflow::failure_hints`)
                if unit_of(t, lay) not in (None, unit_of(mod, lay)):
                    to_parent.setdefault(mod, set()).add(t)
                continue
            edges.setdefault(mod, set()).add(t)
    # a folder of units only declares them
    for a, ts in sorted(edges.items()):
        if a and unit_of(a, lay) is None and is_folder(a, lay):
            for b in sorted(ts):
                problems.append(
                    f"{'::'.join(a)} is a folder of units in the Layers section but imports {'::'.join(b) or 'crate'}"
                )
    # upward arrows between units
    arrows = {a: set(ts) for a, ts in edges.items()}
    for a, ts in to_parent.items():
        arrows.setdefault(a, set()).update(ts)
    for a, ts in sorted(arrows.items()):
        ua = unit_of(a, lay)
        for b in sorted(ts):
            ub = unit_of(b, lay)
            if ua is None or ub is None or ua == ub:
                continue
            la, lb = lay.get(ua), lay.get(ub)
            if la is None or lb is None:
                continue
            if lb > la:
                problems.append(
                    f"upward arrow: {'::'.join(a)} (layer {la}) imports {'::'.join(b)} (layer {lb})"
                )
    # circles between files
    index, low, stack, on, comps, counter = {}, {}, [], set(), [], [0]

    def strong(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in edges.get(v, ()):
            if w not in index:
                strong(w)
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
                comps.append(comp)

    sys.setrecursionlimit(10000)
    for v in list(mods):
        if v not in index:
            strong(v)
    for c in comps:
        problems.append("import circle: " + " <-> ".join(sorted("::".join(m) or "crate" for m in c)))
    if "--dot" in sys.argv:
        print("digraph imports {")
        for a, ts in sorted(edges.items()):
            for b in sorted(ts):
                print(f'  "{"::".join(a)}" -> "{"::".join(b)}";')
        print("}")
        return 0
    n_edges = sum(len(t) for t in edges.values())
    if problems:
        print(f"import graph of {crate}: {len(mods)} modules, {n_edges} arrows; {len(problems)} problems:")
        for p in problems:
            print("  - " + p)
        return 1
    print(f"import graph of {crate}: {len(mods)} modules, {n_edges} arrows; no circle, no upward "
          f"arrow, the Layers section of its src/lib.rs lists all {len(units)} units")
    return 0


def main():
    return max(check(c) for c in CRATES)


if __name__ == "__main__":
    sys.exit(main())
