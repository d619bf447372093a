#!/usr/bin/env python3
"""The import graph of src/: every `crate::`, `super::` and `self::` path in the code (use
statements and paths in expressions, comments and strings left out), resolved to the file it
names, checked against the Layers section of src/lib.rs.

Checks:
  1. the Layers section lists every module of the toolkit and of `fiber` (no module missing,
     none listed that does not exist);
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
SRC = os.path.join(ROOT, "src")


def module_files():
    """{module path tuple: file} for the library (src/bin is a separate crate)."""
    mods = {}
    for dirpath, _, files in os.walk(SRC):
        if os.path.relpath(dirpath, SRC).split(os.sep)[0] == "bin":
            continue
        for f in files:
            if not f.endswith(".rs"):
                continue
            rel = os.path.relpath(os.path.join(dirpath, f), SRC)[:-3].split(os.sep)
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


def layers():
    """{unit: layer} from the Layers section of src/lib.rs: toolkit units are top-level
    module names, fiber units `fiber::NAME` (layer numbers of the fiber list offset by 100)."""
    text = open(os.path.join(SRC, "lib.rs"), encoding="utf-8").read()
    doc = "\n".join(l[4:] if l.startswith("//! ") else l[3:] for l in text.splitlines() if l.startswith("//!"))
    sec = doc.split("## Layers", 1)[1].split("\n## ", 1)[0]
    toolkit, fiber = sec.split("The fiber model and rheometer", 1)
    out = {}
    for part, offset, prefix in ((toolkit, 0, ()), (fiber, 100, ("fiber",))):
        for m in re.finditer(r"^(\d+)\.\s+(.*?)(?=^\d+\.|\Z)", part, flags=re.S | re.M):
            layer = offset + int(m.group(1))
            # the names outside parentheses ("`rheometer` (inside: ...)" explains, links
            # "[`solve`](mod@solve)" point): nested parentheses removed innermost first
            body = m.group(2).split("\n\n", 1)[0]
            while True:
                stripped = re.sub(r"\([^()]*\)", "", body)
                if stripped == body:
                    break
                body = stripped
            names = re.findall(r"`([\w:]+)`", body)
            for n in names:
                out[prefix + tuple(n.split("::"))] = layer
    # `plot` and `atomic_write` stand apart (no solver imports): a layer of their own, 0
    for sentence in re.findall(r"[^.]*stand apart", toolkit):
        for n in re.findall(r"`(\w+)`", sentence):
            out[(n,)] = 0
    return out


def unit_of(mod):
    if not mod:
        return None
    if mod[0] == "fiber":
        return mod[:2] if len(mod) >= 2 else None
    return mod[:1]


def main():
    mods = module_files()
    lay = layers()
    problems = []
    units = {unit_of(m) for m in mods if unit_of(m)}
    for u in sorted(units):
        if u not in lay:
            problems.append(f"module {'::'.join(u)} is not in the Layers section of src/lib.rs")
    for u in sorted(lay):
        if u not in units:
            problems.append(f"the Layers section lists {'::'.join(u)}, which does not exist")
    edges = {}
    for mod, f in mods.items():
        code = strip(open(f, encoding="utf-8").read())
        # test modules may reach anywhere
        code = code.split("#[cfg(test)]", 1)[0]
        for p in paths_of(code):
            t = resolve(p, mod, mods)
            if t is None or t == mod or (t and mod[: len(t)] == t):
                continue
            edges.setdefault(mod, set()).add(t)
    # upward arrows between units
    for a, ts in sorted(edges.items()):
        ua = unit_of(a)
        for b in sorted(ts):
            ub = unit_of(b)
            if ua is None or ub is None or ua == ub:
                continue
            la, lb = lay.get(ua), lay.get(ub)
            if la is None or lb is None:
                continue
            if (la >= 100) != (lb >= 100) and lb >= 100:
                problems.append(f"the toolkit module {'::'.join(a)} imports fiber's {'::'.join(b)}")
            elif lb > la and not (la == 0 and lb == 0):
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
        print(f"import graph: {len(mods)} modules, {n_edges} arrows; {len(problems)} problems:")
        for p in problems:
            print("  - " + p)
        return 1
    print(f"import graph: {len(mods)} modules, {n_edges} arrows; no circle, no upward arrow, "
          f"the Layers section of src/lib.rs lists all {len(units)} units")
    return 0


if __name__ == "__main__":
    sys.exit(main())
