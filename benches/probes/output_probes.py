#!/usr/bin/env python3
"""Hostile probes of the rheometer's output side (issue 28): where outputs go and what they
are (special files, inputs, each other, links, long names, protected files, unwritable places),
standard streams that fail or close, contradicting flags and odd numbers, signals and kill -9.

    python3 benches/probes/output_probes.py            # all probes (a few minutes)
    python3 benches/probes/output_probes.py --quick    # the first 40
    python3 benches/probes/output_probes.py --only in_ # the probes whose names start so

The hostile inputs (TOML and CSV as devices, FIFOs, sparse giants, deep nesting, NaN/inf, huge
numbers, unit slips, long lines) are listed in input_cases.py; those reading an unbounded input
are timed (/usr/bin/time: seconds and peak RSS, limits 1 s and 100 MB).

Every probe runs in a fresh copy of data/pmma7n_synthetic under target/output-probes/ and
records: exit code, time, panic (exit 101 or "panicked at"), abort (exit 134 or SIGABRT), hang
(killed at the time limit), inputs changed (checksums of every file of the copy that existed
before, plus the fit files), special files replaced (/dev/null, /dev/full, /dev/stdout and the
probe's FIFOs and links keep their kind), temporaries left, and the message quality: 2 when
stderr has every phrase the probe expects (what, where, what to do), 1 when some, 0 when none.

As root the whole run happens in a private mount namespace whose /dev is a tmpfs copy, so a
program that replaced /dev/null would damage only the copy (the counts say whether it did).
The report is written to target/output-probes/report.md and summarised on stdout.
"""
import hashlib
import json
import os
import shutil
import signal
import stat
import subprocess
import sys
import time

from input_cases import input_probes

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
BIN = os.path.join(ROOT, "target", "release", "rheometer")
DATA = os.path.join(ROOT, "data", "pmma7n_synthetic")
WORK = os.path.join(ROOT, "target", "output-probes")
LIMIT = 90
DEVICES = ["/dev/null", "/dev/full", "/dev/stdout", "/dev/stderr", "/dev/zero"]


def kind(path):
    try:
        m = os.lstat(path)
    except FileNotFoundError:
        return "missing"
    if stat.S_ISLNK(m.st_mode):
        return "symlink"
    if stat.S_ISCHR(m.st_mode):
        return "char"
    if stat.S_ISFIFO(m.st_mode):
        return "fifo"
    if stat.S_ISDIR(m.st_mode):
        return "dir"
    return "file"


def digest(path):
    try:
        m = os.stat(path)
        if m.st_size > (64 << 20):
            # the probes' sparse giants: size and modification time (reading them is the slow part)
            return "size=%d mtime=%d" % (m.st_size, m.st_mtime_ns)
        with open(path, "rb") as f:
            return hashlib.sha1(f.read()).hexdigest()
    except OSError:
        return None


def inputs_of(d):
    out = {}
    for dirpath, _, files in os.walk(d):
        for f in files:
            p = os.path.join(dirpath, f)
            if kind(p) == "file":
                out[p] = digest(p)
    return out


class Probe:
    def __init__(self, name, script, expect, needles=(), setup=None, special=(), limit=LIMIT,
                 quick=False, watch_extra=(), measure=False):
        self.name, self.script, self.expect = name, script, expect
        self.measure = measure
        self.needles, self.setup, self.special = list(needles), setup, list(special)
        self.limit, self.quick, self.watch_extra = limit, quick, list(watch_extra)


def fresh(name):
    d = os.path.join(WORK, name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    shutil.copytree(DATA, os.path.join(d, "data"))
    return d


def run_probe(p):
    d = fresh(p.name)
    if p.setup:
        try:
            p.setup(d)
        except (OSError, subprocess.CalledProcessError) as e:
            return {"name": p.name, "expect": p.expect, "code": None, "time": 0.0, "hang": False,
                    "panic": False, "abort": False, "changed": [], "replaced": [], "temporaries": [],
                    "ok": False, "quality": 0, "usage": None, "stderr": ["setup failed: %s" % e],
                    "missing": p.needles}
    # a fit file for compare probes (made before the inputs are recorded)
    before = inputs_of(os.path.join(d, "data"))
    for extra in p.watch_extra:
        before[os.path.join(d, extra)] = digest(os.path.join(d, extra))
    special = {s: kind(s if s.startswith("/") else os.path.join(d, s)) for s in DEVICES + p.special}
    env = dict(os.environ, BIN=BIN, T="data/experiments.toml")
    t0 = time.time()
    proc = subprocess.Popen(["bash", "-c", p.script], cwd=d, env=env, stdin=subprocess.DEVNULL,
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, start_new_session=True)
    hang = False
    try:
        out, err = proc.communicate(timeout=p.limit)
    except subprocess.TimeoutExpired:
        hang = True
        os.killpg(proc.pid, signal.SIGKILL)
        out, err = proc.communicate()
    dt = time.time() - t0
    usage = None
    if p.measure:
        try:
            with open(os.path.join(d, "usage.txt")) as f:
                last = f.read().split("\n")
            fields = [ln for ln in last if ln.strip() and ln[0].isdigit()][-1].split()
            usage = {"seconds": float(fields[0]), "peak_rss_mb": int(fields[1]) / 1024.0}
        except (OSError, IndexError, ValueError):
            usage = None
    out = out.decode("utf-8", "replace")
    err = err.decode("utf-8", "replace")
    code = proc.returncode
    after = {k: digest(k) for k in before}
    changed = [k for k in before if after[k] != before[k]]
    replaced = [s for s, k in special.items()
                if kind(s if s.startswith("/") else os.path.join(d, s)) != k]
    temps = []
    for dirpath, _, files in os.walk(d):
        temps += [os.path.join(dirpath, f) for f in files if ".tmp-" in f]
    panic = code == 101 or "panicked at" in err or "panicked at" in out
    abort = code in (134, -6) or "memory allocation of" in err
    low = err.lower()
    hits = sum(1 for n in p.needles if n.lower() in low)
    if p.expect == "ok":
        ok = code == 0
        quality = 2 if ok else 0
    else:
        ok = code not in (0, None) and not panic
        quality = 0 if not ok else (2 if hits == len(p.needles) else (1 if hits else 0))
    return {
        "name": p.name, "expect": p.expect, "code": code, "time": round(dt, 2), "hang": hang,
        "panic": panic, "abort": abort, "changed": changed, "replaced": replaced,
        "temporaries": temps, "ok": ok, "quality": quality,
        "usage": usage, "stderr": err.strip().splitlines()[:6], "missing": [n for n in p.needles if n.lower() not in low],
    }


# ---------------------------------------------------------------------------------------------
# setups

def mkfifo(name):
    return lambda d: os.mkfifo(os.path.join(d, name))


def symlink(target, name):
    return lambda d: os.symlink(target, os.path.join(d, name))


def write_file(name, text="precious\n", mode=None):
    def f(d):
        p = os.path.join(d, name)
        os.makedirs(os.path.dirname(p), exist_ok=True)
        with open(p, "w") as fh:
            fh.write(text)
        if mode is not None:
            os.chmod(p, mode)
    return f


def mkdir(name):
    return lambda d: os.makedirs(os.path.join(d, name), exist_ok=True)


def both(*fs):
    def f(d):
        for g in fs:
            g(d)
    return f


def fit_file(name):
    def f(d):
        subprocess.run([BIN, "--quiet", "fit", "data/experiments.toml", "--json", name], cwd=d,
                       stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
    return f


def rename_input(csv, new):
    def f(d):
        os.rename(os.path.join(d, "data", csv), os.path.join(d, "data", new))
        t = os.path.join(d, "data", "experiments.toml")
        s = open(t).read().replace('"%s"' % csv, '"%s"' % new)
        open(t, "w").write(s)
    return f


def hard_link(src, name):
    return lambda d: os.link(os.path.join(d, src), os.path.join(d, name))


def long_name_toml(n):
    def f(d):
        t = os.path.join(d, "data", "experiments.toml")
        s = open(t).read().replace('name = "v0p27_p1"', 'name = "%s"' % ("e" * n), 1)
        open(t, "w").write(s)
    return f


def dead_temporaries(dirname):
    def f(d):
        c = subprocess.Popen(["true"])
        c.wait()
        o = os.path.join(d, dirname)
        os.makedirs(o, exist_ok=True)
        for n in (".tmp-diffbvp-%d-0" % c.pid, ".v0p27_p1_profile.csv.tmp-%d-2.csv" % c.pid):
            open(os.path.join(o, n), "w").write("half")
    return f


# ---------------------------------------------------------------------------------------------
# the probes

FIT = '"$BIN" --quiet fit $T'
SIM = '"$BIN" --quiet simulate $T --take-up-from-data'
CMP = '"$BIN" --quiet compare $T --n 0.8 --kappa 11.71 --take-up-from-data'
LAND = '"$BIN" --quiet landscape $T --grid 3x3 --n-range 0.7,0.9 --kappa-range 11,12'
DIAG = '"$BIN" --quiet diagnose $T --refit-top 1'


def probes():
    P = []
    # 1. --json targets of fit: (name, path, setup, expect, needles, special)
    json_targets = [
        ("dev_null", "/dev/null", None, "ok", [], []),
        ("dev_full", "/dev/full", None, "fail", ["/dev/full", "no space left"], []),
        ("dev_stdout", "/dev/stdout", None, "ok", [], []),
        ("dev_stderr", "/dev/stderr", None, "ok", [], []),
        ("dash", "-", None, "ok", [], []),
        ("fd1", "/dev/fd/1", None, "ok", [], []),
        ("proc_self_fd1", "/proc/self/fd/1", None, "ok", [], []),
        ("fd_closed", "/dev/fd/9", None, "fail", ["descriptor 9 is not open"], []),
        ("dev_stdin", "/dev/stdin", None, "fail", ["standard input"], []),
        ("dev_zero", "/dev/zero", None, "ok", [], []),
        ("link_to_null", "null.json", symlink("/dev/null", "null.json"), "ok", [], ["null.json"]),
        ("link_to_full", "full.json", symlink("/dev/full", "full.json"), "fail", ["no space left"], ["full.json"]),
        ("fifo_reader", "fifo", mkfifo("fifo"), "ok", [], ["fifo"]),
        ("dir", "data", None, "fail", ["--json", "existing directory"], []),
        ("toml", "data/experiments.toml", None, "fail", ["--json", "input file"], []),
        ("csv", "data/v0p27_p1.csv", None, "fail", ["--json", "input file"], []),
        ("hard_link_csv", "h.json", hard_link("data/v0p27_p1.csv", "h.json"), "fail", ["input file", "through a link"], []),
        ("symlink_toml", "s.json", symlink("data/experiments.toml", "s.json"), "fail", ["input file", "through a link"], []),
        ("readonly_0444", "r.json", write_file("r.json", mode=0o444), "fail", ["refusing to replace", "write-protected", "chmod"], []),
        ("readonly_0400", "r.json", write_file("r.json", mode=0o400), "fail", ["write-protected"], []),
        ("readonly_0000", "r.json", write_file("r.json", mode=0o000), "fail", ["write-protected"], []),
        ("writable_0600_kept", "r.json", write_file("r.json", mode=0o600), "ok", [], []),
        ("name_250", "j" * 245 + ".json", None, "ok", [], []),
        ("name_255", "j" * 250 + ".json", None, "ok", [], []),
        ("name_256", "j" * 251 + ".json", None, "fail", ["--json", "256 bytes long", "at most 255"], []),
        ("name_5000", "j" * 5000 + ".json", None, "fail", ["bytes long", "shorter name"], []),
        ("below_csv", "data/v0p27_p1.csv/fit.json", None, "fail", ["v0p27_p1.csv", "is a file, not a directory"], []),
        ("proc", "/proc/x.json", None, "fail", ["cannot write into /proc"], []),
        ("sys", "/sys/x.json", None, "fail", ["/sys"], []),
        ("deep_new_dir", "a/b/c/d/fit.json", None, "ok", [], []),
        ("dangling_link", "dl.json", symlink("nowhere/x.json", "dl.json"), "fail", ["symbolic link", "does not exist"], ["dl.json"]),
        ("link_to_dir", "ld.json", both(mkdir("somedir"), symlink("somedir", "ld.json")), "fail", ["existing directory"], []),
        ("trailing_slash", "out/", None, "fail", ["--json"], []),
        ("dot", ".", None, "fail", ["existing directory"], []),
        ("empty_name", "", None, "fail", ["--json"], []),
        ("stdout_redirected_file", "rep.json", None, "fail", ["standard output is redirected to it"], []),
        ("existing_regular", "old.json", write_file("old.json"), "ok", [], []),
    ]
    for name, path, setup, expect, needles, special in json_targets:
        script = "%s --json %s > /dev/null" % (FIT, shq(path))
        if name == "fifo_reader":
            script = "(cat fifo > got.json &) ; %s --json fifo > /dev/null; sleep 0.2; test -s got.json" % FIT
        if name == "stdout_redirected_file":
            script = "%s --json rep.json > rep.json" % FIT
        if name == "dev_stderr":
            script = "%s --json /dev/stderr > /dev/null 2> err.json" % FIT
        if path == "":
            script = "%s --json '' > /dev/null" % FIT
        P.append(Probe("json_" + name, script, expect, needles, setup, special, quick=True))
    P.append(Probe("json_fifo_no_reader", "%s --json fifo > /dev/null" % FIT, "fail",
                   ["no process opened this fifo", "cat"], mkfifo("fifo"), ["fifo"]))
    P.append(Probe("json_process_substitution", "%s --json >(cat > got.json) > /dev/null; sleep 0.3; test -s got.json" % FIT, "ok"))
    P.append(Probe("json_fd3_file", "exec 3> fd3.json; %s --json /dev/fd/3 > /dev/null; test -s fd3.json" % FIT, "ok"))
    P.append(Probe("json_fd3_readonly", "exec 3< data/experiments.toml; %s --json /dev/fd/3 > /dev/null" % FIT,
                   "fail", ["descriptor 3", "reading only"]))
    P.append(Probe("json_fd3_append", "echo first > a.json; exec 3>> a.json; %s --json /dev/fd/3 > /dev/null; head -1 a.json | grep -q first" % FIT, "ok"))
    # 2. output directories of each command: (name, dir, setup, expect, needles)
    dir_cases = [
        ("new", "out", None, "ok", []),
        ("data_dir", "data", None, "ok", []),
        ("is_csv", "data/v0p27_p1.csv", None, "fail", ["--out", "input file"]),
        ("is_toml", "data/experiments.toml", None, "fail", ["--out", "input file"]),
        ("is_file", "notes.txt", write_file("notes.txt"), "fail", ["notes.txt", "is a file, not a directory"]),
        ("below_file", "notes.txt/out", write_file("notes.txt"), "fail", ["notes.txt", "is a file"]),
        ("dev_null", "/dev/null", None, "fail", ["/dev/null", "not a directory"]),
        ("dash", "-", None, "fail", ["standard output cannot hold a directory"]),
        ("proc", "/proc/out", None, "fail", ["cannot write into /proc"]),
        ("long_component", "d" * 256, None, "fail", ["bytes long", "at most 255"]),
        ("stale_temporaries", "out", dead_temporaries("out"), "ok", []),
        ("symlink_to_dir", "lnk", both(mkdir("real"), symlink("real", "lnk")), "ok", []),
    ]
    commands = [("fit", FIT), ("simulate", SIM), ("compare", CMP), ("landscape", LAND)]
    for cname, base in commands:
        for name, dirname, setup, expect, needles in dir_cases:
            script = "%s --out %s > /dev/null" % (base, shq(dirname))
            if name == "stale_temporaries":
                script += "; test -z \"$(ls -A out | grep tmp-)\""
            P.append(Probe("%s_out_%s" % (cname, name), script, expect, needles, setup, quick=cname == "fit"))
    # outputs of one command named like inputs, or like each other
    P += [
        Probe("fit_with_figure_named_like_csv", '"$BIN" --quiet fit $T --with radiation --out data > /dev/null', "fail",
              ["residuals_before_after.png", "input file"], rename_input("v0p27_p1.csv", "residuals_before_after.png")),
        Probe("fit_fig2_named_like_csv", '%s --out data > /dev/null' % FIT, "fail", ["fig2_smoothing.png", "input file"],
              rename_input("v0p27_p1.csv", "fig2_smoothing.png")),
        Probe("fit_profile_named_like_csv", '%s --out data > /dev/null' % FIT, "fail", ["input file"],
              rename_input("v0p27_p2.csv", "v0p27_p2_fitted_profile.csv")),
        Probe("simulate_profile_named_like_csv", '%s --out data > /dev/null' % SIM, "fail", ["input file"],
              rename_input("v0p27_p2.csv", "v0p27_p1_profile.csv")),
        Probe("simulate_partial_named_like_csv", '%s --out data > /dev/null' % SIM, "fail", ["PARTIAL.txt", "input file"],
              rename_input("v0p27_p2.csv", "PARTIAL.txt")),
        Probe("compare_fit_file_is_output", '"$BIN" --quiet compare $T --fit data/compare.json --out data > /dev/null', "fail",
              ["compare.json", "input file"], fit_file("data/compare.json")),
        Probe("compare_fit_file_summary", '"$BIN" --quiet compare $T --fit res/compare_summary.txt --out res > /dev/null', "fail",
              ["compare_summary.txt", "input file"], both(mkdir("res"), fit_file("res/compare_summary.txt")),
              watch_extra=["res/compare_summary.txt"]),
        Probe("compare_fit_file_hard_link", '"$BIN" --quiet compare $T --fit f.json --out out > /dev/null', "fail",
              ["compare_points.csv", "input file"], both(fit_file("f.json"), mkdir("out"), hard_link("f.json", "out/compare_points.csv")),
              watch_extra=["f.json"]),
        Probe("compare_fit_file_ok", '"$BIN" --quiet compare $T --fit f.json --out out > /dev/null', "ok", [],
              fit_file("f.json"), watch_extra=["f.json"]),
        Probe("fit_json_is_report", '%s --json out/fit_report.txt --out out > /dev/null' % FIT, "fail",
              ["--json", "--out", "name the same file"]),
        Probe("fit_json_is_profile", '%s --json out/v0p27_p1_fitted_profile.csv --out out > /dev/null' % FIT, "fail",
              ["--json", "--out", "name the same file"]),
        Probe("fit_json_is_fit_json", '%s --json out/fit.json --out out > /dev/null' % FIT, "fail", ["name the same file"]),
        Probe("fit_json_dotdot", '%s --json out/../out/fit.json --out out > /dev/null' % FIT, "fail", ["name the same file"]),
        Probe("fit_json_link_into_out", '%s --json l.json --out out > /dev/null' % FIT, "fail", ["name the same file"],
              both(write_file("out/fit.json", "old"), symlink("out/fit.json", "l.json"))),
        Probe("fit_json_is_out_dir", '%s --json out --out out > /dev/null' % FIT, "fail", ["--json", "--out"]),
        Probe("fit_json_is_partial", '%s --json out/PARTIAL.txt --out out > /dev/null' % FIT, "fail", ["name the same file"]),
        Probe("diagnose_json_is_report", '%s --json out/diagnosis.txt --out out > /dev/null' % DIAG, "fail",
              ["--json", "--out", "name the same file"]),
        Probe("diagnose_json_is_toml", '%s --json $T --out out > /dev/null' % DIAG, "fail", ["--json", "input file"]),
        Probe("diagnose_out_is_csv", '%s --out data/v0p27_p1.csv > /dev/null' % DIAG, "fail", ["--out", "input file"]),
        Probe("diagnose_data_named_like_output", '%s --out data > /dev/null' % DIAG, "fail", ["diagnosis.json", "input file"],
              rename_input("v0p27_p1.csv", "diagnosis.json")),
        Probe("diagnose_json_dev_null", '%s --json /dev/null > /dev/null' % DIAG, "ok"),
        Probe("diagnose_json_dev_full", '%s --json /dev/full > /dev/null' % DIAG, "fail", ["/dev/full", "no space left"]),
        Probe("diagnose_figure_is_dir", '%s --out out > /dev/null' % DIAG, "fail", ["j_profiles.png", "existing directory"],
              mkdir("out/j_profiles.png")),
        Probe("diagnose_readonly_report", '%s --out out > /dev/null' % DIAG, "fail", ["write-protected"],
              write_file("out/diagnosis.txt", mode=0o444)),
        Probe("landscape_csv_readonly", '%s --out out > /dev/null' % LAND, "fail", ["landscape.csv", "write-protected"],
              write_file("out/landscape.csv", mode=0o444)),
        Probe("simulate_long_name_236", '%s --out out > /dev/null' % SIM, "ok", [], long_name_toml(236)),
        # names are limited at the TOML to what every command's file names allow (fit's
        # "<name>_fitted_profile.csv": 236 bytes), so 243 is refused before any work
        Probe("simulate_long_name_243", '%s --out out > /dev/null' % SIM, "fail", ["bytes long", "at most 236"],
              long_name_toml(243)),
        Probe("simulate_long_name_244", '%s --out out > /dev/null' % SIM, "fail", ["bytes long", "at most 255"], long_name_toml(244)),
        Probe("simulate_long_name_5000", '%s --out out > /dev/null' % SIM, "fail", ["bytes long"], long_name_toml(5000)),
        Probe("fit_long_name_240", '%s --out out > /dev/null' % FIT, "ok", [], long_name_toml(236)),
        Probe("fit_format_svg", '"$BIN" --quiet --format svg fit $T --with radiation --out out > /dev/null; ! ls out | grep -q png', "ok"),
    ]
    # 3. standard streams
    for cname, base in [("fit", FIT.replace("--quiet ", "")), ("simulate", SIM.replace("--quiet ", "") + " --out out"),
                        ("compare", CMP.replace("--quiet ", "") + " --out out"), ("landscape", LAND.replace("--quiet ", "") + " --out out")]:
        P += [
            Probe("%s_stdout_full" % cname, "%s > /dev/full" % base, "fail" if cname in ("fit", "compare", "landscape") else "ok",
                  ["cannot write to standard output", "no space left"]),
            Probe("%s_stderr_full" % cname, "%s > /dev/null 2> /dev/full; test $? -ne 101" % base, "ok"),
            Probe("%s_stdout_closed" % cname, "%s >&-" % base, "fail" if cname in ("fit", "compare", "landscape") else "ok",
                  ["standard output is closed", "report was lost"]),
            Probe("%s_stderr_closed" % cname, "%s > /dev/null 2>&-" % base, "ok"),
            Probe("%s_stdout_pipe_closed" % cname, "%s | head -c 0" % base, "ok"),
        ]
    P += [
        Probe("stdout_devnull_read_write", '"$BIN" --quiet fit $T 1<> /dev/null', "ok"),
        Probe("hints_stderr_full", '"$BIN" simulate $T --take-up-from-data --n 0 --out out 2> /dev/full; test $? -eq 1', "ok"),
        Probe("json_dash_stdout_closed", "%s --json - >&-" % FIT, "fail", ["standard output is closed"]),
        Probe("help_stdout_full", '"$BIN" --help > /dev/full', "fail", ["cannot write to standard output"]),
        Probe("usage_error_stderr_full", '"$BIN" simulate --points x 2> /dev/full; test $? -eq 2', "ok"),
    ]
    # 4. flags that contradict each other, numbers in messages
    P += [
        Probe("conflict_compare_newtonian_n", '"$BIN" compare $T --newtonian --kappa 11 --n 0.5 --take-up-from-data --out out', "fail", ["--newtonian", "--n"]),
        Probe("conflict_simulate_newtonian_n", '%s --out out --newtonian --n 0.5' % SIM, "fail", ["--newtonian", "--n"]),
        Probe("conflict_take_up", '"$BIN" simulate $T --take-up-diameter 1e-4 --take-up-from-data --out out', "fail",
              ["--take-up-diameter", "--take-up-from-data"]),
        Probe("conflict_fit_newtonian_model", '"$BIN" fit $T --newtonian --model carreau', "fail", ["--newtonian", "--model"]),
        Probe("conflict_fit_newtonian_start", '"$BIN" fit $T --newtonian --start 0.5,12', "fail", ["--newtonian", "--start"]),
        Probe("conflict_fit_model_newtonian_start", '"$BIN" fit $T --model newtonian --start 0.5,12', "fail", ["--start", "newtonian"]),
        Probe("conflict_f_scale_linear", '"$BIN" fit $T --f-scale 0.02', "fail", ["--f-scale", "robust loss", "--loss"]),
        Probe("conflict_compare_fit_n", '"$BIN" compare $T --fit f.json --n 0.5 --out out', "fail", ["--fit", "--n"], fit_file("f.json")),
        Probe("number_kappa_1e308", '%s --out out --kappa 1e308' % SIM, "fail", ["--kappa", "1e308"]),
        Probe("number_points_negative", '%s --out out --points -5' % SIM, "fail", ["--points", "got -5"]),
        Probe("number_points_fraction", '%s --out out --points 2.5' % SIM, "fail", ["--points", "whole number"]),
        Probe("number_n_dashdash", '%s --out out --n -- -0.1' % SIM, "fail", ["negative numbers need no"]),
        Probe("number_n_range_zero", '"$BIN" landscape $T --grid 3x3 --n-range 0,0 --out out', "fail", ["--n-range", "single value"]),
        Probe("number_n_range_reversed", '"$BIN" landscape $T --grid 3x3 --n-range 1,0 --out out', "fail", ["did you mean 0,1"]),
        Probe("number_grid_negative", '"$BIN" landscape $T --grid -3x3 --out out', "fail", ["--grid", "-3"]),
        Probe("number_max_nodes_negative", '%s --out out --max-nodes -3' % SIM, "fail", ["--max-nodes", "got -3"]),
        Probe("number_take_up_tiny", '"$BIN" simulate $T --take-up-diameter 1e-300 --out out', "fail", ["--take-up-diameter", "1e-300"]),
        Probe("number_long_value", '%s --out out --kappa %s' % (SIM, "9" * 5000), "fail", ["--kappa", "characters"]),
    ]
    # 5. signals and kill -9: no temporaries, marked sets, inputs intact
    big = '"$BIN" simulate $T --take-up-from-data --points 100000 --out out'
    for sig in ("TERM", "HUP", "INT"):
        for delay in ("0.15", "0.4", "0.8"):
            P.append(Probe("signal_%s_%s" % (sig, delay),
                           "%s > /dev/null 2> err.txt & p=$!; sleep %s; kill -%s $p; wait $p; rc=$?; "
                           "test -z \"$(ls -A out 2>/dev/null | grep tmp-)\" && test $rc -ne 0 && "
                           "{ test -e out/PARTIAL.txt || ! ls out/*_profile.csv > /dev/null 2>&1; }"
                           % (big, delay, sig), "ok"))
    for delay in ("0.1", "0.3", "0.6"):
        P.append(Probe("sigterm_fit_out_%s" % delay,
                       '"$BIN" fit $T --out out > /dev/null 2>&1 & p=$!; sleep %s; kill -TERM $p; wait $p; '
                       'test -z "$(ls -A out 2>/dev/null | grep tmp-)"' % delay, "ok"))
    for delay in ("0.15", "0.3", "0.5", "0.7"):
        P.append(Probe("kill9_then_rerun_%s" % delay,
                       "%s > /dev/null 2>&1 & p=$!; sleep %s; kill -9 $p; wait $p; "
                       "n=$(ls -A out 2>/dev/null | grep -c tmp-); test $n -le 1 && %s > /dev/null 2>&1 && "
                       "test -z \"$(ls -A out | grep tmp-)\" && ! test -e out/PARTIAL.txt" % (big, delay, big), "ok"))
    # 6. hostile inputs (input_cases.py)
    P += input_probes(Probe, FIT, SIM)
    return P


def shq(s):
    return "'" + s.replace("'", "'\\''") + "'"


def in_private_dev():
    """As root: re-run this script in a private mount namespace with a tmpfs copy of /dev."""
    if os.geteuid() != 0 or os.environ.get("OUTPUT_PROBES_INNER"):
        return False
    devcopy = os.path.join(WORK, "devcopy")
    os.makedirs(devcopy, exist_ok=True)
    script = (
        "set -e; mount -t tmpfs -o size=1m tmpfs {d}; cp -a /dev/null /dev/full /dev/zero {d}/; "
        "ln -s /proc/self/fd {d}/fd; ln -s /proc/self/fd/0 {d}/stdin; ln -s /proc/self/fd/1 {d}/stdout; "
        "ln -s /proc/self/fd/2 {d}/stderr; mount --bind {d} /dev; "
        "OUTPUT_PROBES_INNER=1 exec python3 {me} {args}"
    ).format(d=devcopy, me=os.path.abspath(__file__), args=" ".join(shq(a) for a in sys.argv[1:]))
    r = subprocess.run(["unshare", "-m", "--propagation", "private", "bash", "-c", script])
    if r.returncode == 0 or os.path.exists(os.path.join(WORK, "report.json")):
        sys.exit(r.returncode)
    print("no private mount namespace: running directly", file=sys.stderr)
    return False


def main():
    if not os.path.exists(BIN):
        sys.exit("build first: cargo build --release")
    os.makedirs(WORK, exist_ok=True)
    if os.path.exists(os.path.join(WORK, "report.json")):
        os.remove(os.path.join(WORK, "report.json"))
    in_private_dev()
    ps = probes()
    if "--quick" in sys.argv:
        ps = [p for p in ps if p.quick][:40]
    if "--only" in sys.argv:
        prefix = sys.argv[sys.argv.index("--only") + 1]
        ps = [p for p in ps if p.name.startswith(prefix)]
    results = []
    for k, p in enumerate(ps):
        r = run_probe(p)
        results.append(r)
        flag = "ok " if r["ok"] else "BAD"
        print("%3d/%d %s %-40s rc=%-4s %6.2fs q=%d%s" % (
            k + 1, len(ps), flag, p.name, r["code"], r["time"], r["quality"],
            "" if r["ok"] else "  " + " | ".join(r["stderr"][:2])), flush=True)
    summary = {
        "probes": len(results),
        "as_expected": sum(r["ok"] for r in results),
        "inputs_modified": sum(bool(r["changed"]) for r in results),
        "special_files_replaced": sum(bool(r["replaced"]) for r in results),
        "panics": sum(r["panic"] for r in results),
        "aborts": sum(r["abort"] for r in results),
        "hangs": sum(r["hang"] for r in results),
        "temporaries_left": sum(bool(r["temporaries"]) for r in results),
        "refusals": sum(r["expect"] == "fail" for r in results),
        "quality_good": sum(r["quality"] == 2 for r in results),
        "quality_partial": sum(r["quality"] == 1 for r in results),
        "quality_poor": sum(r["quality"] == 0 for r in results),
        "root_private_dev": bool(os.environ.get("OUTPUT_PROBES_INNER")),
    }
    measured = [r for r in results if r["usage"]]
    unmeasured = [r["name"] for r in results if r["usage"] is None and r["name"] in
                  {p.name for p in ps if p.measure}]
    if measured:
        slow = max(measured, key=lambda r: r["usage"]["seconds"])
        big = max(measured, key=lambda r: r["usage"]["peak_rss_mb"])
        summary["unbounded_inputs"] = len(measured) + len(unmeasured)
        summary["unbounded_not_measured"] = unmeasured
        summary["unbounded_over_1s_or_100mb"] = [
            r["name"] for r in measured
            if r["usage"]["seconds"] >= 1.0 or r["usage"]["peak_rss_mb"] >= 100.0]
        summary["slowest_refusal"] = [slow["name"], slow["usage"]["seconds"], slow["usage"]["peak_rss_mb"]]
        summary["largest_refusal"] = [big["name"], big["usage"]["seconds"], big["usage"]["peak_rss_mb"]]
    with open(os.path.join(WORK, "report.json"), "w") as f:
        json.dump({"summary": summary, "results": results}, f, indent=1)
    with open(os.path.join(WORK, "report.md"), "w") as f:
        f.write("| probe | expect | exit | s | as expected | quality | note |\n|---|---|---|---|---|---|---|\n")
        for r in results:
            note = "; ".join(x for x in [
                "inputs changed: %s" % r["changed"] if r["changed"] else "",
                "replaced: %s" % r["replaced"] if r["replaced"] else "",
                "temporaries: %s" % r["temporaries"] if r["temporaries"] else "",
                "missing: %s" % r["missing"] if r["expect"] == "fail" and r["missing"] else "",
                "%.2f s, %.0f MB peak" % (r["usage"]["seconds"], r["usage"]["peak_rss_mb"]) if r["usage"] else "",
            ] if x)
            f.write("| %s | %s | %s | %s | %s | %d | %s |\n" % (
                r["name"], r["expect"], r["code"], r["time"], "yes" if r["ok"] else "NO", r["quality"], note))
    print(json.dumps(summary, indent=1))
    bad = summary["inputs_modified"] + summary["special_files_replaced"] + summary["panics"] + \
        summary["aborts"] + summary["hangs"]
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
