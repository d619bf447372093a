"""Hostile inputs for output_probes.py (issue 28): the experiments TOML and the measurement CSV
as special files (devices, FIFOs, directories, links, sparse giants), malformed, deeply nested,
over-long, with NaN/inf/huge numbers, wrong types and unit slips.

Each probe runs `fit` (or `simulate`) on a copy of data/pmma7n_synthetic whose TOML or first CSV
(v0p27_p1.csv) was changed by its setup. Probes marked `measure` read an unbounded input
(/dev/zero, /dev/urandom, a sparse 10 GB file, a line without end, too many rows or
experiments): the runner records their time and peak RSS (/usr/bin/time), which must stay
under 1 s and 100 MB.
"""
import os
import re

TOML = os.path.join("data", "experiments.toml")
CSV = os.path.join("data", "v0p27_p1.csv")


def _path(d, rel):
    return os.path.join(d, rel)


def edit_toml(fn):
    """Setup: replace the TOML's text by fn(text)."""
    def f(d):
        p = _path(d, TOML)
        with open(p) as fh:
            s = fh.read()
        with open(p, "w") as fh:
            fh.write(fn(s))
    return f


def set_key(key, value):
    """Setup: the first `key = ...` line of the TOML becomes `key = value`."""
    return edit_toml(lambda s: re.sub(r"(?m)^%s = .*$" % re.escape(key),
                                      lambda m: "%s = %s" % (key, value), s, count=1))


def data_path(value):
    """Setup: the first experiment's `data = ...` becomes `data = "value"`."""
    return set_key("data", '"%s"' % value)


def write_bytes(rel, content):
    def f(d):
        with open(_path(d, rel), "wb") as fh:
            fh.write(content)
    return f


def edit_csv(fn):
    """Setup: the first CSV's lines (without header) become fn(header, rows) (a list of lines)."""
    def f(d):
        p = _path(d, CSV)
        lines = open(p).read().splitlines()
        out = fn(lines[0], lines[1:])
        with open(p, "w") as fh:
            fh.write("\n".join(out) + "\n")
    return f


def sparse(rel, size):
    def f(d):
        with open(_path(d, rel), "wb") as fh:
            fh.truncate(size)
    return f


def fifo(rel):
    return lambda d: os.mkfifo(_path(d, rel))


def link(target, rel):
    return lambda d: os.symlink(target, _path(d, rel))


def chain(*fs):
    def f(d):
        for g in fs:
            g(d)
    return f


def many_rows(n):
    def f(d):
        with open(_path(d, CSV), "w") as fh:
            fh.write("position_m,diameter_m\n")
            step = 0.5 / n
            fh.write("".join("%.9g,%.6e\n" % (k * step, 1.1e-3 - 1e-3 * k / n) for k in range(n)))
    return f


def many_experiments(n):
    def f(d):
        p = _path(d, TOML)
        s = open(p).read()
        head = s[:s.index("[[experiment]]")]
        block = ('[[experiment]]\nname = "e%05d"\nmass_flow_kg_s = 1.5690566037735852e-05\n'
                 'inlet_diameter_m = 0.001134\ndata = "v0p27_p1.csv"\n\n')
        with open(p, "w") as fh:
            fh.write(head + "".join(block % k for k in range(n)))
    return f


# numeric keys of the TOML and the bad values every one of them must refuse
KEYS = [
    "density_slope_kg_m3_K", "density_intercept_kg_m3", "heat_capacity_slope_J_kg_K2",
    "heat_capacity_intercept_J_kg_K", "vft_mu_c_Pa_s", "vft_B_K", "vft_T_VF_K",
    "air_density_kg_m3", "air_heat_capacity_J_kg_K", "air_kinematic_viscosity_m2_s",
    "air_heat_conductivity_W_m_K", "spinline_length_m", "inlet_temperature_K",
    "air_temperature_K", "mass_flow_kg_s", "inlet_diameter_m",
]
BAD_VALUES = [("nan", "nan"), ("inf", "inf"), ("neginf", "-inf"), ("overflow", "1e309"),
              ("huge", "1e300"), ("neghuge", "-1e300"), ("string", '"abc"'), ("array", "[1.0, 2.0]"),
              ("bool", "true")]


def input_probes(Probe, FIT, SIM):
    P = []
    fit = "%s > /dev/null" % FIT
    timed = "/usr/bin/time -f '%%e %%M' -o usage.txt %s" % fit

    def add(name, setup, needles, expect="fail", script=fit, measure=False, limit=30):
        P.append(Probe("in_" + name, timed if measure else script, expect, needles, setup,
                       limit=limit, measure=measure))

    # 1. every numeric key with every bad value
    for key in KEYS:
        for vname, value in BAD_VALUES:
            add("key_%s_%s" % (key, vname), set_key(key, value), [key])
    for key in ("stencil_velocity_mm_s", "take_up_pressure_bar"):
        for vname, value in (("nan", "nan"), ("string", '"abc"'), ("inf", "inf")):
            add("key_%s_%s" % (key, vname), set_key(key, value), [key])
    # 2. unit slips
    for name, key, value, needles in [
        ("celsius", "inlet_temperature_K", "240", ["inlet_temperature_K", "Celsius"]),
        ("air_celsius", "air_temperature_K", "20", ["air_temperature_K"]),
        ("diameter_mm", "inlet_diameter_m", "1.134", ["inlet_diameter_m"]),
        ("length_cm", "spinline_length_m", "51", ["spinline_length_m"]),
        ("mass_flow_g_s", "mass_flow_kg_s", "1.5690566037735852e-02", ["mass_flow_kg_s"]),
        ("mass_flow_kg_h", "mass_flow_kg_s", "0.0565", ["mass_flow_kg_s"]),
        ("mass_flow_zero", "mass_flow_kg_s", "0", ["mass_flow_kg_s"]),
        ("mass_flow_negative", "mass_flow_kg_s", "-1.5e-5", ["mass_flow_kg_s"]),
        ("length_zero", "spinline_length_m", "0", ["spinline_length_m"]),
        ("diameter_zero", "inlet_diameter_m", "0", ["inlet_diameter_m"]),
        ("mu_c_zero", "vft_mu_c_Pa_s", "0", ["vft_mu_c_Pa_s"]),
        ("t_vf_above_inlet", "vft_T_VF_K", "600", ["vft_T_VF_K"]),
        ("integer_overflow", "mass_flow_kg_s", "99999999999999999999999", ["mass_flow_kg_s"]),
        ("hex_integer", "mass_flow_kg_s", "0xffff", ["mass_flow_kg_s"]),
        ("subnormal", "mass_flow_kg_s", "5e-324", ["mass_flow_kg_s"]),
    ]:
        add("unit_" + name, set_key(key, value), needles)
    # 3. the TOML itself as a special or malformed file
    run_on = lambda path: '"$BIN" --quiet fit %s > /dev/null' % path
    timed_on = lambda path: "/usr/bin/time -f '%%e %%M' -o usage.txt %s" % run_on(path)
    for name, path, setup, needles, measure in [
        ("toml_dev_zero", "/dev/zero", None, ["/dev/zero"], True),
        ("toml_dev_urandom", "/dev/urandom", None, ["/dev/urandom"], True),
        ("toml_dev_full", "/dev/full", None, ["/dev/full"], True),
        ("toml_dev_null", "/dev/null", None, ["/dev/null"], False),
        ("toml_dev_stdin_empty", "/dev/stdin", None, ["/dev/stdin"], False),
        ("toml_fifo", "x.toml", fifo("x.toml"), ["x.toml", "fifo"], True),
        ("toml_link_to_zero", "z.toml", link("/dev/zero", "z.toml"), ["z.toml"], True),
        ("toml_sparse_10g", "big.toml", sparse("big.toml", 10 << 30), ["big.toml"], True),
        ("toml_sparse_17m", "big.toml", sparse("big.toml", 17 << 20), ["big.toml"], True),
        ("toml_directory", "data", None, ["data", "directory"], False),
        ("toml_missing", "nothing.toml", None, ["nothing.toml"], False),
        ("toml_link_loop", "loop.toml", link("loop.toml", "loop.toml"), ["loop.toml"], False),
        ("toml_dangling_link", "dl.toml", link("nowhere.toml", "dl.toml"), ["dl.toml"], False),
        ("toml_proc_mem", "/proc/self/mem", None, ["/proc/self/mem"], False),
        ("toml_is_csv", "data/v0p27_p1.csv", None, ["v0p27_p1.csv"], False),
        ("toml_empty", "e.toml", write_bytes("e.toml", b""), ["e.toml"], False),
        ("toml_comments_only", "c.toml", write_bytes("c.toml", b"# nothing\n" * 10), ["c.toml"], False),
        ("toml_binary", "b.toml", write_bytes("b.toml", bytes(range(256)) * 8), ["b.toml"], False),
        ("toml_nul_bytes", "n.toml", write_bytes("n.toml", b"\0" * 4096), ["n.toml"], False),
        ("toml_deep_arrays", "deep.toml", write_bytes("deep.toml", b"x = " + b"[" * 100000 + b"]" * 100000 + b"\n"),
         ["deep.toml"], True),
        ("toml_deep_inline_tables", "deep.toml", write_bytes("deep.toml", b"x = " + b"{a=" * 50000 + b"1" + b"}" * 50000 + b"\n"),
         ["deep.toml"], True),
        ("toml_deep_dotted_key", "deep.toml", write_bytes("deep.toml", b"a" + b".a" * 100000 + b" = 1\n"),
         ["deep.toml"], True),
        ("toml_deep_table_header", "deep.toml", write_bytes("deep.toml", b"[a" + b".a" * 100000 + b"]\n"),
         ["deep.toml"], True),
        ("toml_unclosed_string", "u.toml", write_bytes("u.toml", b'x = "' + b"a" * 1000000), ["u.toml"], True),
        ("toml_long_line_no_newline", "l.toml", write_bytes("l.toml", b"#" + b"a" * (20 << 20)), ["l.toml"], True),
    ]:
        P.append(Probe("in_" + name, timed_on(path) if measure else run_on(path), "fail", needles, setup,
                       limit=30, measure=measure))
    # 4. TOML content
    for name, fn, needles in [
        ("utf16", lambda s: None, ["UTF-8"]),
        ("latin1", None, ["UTF-8", "experiments.toml:28"]),
        ("missing_material", lambda s: s.replace("[material]", "[materiel]"), ["material"]),
        ("unknown_key", lambda s: s.replace("[defaults]", "[defaults]\nspinline_lenght_m = 0.51"), ["spinline_lenght_m"]),
        ("duplicate_key", lambda s: s.replace("vft_B_K = 3649.0", "vft_B_K = 3649.0\nvft_B_K = 3649.0"), ["vft_B_K"]),
        ("duplicate_names", lambda s: s.replace('name = "v0p27_p2"', 'name = "v0p27_p1"'), ["v0p27_p1"]),
        ("missing_mass_flow", lambda s: s.replace("mass_flow_kg_s = 1.5690566037735852e-05\ninlet_diameter_m = 0.001134\ndata = \"v0p27_p1.csv\"",
                                                 "inlet_diameter_m = 0.001134\ndata = \"v0p27_p1.csv\"", 1), ["mass_flow_kg_s"]),
        ("no_experiments", lambda s: s[:s.index("[[experiment]]")], ["experiment"]),
        ("experiment_as_table", lambda s: s.replace("[[experiment]]", "[experiment]", 1), ["experiment"]),
        ("empty_name", lambda s: s.replace('name = "v0p27_p1"', 'name = ""'), ["name"]),
        ("name_slash", lambda s: s.replace('name = "v0p27_p1"', 'name = "../../escaped"'), ["name"]),
        ("name_dotdot", lambda s: s.replace('name = "v0p27_p1"', 'name = ".."'), []),
        ("name_newline", lambda s: s.replace('name = "v0p27_p1"', 'name = "a\\nb"'), ["name"]),
        ("name_nul", lambda s: s.replace('name = "v0p27_p1"', 'name = "a\\u0000b"'), ["name"]),
        ("name_1mb", lambda s: s.replace('name = "v0p27_p1"', 'name = "%s"' % ("n" * 1000000)), ["name"]),
        ("data_empty", lambda s: s.replace('data = "v0p27_p1.csv"', 'data = ""'), ["data"]),
        ("data_number", lambda s: s.replace('data = "v0p27_p1.csv"', "data = 3"), ["data"]),
        ("data_missing_file", lambda s: s.replace('data = "v0p27_p1.csv"', 'data = "nope.csv"'), ["nope.csv"]),
        ("crlf", lambda s: s.replace("\n", "\r\n"), []),
        ("bom", lambda s: "\ufeff" + s, []),
    ]:
        expect = "ok" if name in ("crlf", "bom") else "fail"
        if name in ("utf16", "latin1"):
            def setup(d, name=name):
                p = _path(d, TOML)
                s = open(p).read()
                if name == "latin1":
                    s = s.replace('name = "v0p27_p1"', 'name = "Versuch \xe4"')
                open(p, "wb").write(s.encode("utf-16" if name == "utf16" else "latin-1"))
        else:
            setup = edit_toml(fn)
        script = fit
        if name.startswith("name_"):
            script = ("%s --out out > /dev/null; rc=$?; if test -e escaped_profile.csv || "
                      "test -e ../escaped_profile.csv; then exit 99; fi; exit $rc" % SIM)
            if name == "name_dotdot":
                expect = "ok"  # ".." + "_profile.csv" is a legal file name inside out/
        add("toml_" + name, setup, needles, expect, script)
    add("toml_5000_experiments", many_experiments(5000), ["5,000", "[[experiment]]", "max_experiments"], measure=True)
    add("toml_20m_comment", edit_toml(lambda s: "#" + "c" * (20 << 20) + "\n" + s), ["experiments.toml"], measure=True)
    # 5. the measurement CSV as a special file
    for name, setup, needles, measure in [
        ("csv_dev_zero", data_path("/dev/zero"), ["/dev/zero"], True),
        ("csv_dev_urandom", data_path("/dev/urandom"), ["/dev/urandom"], True),
        ("csv_dev_random", data_path("/dev/random"), ["/dev/random"], True),
        ("csv_dev_full", data_path("/dev/full"), ["/dev/full"], True),
        ("csv_dev_null", data_path("/dev/null"), ["/dev/null"], False),
        ("csv_dev_stdin", data_path("/dev/stdin"), ["/dev/stdin"], True),
        ("csv_dev_tty", data_path("/dev/tty"), ["/dev/tty"], True),
        ("csv_fifo", chain(fifo("data/p.csv"), data_path("p.csv")), ["p.csv", "fifo"], True),
        ("csv_fifo_with_writer", chain(fifo("data/p.csv"), data_path("p.csv")), ["p.csv", "fifo"], True),
        ("csv_link_to_zero", chain(link("/dev/zero", "data/z.csv"), data_path("z.csv")), ["z.csv"], True),
        ("csv_sparse_10g", chain(sparse("data/big.csv", 10 << 30), data_path("big.csv")), ["big.csv"], True),
        ("csv_sparse_200m", chain(sparse("data/big.csv", 200 << 20), data_path("big.csv")), ["big.csv"], True),
        ("csv_directory", data_path("."), ["v0p27_p1"], False),
        ("csv_link_loop", chain(link("loop.csv", "data/loop.csv"), data_path("loop.csv")), ["loop.csv"], False),
        ("csv_proc_self_mem", data_path("/proc/self/mem"), ["/proc/self/mem"], True),
        ("csv_is_toml", data_path("experiments.toml"), ["experiments.toml"], False),
        ("csv_2m_rows", many_rows(2_000_000), ["v0p27_p1.csv", "rows"], True),
        ("csv_line_20m", edit_csv(lambda h, r: [h, "0.0," + "1" * (20 << 20)] + r), ["v0p27_p1.csv", "line"], True),
        ("csv_no_newline_20m", write_bytes(CSV, b"position_m,diameter_m\n" + b"1" * (20 << 20)), ["v0p27_p1.csv"], True),
        ("csv_100k_columns", edit_csv(lambda h, r: [h] + [r[0] + ",1" * 100000] + r[1:]), ["v0p27_p1.csv:2", "longer than"], True),
    ]:
        script = timed if measure else fit
        if name == "csv_fifo_with_writer":
            script = "( exec yes 0.1,1e-3 > data/p.csv ) & w=$!; " + timed + "; rc=$?; kill $w 2>/dev/null; exit $rc"
        if name == "csv_dev_stdin":
            script = timed.replace("> /dev/null", "< /dev/zero > /dev/null")
        P.append(Probe("in_" + name, script, "fail", needles, setup, limit=30, measure=measure))
    # 6. the measurement CSV's content
    def row(h, r, k, new):
        return [h] + r[:k] + [new] + r[k + 1:]
    for name, fn, needles in [
        ("position_nan", lambda h, r: row(h, r, 3, "nan,5e-4"), ["v0p27_p1.csv:5"]),
        ("diameter_nan", lambda h, r: row(h, r, 3, "0.06,NaN"), ["v0p27_p1.csv:5"]),
        ("diameter_inf", lambda h, r: row(h, r, 3, "0.06,inf"), ["v0p27_p1.csv:5"]),
        ("diameter_neginf", lambda h, r: row(h, r, 3, "0.06,-inf"), ["v0p27_p1.csv:5"]),
        ("diameter_overflow", lambda h, r: row(h, r, 3, "0.06,1e309"), ["v0p27_p1.csv:5"]),
        ("position_overflow", lambda h, r: row(h, r, 3, "1e309,5e-4"), ["v0p27_p1.csv:5"]),
        ("position_huge", lambda h, r: row(h, r, 3, "1e308,5e-4"), ["v0p27_p1.csv:5"]),
        ("diameter_huge", lambda h, r: row(h, r, 3, "0.06,1e300"), ["v0p27_p1.csv:5"]),
        ("diameter_negative", lambda h, r: row(h, r, 3, "0.06,-5e-4"), ["v0p27_p1.csv:5"]),
        ("diameter_zero", lambda h, r: row(h, r, 3, "0.06,0"), ["v0p27_p1.csv:5"]),
        ("diameter_subnormal", lambda h, r: row(h, r, 3, "0.06,5e-324"), ["v0p27_p1.csv:5"]),
        ("position_negative", lambda h, r: row(h, r, 3, "-0.06,5e-4"), ["v0p27_p1.csv:5"]),
        ("position_duplicate", lambda h, r: row(h, r, 3, r[2]), ["v0p27_p1.csv:5"]),
        ("positions_reversed", lambda h, r: [h] + r[::-1], ["v0p27_p1.csv"]),
        ("empty_cell", lambda h, r: row(h, r, 3, "0.06,"), ["v0p27_p1.csv:5"]),
        ("quoted_cell", lambda h, r: row(h, r, 3, '"0.06","5e-4"'), []),
        ("extra_column", lambda h, r: row(h, r, 3, "0.06,5e-4,1"), ["v0p27_p1.csv:5"]),
        ("missing_column", lambda h, r: row(h, r, 3, "0.06"), ["v0p27_p1.csv:5"]),
        ("text_cell", lambda h, r: row(h, r, 3, "0.06,abc"), ["v0p27_p1.csv:5"]),
        ("hex_float", lambda h, r: row(h, r, 3, "0.06,0x1p-11"), ["v0p27_p1.csv:5"]),
        ("d_exponent", lambda h, r: [x.replace("e", "D") for x in r], ["v0p27_p1.csv"]),
        ("decimal_comma", lambda h, r: [x.replace(".", ",") for x in r], ["v0p27_p1.csv"]),
        ("semicolon", lambda h, r: [h.replace(",", ";")] + [x.replace(",", ";") for x in r], ["v0p27_p1.csv", "separator"]),
        ("tab", lambda h, r: [h.replace(",", "\t")] + [x.replace(",", "\t") for x in r], ["v0p27_p1.csv"]),
        ("header_only", lambda h, r: [h], ["v0p27_p1.csv"]),
        ("no_header", lambda h, r: r, ["v0p27_p1.csv"]),
        ("wrong_header", lambda h, r: ["x,y"] + r, ["v0p27_p1.csv"]),
        ("one_row", lambda h, r: [h, r[0]], ["v0p27_p1.csv"]),
        ("millimetres", lambda h, r: [h] + ["%s,%g" % (x.split(",")[0], float(x.split(",")[1]) * 1000) for x in r],
         ["v0p27_p1.csv", "mm"]),
        ("nul_byte", lambda h, r: row(h, r, 3, "0.06,5e-4\0"), ["v0p27_p1.csv:5", "binary"]),
        ("crlf", lambda h, r: [h + "\r"] + [x + "\r" for x in r], []),
        ("bom", lambda h, r: ["\ufeff" + h] + r, []),
        ("blank_lines", lambda h, r: [h] + r + ["", ""], []),
    ]:
        # quoted cells are legal CSV
        expect = "ok" if name in ("crlf", "bom", "blank_lines", "quoted_cell") else "fail"
        add("csvdata_" + name, edit_csv(fn), needles, expect)
    add("csvdata_utf16", lambda d: open(_path(d, CSV), "wb").write(open(_path(d, CSV)).read().encode("utf-16")),
        ["v0p27_p1.csv", "UTF-8"])
    add("csvdata_random_bytes", write_bytes(CSV, os.urandom(3000)), ["v0p27_p1.csv"])
    add("csvdata_empty", write_bytes(CSV, b""), ["v0p27_p1.csv"])
    return P
