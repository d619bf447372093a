#!/usr/bin/env python3
"""No function in the workspace's sources (src/, crates/*/src) over 150 lines.

Counts each function from the line of its `fn` keyword to the line of its closing brace
(attributes and doc comments not counted; nested functions and closures count toward the
function they sit in, and are checked on their own too). Comments, strings (raw and byte
strings included) and character literals are blanked before the braces are matched, so a
brace in a string or a comment does not count; generics, `where` clauses, multi-line
signatures, trait impls and default trait methods are handled. Trait method declarations
without a body are not functions here.

Usage: .ci/long-functions.py [--limit N] [--top K] [--allow FILE] [PATH ...]
  PATH     directories or files to check (default: src, crates/diffbvp/src, crates/rheometer/src,
           python/src)
  --limit  the largest allowed length in lines (default 150)
  --top    also list the K longest functions (a report; does not change the exit status)
  --allow  the allowlist (default: .ci/long-functions.allow next to this script)

The allowlist names functions that may stay long, one per line, each with its reason:
    src/path/to/file.rs Type::function: why it cannot be split
A line without a reason is an error, and so is an entry that no longer names a long
function (so the list cannot go stale). `#` starts a comment.

Exit status: 0 when no function exceeds the limit, 1 when one does (each listed as
`path:line: name is N lines`), 2 on a malformed allowlist or a path that does not exist.
"""

import argparse
import os
import re
import sys

DEFAULT_LIMIT = 150


def blank(text):
    """The source with comments, strings and character literals replaced by spaces (newlines
    kept, so line numbers stay)."""
    out = []
    i, n = 0, len(text)

    def keep_lines(s):
        return "".join(c if c == "\n" else " " for c in s)

    while i < n:
        c = text[i]
        if text.startswith("//", i):
            j = text.find("\n", i)
            j = n if j < 0 else j
            out.append(" " * (j - i))
            i = j
        elif text.startswith("/*", i):
            # block comments nest in Rust
            depth, j = 1, i + 2
            while j < n and depth:
                if text.startswith("/*", j):
                    depth, j = depth + 1, j + 2
                elif text.startswith("*/", j):
                    depth, j = depth - 1, j + 2
                else:
                    j += 1
            out.append(keep_lines(text[i:j]))
            i = j
        else:
            m = re.compile(r'b?r(#*)"').match(text, i)
            if m and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_")):
                end = text.find('"' + m.group(1), m.end())
                j = n if end < 0 else end + 1 + len(m.group(1))
                out.append(keep_lines(text[i:j]))
                i = j
            elif c == '"' or (c == "b" and text.startswith('b"', i)
                              and (i == 0 or not (text[i - 1].isalnum() or text[i - 1] == "_"))):
                j = i + (2 if c == "b" else 1)
                while j < n and text[j] != '"':
                    j += 2 if text[j] == "\\" else 1
                j = min(j + 1, n)
                out.append(keep_lines(text[i:j]))
                i = j
            elif c == "'":
                # a character literal ('x', '\n', '\u{..}', '\''), not a lifetime ('a)
                m = re.compile(r"'(\\u\{[0-9a-fA-F]+\}|\\x[0-9a-fA-F]{2}|\\.|[^\\'\n])'").match(text, i)
                if m:
                    out.append(" " * (m.end() - i))
                    i = m.end()
                else:
                    out.append(c)
                    i += 1
            else:
                out.append(c)
                i += 1
    return "".join(out)


TOKEN = re.compile(r"[A-Za-z_][A-Za-z0-9_]*|->|=>|::|[{}()\[\];<>]|\n")


def functions(text):
    """(name, first line, last line) of every function with a body; methods are named
    `Type::name` after the impl (or trait) they sit in."""
    toks = []
    line = 1
    for m in TOKEN.finditer(blank(text)):
        t = m.group(0)
        if t == "\n":
            line += 1
        else:
            toks.append((t, line))
    found = []
    stack = []  # one entry per open brace: ("fn", name, line), ("impl", type) or None
    pending = None  # what the next `{` opens
    i = 0
    while i < len(toks):
        t, ln = toks[i]
        if t in ("impl", "trait") and pending is None:
            pending = ("impl", owner_name(toks, i))
        elif t == "fn" and i + 1 < len(toks) and re.match(r"[A-Za-z_]", toks[i + 1][0]):
            # the body starts at the first `{` outside parentheses and brackets; a `;` there
            # first is a declaration
            depth, j = 0, i + 2
            while j < len(toks):
                u = toks[j][0]
                if u in "([":
                    depth += 1
                elif u in ")]":
                    depth -= 1
                elif depth == 0 and u in "{;":
                    break
                j += 1
            if j < len(toks) and toks[j][0] == "{":
                owner = next((s[1] for s in reversed(stack) if s and s[0] == "impl"), None)
                inner = next((s for s in reversed(stack) if s), None)
                name = toks[i + 1][0]
                if inner and inner[0] == "impl" and owner:
                    name = f"{owner}::{name}"
                stack.append(("fn", name, ln))
                i = j + 1
                continue
            i = j + 1
            continue
        elif t == "{":
            stack.append(pending)
            pending = None
        elif t == "}":
            top = stack.pop() if stack else None
            if top and top[0] == "fn":
                found.append((top[1], top[2], ln))
        elif t == ";":
            pending = None
        i += 1
    return found


def owner_name(toks, i):
    """The type an `impl` is about (after `for` when it implements a trait), or the name of
    a `trait`: the last segment of its path, without generics."""
    if toks[i][0] == "trait":
        return toks[i + 1][0] if i + 1 < len(toks) else None
    words = []
    j = i + 1
    while j < len(toks) and toks[j][0] not in ("{", ";", "where"):
        words.append(toks[j][0])
        j += 1
    if "for" in words:
        words = words[words.index("for") + 1:]
    elif words[:1] == ["<"]:
        # the impl's own generic parameters
        depth = 0
        for k, w in enumerate(words):
            depth += (w == "<") - (w == ">")
            if depth == 0:
                words = words[k + 1:]
                break
    name = None
    for w in words:
        if w == "<":
            break
        if re.match(r"[A-Za-z_]", w) and w not in ("dyn", "mut", "const", "unsafe"):
            name = w
    return name


def read_allowlist(path):
    allowed = {}
    if not os.path.exists(path):
        return allowed
    with open(path, encoding="utf-8") as f:
        for k, raw in enumerate(f, 1):
            line = raw.split("#", 1)[0].strip()
            if not line:
                continue
            m = re.match(r"^(\S+\.rs)\s+(\S+?):\s+(\S.*)$", line)
            if not m:
                sys.exit(f"{path}:{k}: expected `src/file.rs name: reason` (a reason is required)")
            allowed[(m.group(1), m.group(2))] = m.group(3)
    return allowed


def rust_files(paths):
    for p in paths:
        if os.path.isfile(p):
            yield p
        elif os.path.isdir(p):
            for root, dirs, files in os.walk(p):
                dirs.sort()
                for f in sorted(files):
                    if f.endswith(".rs"):
                        yield os.path.join(root, f)
        else:
            sys.exit(f"no such file or directory: {p}")


def main():
    here = os.path.dirname(os.path.abspath(__file__))
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("paths", nargs="*", default=["src", "crates/diffbvp/src", "crates/rheometer/src", "python/src"])
    ap.add_argument("--limit", type=int, default=DEFAULT_LIMIT)
    ap.add_argument("--top", type=int, default=0)
    ap.add_argument("--allow", default=os.path.join(here, "long-functions.allow"))
    args = ap.parse_args()
    allowed = read_allowlist(args.allow)
    everything = []
    for path in rust_files(args.paths):
        with open(path, encoding="utf-8") as f:
            text = f.read()
        for name, first, last in functions(text):
            everything.append((last - first + 1, os.path.normpath(path), first, name))
    everything.sort(key=lambda r: (-r[0], r[1], r[2]))
    for n, path, first, name in everything[: args.top]:
        print(f"{n:5}  {path}:{first}: {name}")
    offenders, used = [], set()
    for n, path, first, name in everything:
        if n <= args.limit:
            continue
        key = (path, name)
        if key in allowed:
            used.add(key)
            continue
        offenders.append(f"{path}:{first}: {name} is {n} lines (limit {args.limit})")
    stale = [f"{p} {nm}" for (p, nm) in allowed if (p, nm) not in used]
    if stale:
        print(f"{args.allow}: entries that name no function over {args.limit} lines "
              "(remove them):", file=sys.stderr)
        for s in stale:
            print(f"    {s}", file=sys.stderr)
    if offenders:
        print(f"functions over {args.limit} lines (split them into named steps, or list them "
              f"with a reason in {os.path.relpath(args.allow)}):", file=sys.stderr)
        for o in offenders:
            print(f"    {o}", file=sys.stderr)
    if offenders or stale:
        sys.exit(1)


if __name__ == "__main__":
    main()
