#!/usr/bin/env python3
"""The book's Python API reference (book/src/reference/python-api.md), generated from the
package's sources: every public name of `diffbvp` and of its public modules, with its signature
(as written in the source, annotations included) and its docstring. The sources are read with
`ast`, not imported, so no build of the Rust layer is needed.

    python3 .ci/python-api.py           # check: the committed page equals the generated one
    python3 .ci/python-api.py --write   # regenerate the page after changing a docstring

Exit status 1 when the committed page differs (the book would show stale signatures or
docs), 2 on a bad argument or a public name without a docstring.
"""

import ast
import os
import re
import sys

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
PACKAGE = os.path.join(ROOT, "python", "diffbvp")
PAGE = os.path.join(ROOT, "book", "src", "reference", "python-api.md")

# (module, file, what the section is about); the package's own names are those of __all__
MODULES = [
    ("diffbvp", "__init__.py", "the rheometer's workflows and the package's names"),
    ("diffbvp.results", "results.py", "the results of the workflows"),
    ("diffbvp.bvp", "bvp.py", "any boundary value problem: scipy's `solve_bvp` contract"),
    ("diffbvp.errors", "errors.py", "the exceptions"),
    ("diffbvp.distributed", "distributed.py", "many fits on a Dask cluster"),
]


def rst_to_markdown(text):
    """Docstring markup as Markdown: ``code`` and :role:`name` as code, doctest examples as
    `pycon` blocks."""
    text = re.sub(r":(?:func|class|meth|mod|attr|data|exc):`~?([^`]+)`", r"`\1`", text)
    text = text.replace("``", "`")
    out, in_example = [], False
    for line in text.split("\n"):
        stripped = line.strip()
        starts_example = stripped.startswith(">>>")
        if starts_example and not in_example:
            out.append("```pycon")
            in_example = True
        elif in_example and not stripped:
            out.append("```")
            in_example = False
        out.append(stripped if in_example else line)
    if in_example:
        out.append("```")
    return "\n".join(out).strip()


def split_top_level(text):
    """`text` split at the commas outside brackets and strings."""
    parts, depth, quote, start = [], 0, None, 0
    for i, c in enumerate(text):
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == "," and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    parts.append(text[start:].strip())
    return [p for p in parts if p]


def signature(node, width=88):
    """`name(args) -> returns` as written in the source; one argument per line when longer
    than `width`."""
    args = ast.unparse(node.args)
    ret = f" -> {ast.unparse(node.returns)}" if node.returns is not None else ""
    one_line = f"{node.name}({args}){ret}"
    if len(one_line) <= width:
        return one_line
    inner = "".join(f"\n    {a}," for a in split_top_level(args))
    return f"{node.name}({inner}\n){ret}"


def is_property(node):
    return any(isinstance(d, ast.Name) and d.id == "property" for d in node.decorator_list)


def public_names(tree):
    """`__all__` where the module has one, else every top-level name without a leading `_`."""
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
            isinstance(t, ast.Name) and t.id == "__all__" for t in node.targets
        ):
            return [ast.literal_eval(e) for e in node.value.elts]
    return [
        n.name
        for n in tree.body
        if isinstance(n, (ast.FunctionDef, ast.ClassDef)) and not n.name.startswith("_")
    ]


def doc_of(node, where, missing):
    d = ast.get_docstring(node)
    if not d:
        missing.append(where)
        return ""
    return rst_to_markdown(d)


def class_section(module, node, missing):
    lines = [f"### class `{module}.{node.name}`", ""]
    bases = [ast.unparse(b) for b in node.bases]
    if bases:
        lines += [f"Bases: {', '.join(f'`{b}`' for b in bases)}", ""]
    doc = doc_of(node, f"{module}.{node.name}", missing)
    if doc:
        lines += [doc, ""]
    for item in node.body:
        if not isinstance(item, ast.FunctionDef):
            continue
        if item.name.startswith("_") and item.name not in ("__call__", "__init__"):
            continue
        if item.name == "__init__" and not ast.get_docstring(item):
            continue
        if is_property(item):
            ret = f": {ast.unparse(item.returns)}" if item.returns is not None else ""
            lines += [f"- **property** `{item.name}{ret}`"]
        else:
            lines += [f"- **method** `{signature(item, width=10**6)}`"]
        d = ast.get_docstring(item)
        if d:
            body = rst_to_markdown(d)
            lines += ["", *("  " + x if x else "" for x in body.split("\n"))]
        lines.append("")
    return lines


def module_section(module, filename, about, imported, missing):
    path = os.path.join(PACKAGE, filename)
    with open(path, encoding="utf-8") as f:
        tree = ast.parse(f.read(), filename=path)
    defs = {
        n.name: n for n in tree.body if isinstance(n, (ast.FunctionDef, ast.ClassDef))
    }
    lines = [f"## `{module}`: {about}", ""]
    doc = ast.get_docstring(tree)
    if doc:
        lines += [rst_to_markdown(doc), ""]
    names = public_names(tree)
    elsewhere = [n for n in names if n not in defs]
    for name in names:
        node = defs.get(name)
        if node is None:
            continue
        if module != "diffbvp" and name in imported:
            continue
        if isinstance(node, ast.ClassDef):
            lines += class_section(module, node, missing)
        else:
            lines += [f"### `{module}.{name}`", "", "```text", signature(node), "```", ""]
            d = doc_of(node, f"{module}.{name}", missing)
            if d:
                lines += [d, ""]
    if elsewhere:
        lines += [
            "Also exported here (documented with their modules below): "
            + ", ".join(f"`{n}`" for n in elsewhere)
            + ".",
            "",
        ]
    return lines, set(names) - set(elsewhere)


def generate():
    missing = []
    lines = [
        "# Python API reference",
        "",
        "<!-- generated by .ci/python-api.py from the package's sources; do not edit: change",
        "     the docstring and run `python3 .ci/python-api.py --write` -->",
        "",
        "Every public function and class of the `diffbvp` package, with its signature as",
        "written in the source and its docstring. The chapters [From Python](../python.md) and",
        "[Your BVP from Python](../python-bvp.md) show them at work.",
        "",
    ]
    documented = set()
    for module, filename, about in MODULES:
        section, names = module_section(module, filename, about, documented, missing)
        lines += section
        documented |= names
    return "\n".join(lines).rstrip() + "\n", missing


def main(argv):
    if argv not in ([], ["--write"]):
        print(__doc__, file=sys.stderr)
        return 2
    text, missing = generate()
    if missing:
        print("public names without a docstring: " + ", ".join(missing), file=sys.stderr)
        return 2
    if argv == ["--write"]:
        with open(PAGE, "w", encoding="utf-8") as f:
            f.write(text)
        print(f"wrote {os.path.relpath(PAGE, ROOT)}")
        return 0
    try:
        with open(PAGE, encoding="utf-8") as f:
            current = f.read()
    except FileNotFoundError:
        current = ""
    if current != text:
        print(
            f"{os.path.relpath(PAGE, ROOT)} differs from the package's docstrings: run "
            "`python3 .ci/python-api.py --write` and commit the page",
            file=sys.stderr,
        )
        return 1
    print(f"{os.path.relpath(PAGE, ROOT)}: up to date with the package's docstrings")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
