"""The paper's tables as this repository keeps them (results/paper/paper_tables.csv): the one
reader of its SOR sweep counts, and the one spelling of a configuration's tolerance and of
SOR's temporal blocking, for the campaign, the simulation's calibration and extrapolation,
and the plots.

Standard library only.
"""

import csv
import os

PAPER_TABLES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                            "results", "paper", "paper_tables.csv")


def eps_label(text):
    """'0.001', '1e-3', '1.0e-03' -> '1e-3'; '' or None -> ''."""
    if text is None or str(text).strip() == "":
        return ""
    mant, exp = f"{float(text):.0e}".split("e")
    return f"{mant}e{int(exp)}"


def blocking_label(text):
    """SOR's sweeps between exchanges as a configuration tells it apart: '' for the paper's
    pattern (1, or a row from before the CSV had the column) and for the other methods."""
    return "" if text in (None, "", "1") else text


def rows(path=PAPER_TABLES):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def sor_sweeps(path=PAPER_TABLES):
    """{(experiment, eps): (N_S, N_C, steps)} of the paper's SOR runs (Table 1 weak, Table 3
    strong): the sweeps a step as the mean over the run's steps (the strong case's 1058 SOR
    sweeps in 10 steps: 105.8), eps as eps_label spells it."""
    return {(r["experiment"], eps_label(r["eps"])): (int(r["n_sor_total"]) / int(r["steps"]),
                                                     int(r["n_cn_total"]) / int(r["steps"]), int(r["steps"]))
            for r in rows(path) if r["table"] in ("1", "3") and r["method"] == "sor"}
