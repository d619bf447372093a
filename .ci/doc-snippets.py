#!/usr/bin/env python3
"""Runs the Python snippets and the quoted commands of the documentation and checks the outputs
they show.

Which snippets: every fenced block whose info string starts with ``python`` in README.md,
python/README.md and book/src/**/*.md. The blocks of one file run in order in one namespace,
from the repository root, as a reader follows the page; a block that raises ends its file.

A shown output is a comment that starts with an arrow, at the end of a top-level statement
(on any of its lines):

    fit.n                      # → Estimate(n=0.804±0.007)
    fit = diffbvp.fit(ds)      # → FitResult(n=0.804±0.007, ...)
    print(res.status)          # → 0

For an expression the ``repr`` of its value must match the text after the arrow; for an
assignment the ``repr`` of what was assigned (a tuple for several targets); for a call of
``print`` what it printed. Matching: runs of whitespace count as one space (so a multi-line
``repr`` is written on one line), and ``...`` stands for any run of characters, also none
(elide volatile digits, keep the shape and the stable figures). Every other comment is free text.

A block that cannot run here is marked on the line right before its fence:

    <!-- snippet: not run: REASON -->

Quoted command outputs (the book): a ```text block that is the next fenced block after a
```sh or ```console block quotes the output of its commands (its own lines or
``{{#include FILE}}``, as written by .ci/book-outputs). The commands run in order from the
repository root with the binaries of target/release (``cargo run --release --bin rheometer --``
and ``target/release/rheometer`` run target/release/rheometer, ``cargo run --release --example
NAME`` target/release/examples/NAME; another command needs the marker below), their stdout
and stderr together, "(exit code N)" appended when it is not 0. Every non-blank quoted line must
occur in that output, in order; runs of whitespace and line breaks count as one space, a
duration (a number with s, ms or µs) matches any duration, numbers agree to 1e-9 relative, and
an absolute path to a ``target/`` directory reads ``target/``.

The same marker before a ```sh fence skips its quoted output. The checker lists the skipped
blocks with their reasons and exits with 1 when a block raises or a shown or quoted output does
not match (file, line, expected, got). ``--all`` runs the marked blocks too;
``--python-only`` and ``--shell-only`` run one part; ``--release DIR`` takes the binaries from
DIR; ``--self-test`` checks the checker on inline samples; file arguments restrict the run to
those files.
"""
import ast
import contextlib
import glob
import io
import os
import re
import shlex
import subprocess
import sys
import time
import tokenize
import traceback

ARROW = "→"
FENCE = re.compile(r"^(```+|~~~+)\s*([^\s`]*)")
SKIP = re.compile(r"^<!--\s*snippet:\s*not run:\s*(.+?)\s*-->\s*$")
MARKER = re.compile(r"^<!--\s*snippet:")


class Block:
    def __init__(self, path, line, lang, code, skip):
        self.path, self.line, self.lang, self.code, self.skip = path, line, lang, code, skip


def blocks(path, text):
    """The fenced blocks of a markdown text: (first code line, info, code, skip reason)."""
    lines = text.split("\n")
    out, i = [], 0
    while i < len(lines):
        m = FENCE.match(lines[i])
        if not m:
            if MARKER.match(lines[i]) and not SKIP.match(lines[i]):
                raise ValueError(f"{path}:{i + 1}: malformed snippet marker "
                                 f"(write <!-- snippet: not run: REASON -->)")
            i += 1
            continue
        fence, lang = m.group(1), m.group(2).lower()
        skip = None
        if i > 0:
            s = SKIP.match(lines[i - 1])
            if s:
                skip = s.group(1)
        j = i + 1
        while j < len(lines) and not lines[j].startswith(fence[0] * len(fence)):
            j += 1
        out.append(Block(path, i + 2, lang, "\n".join(lines[i + 1:j]) + "\n", skip))
        i = j + 1
    for k in range(len(lines)):
        if SKIP.match(lines[k]) and not (k + 1 < len(lines) and FENCE.match(lines[k + 1])):
            raise ValueError(f"{path}:{k + 1}: a snippet marker must be right before a fence")
    return out


def shown_outputs(code):
    """{line in the block (from 1): shown text} for the comments that start with the arrow."""
    shown = {}
    for tok in tokenize.generate_tokens(io.StringIO(code).readline):
        if tok.type == tokenize.COMMENT:
            body = tok.string[1:].strip()
            if body.startswith(ARROW):
                shown[tok.start[0]] = body[len(ARROW):].strip()
    return shown


def matches(expected, got):
    norm = lambda s: " ".join(s.split())  # noqa: E731
    pattern = ".*".join(re.escape(p) for p in norm(expected).split("..."))
    return re.fullmatch(pattern, norm(got), re.DOTALL) is not None


class Failure(Exception):
    pass


def _is_print(node):
    return (isinstance(node, ast.Expr) and isinstance(node.value, ast.Call)
            and isinstance(node.value.func, ast.Name) and node.value.func.id == "print")


def run_block(block, ns, counts):
    """Runs one block statement by statement in ns, counting the checked outputs in
    counts["checked"]. Raises Failure with the message to print."""
    offset = block.line - 1
    try:
        tree = ast.parse(block.code)
        shown = shown_outputs(block.code)
    except (SyntaxError, tokenize.TokenError) as e:
        raise Failure(f"{block.path}:{offset + (getattr(e, 'lineno', None) or 1)}: "
                      f"does not parse: {e}")
    spans = [(s.lineno, s.end_lineno, s) for s in tree.body]
    for line in shown:
        if not any(a <= line <= b for a, b, _ in spans):
            raise Failure(f"{block.path}:{offset + line}: a shown output (# {ARROW}) must "
                          f"end a line of a top-level statement")
    ast.increment_lineno(tree, offset)
    for a, b, stmt in spans:
        marks = [line for line in shown if a <= line <= b]
        if len(marks) > 1:
            raise Failure(f"{block.path}:{offset + marks[1]}: one shown output per statement")
        if marks and isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef,
                                       ast.For, ast.While, ast.If, ast.With, ast.Try)):
            raise Failure(f"{block.path}:{offset + marks[0]}: a shown output needs an "
                          f"expression or an assignment, not a compound statement")
        out = io.StringIO()
        try:
            with contextlib.redirect_stdout(out):
                if marks and isinstance(stmt, ast.Expr) and not _is_print(stmt):
                    code = compile(ast.Expression(stmt.value), block.path, "eval")
                    got = repr(eval(code, ns))
                else:
                    code = compile(ast.Module([stmt], []), block.path, "exec")
                    exec(code, ns)
                    got = None
                    if marks and isinstance(stmt, (ast.Assign, ast.AnnAssign, ast.AugAssign)):
                        target = stmt.targets[0] if isinstance(stmt, ast.Assign) else stmt.target
                        got = repr(eval(ast.unparse(target), ns))
        except Exception:
            tb = traceback.format_exc(limit=-3)
            raise Failure(f"{block.path}:{offset + a}: raised\n{tb}")
        if not marks:
            continue
        if _is_print(stmt):
            got = out.getvalue().rstrip("\n")
        elif got is None:
            raise Failure(f"{block.path}:{offset + a}: a shown output needs an expression, an "
                          f"assignment or a print")
        expected = shown[marks[0]]
        if not matches(expected, got):
            raise Failure(f"{block.path}:{offset + marks[0]}: shown output does not match\n"
                          f"  expected: {expected}\n  got:      {' '.join(got.split())}")
        counts["checked"] += 1


def check_text(path, text, run_all=False):
    """Checks the python blocks of one markdown text; returns (blocks run, outputs checked,
    skipped [(line, reason)], failures [message])."""
    ns = {"__name__": "__doc_snippet__"}
    ran = 0
    counts = {"checked": 0}
    skipped, failures = [], []
    try:
        bs = [b for b in blocks(path, text) if b.lang.startswith("python")]
    except ValueError as e:
        return 0, 0, [], [str(e)]
    for k, b in enumerate(bs):
        if b.skip and not run_all:
            skipped.append((b.line - 1, b.skip))
            continue
        try:
            run_block(b, ns, counts)
            ran += 1
        except Failure as e:
            failures.append(str(e))
            rest = len([x for x in bs[k + 1:] if run_all or not x.skip])
            if rest:
                failures.append(f"{path}: {rest} later block(s) not run")
            break
    return ran, counts["checked"], skipped, failures


# ---- quoted outputs of shell commands (the book) ----

NUMBER = r"[-+]?\d+(?:\.\d+)?(?:[eE][-+]?\d+)?"
TOKEN = re.compile(rf"(?P<dur>{NUMBER} ?(?:s|ms|µs)(?![\w/]))|(?P<num>{NUMBER})")
# an absolute path into a checkout's target/: the checkout's place does not matter
ROOT_PATH = re.compile(r"(?<![\w.])/\S*?/target/")
INCLUDE = re.compile(r"^\{\{#include\s+([^}\s:]+)\}\}$")


def _line_regex(line):
    """A quoted line (whitespace collapsed) as a regex; its numbers as groups, durations as
    groups whose value is ignored (None in the list of expected numbers)."""
    pattern, expected, pos = "", [], 0
    for m in TOKEN.finditer(line):
        pattern += re.escape(line[pos:m.start()])
        if m.group("dur"):
            pattern += rf"({NUMBER} ?(?:s|ms|µs))"
            expected.append(None)
        else:
            pattern += f"({NUMBER})"
            expected.append(float(m.group("num")))
        pos = m.end()
    return re.compile(pattern + re.escape(line[pos:])), expected


def _close(a, b):
    return a == b or abs(a - b) <= 1e-9 * max(abs(a), abs(b))


def quoted_mismatch(quoted, output):
    """None when every non-blank quoted line occurs in the output, in order; else (quoted line,
    what the output has there or None). Whitespace runs (line breaks too, so a wrap may move)
    count as one space, a duration (a number with s, ms or µs) matches any duration, numbers
    agree to 1e-9 relative, and an absolute path to a target/ directory reads target/."""
    text = " ".join(ROOT_PATH.sub("target/", output).split())
    pos = 0
    for raw in quoted:
        line = " ".join(ROOT_PATH.sub("target/", raw).split())
        if not line:
            continue
        rx, expected = _line_regex(line)
        first = None
        for m in rx.finditer(text, pos):
            first = first or m.group(0)
            if all(e is None or _close(e, float(g)) for e, g in zip(expected, m.groups())):
                pos = m.end()
                break
        else:
            return raw, first
    return None


def command_argv(line, release="target/release"):
    """The program and arguments a quoted command runs, with the binaries of `release`; None
    for a command the checker cannot run."""
    a = shlex.split(line, comments=True)
    if not a:
        return []
    if a[:5] == ["cargo", "run", "--release", "--bin", "rheometer"]:
        return [os.path.join(release, "rheometer")] + a[6 if a[5:6] == ["--"] else 5:]
    if a[0] == "target/release/rheometer":
        return [os.path.join(release, "rheometer")] + a[1:]
    if a[:4] == ["cargo", "run", "--release", "--example"] and len(a) > 4:
        return [os.path.join(release, "examples", a[4])] + a[6 if a[5:6] == ["--"] else 5:]
    return None


def run_command(argv):
    """stdout and stderr of a command as .ci/book-outputs records them (the exit code appended
    when it is not 0)."""
    p = subprocess.run(argv, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True,
                       timeout=600)
    return p.stdout + (f"(exit code {p.returncode})\n" if p.returncode else "")


def check_shell_text(path, text, run=run_command, release="target/release", run_all=False):
    """Checks the ```text blocks that follow a ```sh or ```console block (the next fenced block)
    against the output of its commands, run in order from the repository root. Returns
    (pairs checked, skipped [(line, reason)], failures [message])."""
    try:
        bs = blocks(path, text)
    except ValueError as e:
        return 0, [], [str(e)]
    done, skipped, failures = 0, [], []
    for b, nxt in zip(bs, bs[1:]):
        if b.lang not in ("sh", "console", "shell", "bash") or nxt.lang != "text":
            continue
        if b.skip and not run_all:
            skipped.append((b.line - 1, b.skip))
            continue
        quoted = []
        for q in nxt.code.split("\n"):
            inc = INCLUDE.match(q.strip())
            if inc:
                included = os.path.join(os.path.dirname(path), inc.group(1))
                with open(included, encoding="utf-8") as fh:
                    quoted += fh.read().split("\n")
            else:
                quoted.append(q)
        output = ""
        commands = b.code.replace("\\\n", " ").split("\n")
        try:
            for k, line in enumerate(commands):
                argv = command_argv(line, release)
                if argv is None:
                    raise Failure(f"{path}:{b.line + k}: cannot run `{line.strip()}` (write "
                                  f"`cargo run --release --bin rheometer -- ...` or mark the "
                                  f"block <!-- snippet: not run: REASON -->)")
                if argv:
                    output += run(argv)
        except Failure as e:
            failures.append(str(e))
            continue
        except (OSError, subprocess.SubprocessError) as e:
            failures.append(f"{path}:{b.line}: the command failed to run: {e}")
            continue
        bad = quoted_mismatch(quoted, output)
        if bad:
            failures.append(f"{path}:{nxt.line - 1}: quoted output not in the command's output\n"
                            f"  expected: {' '.join(bad[0].split())}\n"
                            f"  got:      {bad[1] if bad[1] else '(no such line)'}")
        done += 1
    return done, skipped, failures


def doc_files(root):
    files = ["README.md", "python/README.md"]
    files += sorted(os.path.relpath(p, root)
                    for p in glob.glob(os.path.join(root, "book/src/**/*.md"), recursive=True))
    return files


def main(argv):
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    os.chdir(root)
    args = argv[1:]
    if args[:1] == ["--self-test"]:
        return self_test()
    run_all = "--all" in args
    release = "target/release"
    if "--release" in args:
        k = args.index("--release")
        release = args[k + 1]
        del args[k:k + 2]
    parts = {"python", "shell"}
    for only in ("python", "shell"):
        if f"--{only}-only" in args:
            parts = {only}
    files = [a for a in args if not a.startswith("--")] or doc_files(root)
    t0 = time.perf_counter()
    total_blocks = total_checked = total_pairs = 0
    skipped_all, failures_all = [], []
    for f in files:
        with open(f, encoding="utf-8") as fh:
            text = fh.read()
        if "python" in parts and "```python" in text:
            t = time.perf_counter()
            ran, checked, skipped, failures = check_text(f, text, run_all)
            print(f"{f}: {ran} python block(s) run, {checked} shown output(s) checked, "
                  f"{len(skipped)} skipped ({time.perf_counter() - t:.1f} s)", flush=True)
            total_blocks += ran
            total_checked += checked
            skipped_all += [(f, line, reason) for line, reason in skipped]
            failures_all += failures
        if "shell" in parts and f.startswith("book/src/"):
            t = time.perf_counter()
            pairs, skipped, failures = check_shell_text(f, text, release=release, run_all=run_all)
            if pairs or skipped or failures:
                print(f"{f}: {pairs} quoted command output(s) checked, {len(skipped)} skipped "
                      f"({time.perf_counter() - t:.1f} s)", flush=True)
            total_pairs += pairs
            skipped_all += [(f, line, reason) for line, reason in skipped]
            failures_all += failures
    for f, line, reason in skipped_all:
        print(f"skipped {f}:{line}: {reason}")
    for msg in failures_all:
        print(f"FAIL {msg}")
    print(f"doc snippets: {total_blocks} python block(s) run, {total_checked} shown output(s) "
          f"checked, {total_pairs} quoted command output(s) checked, {len(skipped_all)} "
          f"skipped, {len(failures_all)} failure(s) in {time.perf_counter() - t0:.1f} s")
    return 1 if failures_all else 0


SAMPLE_PASS = '''Text.

```python
import math
x = [1, 2,
     3]                    # → [1, 2, 3]
# a plain comment: free text, not checked, e.g. 42
math.pi                    # → 3.14159...
a, b = 1, "two"            # → (1, 'two')
print("hello", a)          # → hello 1
{"k": [1.0, 2.5]}          # →  {'k': [1.0,   2.5]}
```

<!-- snippet: not run: needs a cluster -->
```python
raise RuntimeError("must not run")
```

```sh
echo not python
```

```python
x[-1] * 2                  # → 6
```
'''

SAMPLES_FAIL = {
    "a wrong shown output": '```python\n1 + 1   # → 3\n```\n',
    "a block that raises": '```python\n1 / 0\n```\n',
    "a name from a skipped block": ('<!-- snippet: not run: slow -->\n```python\ny = 1\n```\n\n'
                                    '```python\ny   # → 1\n```\n'),
    "an arrow on its own line": '```python\nz = 2\n# → 2\n```\n',
    "a wildcard that does not cover": '```python\n"abc"   # → \'b...\'\n```\n',
    "a marker not before a fence": '<!-- snippet: not run: x -->\n\n```python\n1\n```\n',
}


def self_test():
    ok = True
    ran, checked, skipped, failures = check_text("pass.md", SAMPLE_PASS)
    if failures or (ran, checked, len(skipped)) != (2, 6, 1) or skipped[0][1] != "needs a cluster":
        print(f"self-test: the passing sample gave {ran} run, {checked} checked, {skipped}, "
              f"{failures}")
        ok = False
    for name, text in SAMPLES_FAIL.items():
        _, _, _, failures = check_text("fail.md", text)
        if not failures:
            print(f"self-test: {name} was not caught")
            ok = False
    out = ("fit of 9 experiments\nwall time = 0.512 s, cost 1.5e-3\n"
           "model from /ci/tree/target/fit.json: n = 0.80371893774388, kappa = 11.6291 and a\n"
           "    wrapped tail\n(exit code 1)\n")
    sample = ("<!-- snippet: not run: slow -->\n```sh\ncargo run --release --example slow\n```\n"
              "```text\nnever compared\n```\n\n```sh\ntarget/release/rheometer fit x.toml\n```\n\n"
              "```text\nwall time = 0.009 s, cost 1.5e-3\nmodel from target/fit.json: "
              "n = 0.8037189377438774, kappa = 11.6291 and a wrapped tail\n(exit code 1)\n```\n")
    ran_argv = []
    fake = lambda argv: ran_argv.append(argv) or out  # noqa: E731
    pairs, skipped, failures = check_shell_text("pass.md", sample, run=fake, release="R")
    if (failures or pairs != 1 or len(skipped) != 1
            or ran_argv != [["R/rheometer", "fit", "x.toml"]]):
        print(f"self-test: the passing shell sample gave {pairs}, {skipped}, {failures}, "
              f"{ran_argv}")
        ok = False
    shell_bad = {
        "a changed figure": sample.replace("11.6291", "11.6292"),
        "lines out of order": sample.replace("(exit code 1)\n```", "```").replace(
            "```text\nwall", "```text\n(exit code 1)\nwall"),
        "a command it cannot run": sample.replace("target/release/rheometer", "ls"),
    }
    for name, bad in shell_bad.items():
        if not check_shell_text("fail.md", bad, run=fake, release="R")[2]:
            print(f"self-test: {name} in a quoted output was not caught")
            ok = False
    if not matches("(11.45..., 11.79...)", "(11.458282908854484, 11.799926005926439)"):
        ok = False
        print("self-test: the wildcard does not match digits")
    print("doc snippets self-test:", "ok" if ok else "FAILED")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main(sys.argv))
