#!/usr/bin/env python3
"""Writes a copy of data/pmma7n_synthetic in the units of a lab sheet: mass flow in g/min,
temperatures in degrees Celsius, the inlet diameter in mm, the spin line in cm, and CSV files
with the header `position_mm,diameter_um`.

The conversion is exact decimal arithmetic on the numbers as written in the shipped files
(Python's `decimal`), independent of the Rust loader under test. Run from this folder:
`python3 make.py` (it reads ../../../data/pmma7n_synthetic).
"""
import re
from decimal import Decimal
from pathlib import Path

SRC = Path(__file__).resolve().parents[3] / "data" / "pmma7n_synthetic"
OUT = Path(__file__).resolve().parent


def plain(x: Decimal) -> str:
    s = format(x.normalize(), "f")
    return s


def convert(line: str) -> str:
    rules = [
        ("mass_flow_kg_s", "mass_flow_g_min", lambda v: v * 60000),
        ("inlet_temperature_K", "inlet_temperature_C", lambda v: v - Decimal("273.15")),
        ("air_temperature_K", "air_temperature_C", lambda v: v - Decimal("273.15")),
        ("vft_T_VF_K", "vft_T_VF_C", lambda v: v - Decimal("273.15")),
        ("inlet_diameter_m", "inlet_diameter_mm", lambda v: v * 1000),
        ("spinline_length_m", "spinline_length_cm", lambda v: v * 100),
    ]
    for key, new, f in rules:
        m = re.fullmatch(rf"{key} = (\S+)", line)
        if m:
            return f"{new} = {plain(f(Decimal(m.group(1))))}"
    return line


toml = (SRC / "experiments.toml").read_text()
head = (
    "# The shipped data set data/pmma7n_synthetic in lab units (made by make.py from the SI\n"
    "# files with exact decimal arithmetic): g/min, degrees Celsius, mm, cm; CSV in mm and um.\n"
)
(OUT / "experiments.toml").write_text(head + "\n".join(convert(l) for l in toml.split("\n")))
for csv in sorted(SRC.glob("*.csv")):
    rows = csv.read_text().split()
    assert rows[0] == "position_m,diameter_m", rows[0]
    out = ["position_mm,diameter_um"]
    for row in rows[1:]:
        s, d = row.split(",")
        out.append(f"{plain(Decimal(s) * 1000)},{plain(Decimal(d) * 1000000)}")
    (OUT / csv.name).write_text("\n".join(out) + "\n")
