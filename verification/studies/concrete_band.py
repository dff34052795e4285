r"""Where the concrete cavity model has no self-similar solution: the band near the elastic wave.

``python -m cavex.verification.studies.concrete_band [--out DIR]`` writes
``DIR/no_solution_band.md`` (default ``results/concrete``): for each lock strain of the concrete
model (:data:`cavex.analytic.models.concrete.OPTIONS`), ``f_c`` in :data:`STRENGTHS` and ``rho``
in :data:`DENSITIES`, the band of ``phi = rho V^2/f_c`` between the last elastic-comminuted
solution (its comminution front just short of the elastic wave front ``1/w``) and the first
comminuted shock into undisturbed concrete, where neither structure has a root
(docs/concrete.md "What is left"), and the wall velocity ``sqrt(phi f_c/rho)`` at its lower
edge. The edges are bisected on the structure found (:func:`band`) to 1e-9 of ``phi``.
"""

import argparse
import math
import sys
from pathlib import Path
from types import SimpleNamespace

import numpy as np

from cavex.analytic.concrete_cavity import SUPERSEISMIC, NoSolution, solve
from cavex.analytic.models import get
from cavex.analytic.models.concrete import OPTIONS
from cavex.analytic.penetration.concrete_table import concrete_cavity
from cavex.verification.output.files import write_text_atomic
from cavex.verification.studies.inputs import output_folder

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_OUT = ROOT / "results" / "concrete"
STRENGTHS = (10e6, 15e6, 20e6, 30e6, 40e6, 60e6, 100e6, 200e6)
DENSITIES = (2200.0, 2400.0, 2600.0)
SCAN = np.geomspace(8.0, 2048.0, 40)  # phi scanned for the first structure change
JUMP_BASE = 0.01  # the elastic branch's line through its edge and 1 % of phi below
ELASTIC, SHOCK, NONE = 0, 1, 2


def kind(material, phi):
    """ELASTIC (a structure with an elastic zone ahead), SHOCK (the comminuted shock into
    undisturbed concrete) or NONE (no self-similar solution) at ``phi``."""
    try:
        return SHOCK if solve(material, float(phi)).structure == SUPERSEISMIC else ELASTIC
    except NoSolution:
        return NONE


def _bisect(material, lo, hi, inside):
    """The edge between ``lo`` (``inside`` false) and ``hi`` (true) to 1e-9 of ``hi``."""
    while hi - lo > 1e-9 * hi:
        mid = 0.5 * (lo + hi)
        if inside(kind(material, mid)):
            hi = mid
        else:
            lo = mid
    return lo, hi


def band(material):
    """``(lower, upper)``: the last ``phi`` with an elastic structure and the first with the
    shock into undisturbed concrete, or None when the scan meets no change up to 2048."""
    kinds = [kind(material, phi) for phi in SCAN]
    first = next((i for i, k in enumerate(kinds) if k != ELASTIC), None)
    if first is None or first == 0:
        return None
    lower, _ = _bisect(material, SCAN[first - 1], SCAN[first], lambda k: k != ELASTIC)
    upper = lower * 1.01
    while kind(material, upper) != SHOCK:
        upper *= 1.01
    _, upper = _bisect(material, lower, upper, lambda k: k == SHOCK)
    return lower, upper


def jump(material, lower, upper):
    """``S`` at the band's upper edge against the line through ``S`` at ``lower`` and at
    ``lower (1 - JUMP_BASE)``, relative: how far the shock's branch lies off the elastic one's
    continuation across the band."""
    base = lower * (1.0 - JUMP_BASE)
    s0, s1 = solve(material, base).S, solve(material, lower).S
    continued = s1 + (s1 - s0) / (lower - base) * (upper - lower)
    return solve(material, upper).S / continued - 1.0


def row(option, fc, rho):
    """One line of the table: the band of the concrete ``(fc, rho)`` under ``option``."""
    constants = get("concrete").constants(SimpleNamespace(fc=fc, rho=rho), option)
    material = concrete_cavity(fc, rho, constants)
    edges = band(material)
    if edges is None:
        return f"| {option} | {fc / 1e6:g} | {rho:g} | none up to 2048 | | | |"
    lower, upper = edges
    return (f"| {option} | {fc / 1e6:g} | {rho:g} | {lower:.2f} to {upper:.2f} | "
            f"{upper - lower:.2f} | {math.sqrt(lower * fc / rho):.0f} | "
            f"{jump(material, lower, upper):+.1e} |")


def report():
    lines = ["# The concrete cavity model's band without a self-similar solution", "",
             "Written by `python -m cavex.verification.studies.concrete_band` (docs/concrete.md "
             "\"What is left\"). `phi = rho V^2/f_c`; the wall velocity at the band's lower "
             "edge; the jump: S at the upper edge against the line of the elastic branch "
             "(through its edge and 1 % of phi below) continued across the band.", "",
             "| lock strain | f_c (MPa) | rho (kg/m^3) | band in phi | width "
             "| wall velocity (m/s) | jump |",
             "|---|---:|---:|---|---:|---:|---:|"]
    lines += [row(option, fc, rho) for option in OPTIONS for fc in STRENGTHS
              for rho in DENSITIES]
    return "\n".join(lines) + "\n"


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(DEFAULT_OUT))
    args = parser.parse_args(argv)
    out = output_folder(args)
    if out is None:
        return 2
    out.mkdir(parents=True, exist_ok=True)
    text = report()
    write_text_atomic(out / "no_solution_band.md", text)
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
