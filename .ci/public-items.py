#!/usr/bin/env python3
"""The public surface of a library crate: the items a user of the crate can name.

An item counts when it is declared `pub` (not `pub(crate)`, `pub(super)`, `pub(in ...)`) in a
module that is itself reachable: the crate root, and every `pub mod` inside a reachable module.
Counted: functions, structs, enums, traits, type aliases, constants, statics, macros exported
with `#[macro_export]`, and `pub use` re-exports (each name once); methods of public types and
struct fields are not counted (they belong to their type). Test modules (`#[cfg(test)]` and
below) are left out.

    python3 .ci/public-items.py crates/rheometer 1300   # fails above 1300 items
    python3 .ci/public-items.py crates/rheometer --list # every item, by module

Exit status 1 when the count exceeds the limit, 2 on a bad argument.
"""
import importlib.util
import os
import re
import sys

ITEM = re.compile(
    r"^pub\s+(?:unsafe\s+|async\s+|const\s+(?=fn))*(fn|struct|enum|trait|type|const|static|mod|use)\b\s*([^;{(<:=\s]*)",
    re.M,
)


def _lexer():
    """The Rust lexer of long-functions.py (one blanking of comments, strings, raw strings and
    character literals for both checks)."""
    spec = importlib.util.spec_from_file_location(
        "long_functions", os.path.join(os.path.dirname(os.path.abspath(__file__)), "long-functions.py")
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module.blank


blank = _lexer()


def strip(text):
    """Comments, strings and character literals blanked (line structure kept), the test module
    cut off."""
    text = blank(text)
    # the test module (a `#[cfg(test)]` on a single `use` or item does not end the file)
    text = re.split(r"#\[cfg\(test\)\]\s*(?:pub(?:\([^)]*\))?\s+)?mod\s+\w+\s*\{", text, maxsplit=1)[0]
    # a `use` statement on one line, so that its braces do not look like a block
    return re.sub(r"\buse\s+[^;]*;", lambda m: re.sub(r"\s+", " ", m.group(0)), text)


def top_level(text):
    """The lines of `text` at brace depth 0 (items inside impl blocks and functions left out)."""
    out, depth = [], 0
    for line in text.splitlines():
        if depth == 0:
            out.append(line.strip())
        depth += line.count("{") - line.count("}")
    return "\n".join(out)


def module_file(src, path):
    """The file of module `path` (a tuple) below `src`, or None."""
    if not path:
        return os.path.join(src, "lib.rs")
    base = os.path.join(src, *path)
    for f in (base + ".rs", os.path.join(base, "mod.rs")):
        if os.path.isfile(f):
            return f
    return None


def use_names(body):
    """The names a `pub use` brings in: `a::{b, c as d, e::*}` -> ['b', 'd', 'e::*']."""
    body = re.sub(r"\s+", " ", body)
    m = re.match(r"^(.*?)\{(.*)\}$", body)
    if not m:
        last = body.split("::")[-1]
        return [last.split(" as ")[-1].strip()]
    items, depth, cur = [], 0, ""
    for ch in m.group(2):
        depth += (ch == "{") - (ch == "}")
        if ch == "," and depth == 0:
            items.append(cur)
            cur = ""
        else:
            cur += ch
    items.append(cur)
    out = []
    for it in items:
        it = it.strip()
        if it:
            out.extend(use_names(it) if "{" in it else [it.split("::")[-1].split(" as ")[-1].strip()])
    return out


def items(src):
    """[(module path, kind, name)] of the crate's public surface."""
    found, todo = [], [()]
    while todo:
        path = todo.pop()
        f = module_file(src, path)
        if f is None:
            continue
        text = top_level(strip(open(f, encoding="utf-8").read()))
        for m in ITEM.finditer(text):
            kind, name = m.group(1), m.group(2)
            if kind == "mod":
                todo.append(path + (name,))
                continue
            if kind == "use":
                end = text.index(";", m.end())
                body = text[m.start():end].split("use", 1)[1].strip()
                for n in use_names(body):
                    if n != "self":
                        found.append(("::".join(path), "use", n))
                continue
            found.append(("::".join(path), kind, name))
        for m in re.finditer(r"#\[macro_export\]\s*macro_rules!\s*(\w+)", text):
            found.append(("::".join(path), "macro", m.group(1)))
    return found


def main():
    args = sys.argv[1:]
    if not args or not os.path.isdir(os.path.join(args[0], "src")):
        print(__doc__)
        return 2
    src = os.path.join(args[0], "src")
    found = items(src)
    if "--list" in args:
        for mod, kind, name in sorted(found):
            print(f"{mod or 'crate'}\t{kind}\t{name}")
    limits = [a for a in args[1:] if a.isdigit()]
    n = len(found)
    mods = len({m for m, _, _ in found})
    if limits and n > int(limits[0]):
        print(f"public items of {args[0]}: {n} in {mods} public modules, above the limit {limits[0]}")
        return 1
    print(f"public items of {args[0]}: {n} in {mods} public modules"
          + (f" (limit {limits[0]})" if limits else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())
