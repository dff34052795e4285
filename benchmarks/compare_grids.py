"""Cell-by-cell comparison of two FE grids (``results/verification/grid.nc`` or a table).

Prints, for every FE answer (``sigma_r``, ``plastic_radius``) the largest relative change
between the two files and the largest ratio of the change of ``sigma_r`` to the cell's error
estimate in the old file, and lists the cells with the largest ratios. A written estimate of 0
(below the quantum of 1e-5 that estimates are written to) counts as half the quantum. The same
ratio against the larger of the two files' estimates is printed too.

Run: ``python benchmarks/compare_grids.py OLD.nc NEW.nc`` (e.g. ``git show
main:results/verification/grid.nc > /tmp/old.nc`` first).
"""

import argparse

import numpy as np
import xarray as xr

QUANTUM = 1e-5  # cavex.verification.output.number_format.ESTIMATE_DECIMALS


def compare(old, new):
    """Per cell ``(relative change of sigma_r, change / estimate)`` and a summary dict."""
    ok = (old["failed"] == 0) & (new["failed"] == 0)
    s0, s1 = old["sigma_r"].where(ok), new["sigma_r"].where(ok)
    change = np.abs(s1 - s0) / np.abs(s0)
    estimate = np.maximum(old["error_estimate"], QUANTUM / 2).where(ok)
    ratio = change / estimate
    either = change / np.maximum(estimate, new["error_estimate"])
    b0, b1 = old["plastic_radius"].where(ok), new["plastic_radius"].where(ok)
    summary = {
        "cells": int(ok.sum()),
        "failed_old": int((old["failed"] != 0).sum()),
        "failed_new": int((new["failed"] != 0).sum()),
        "cells_changed": int((change > 0).sum()),
        "max_relative_change_sigma_r": float(change.max()),
        "max_change_over_estimate": float(ratio.max()),
        "cells_above_their_estimate": int((ratio > 1).sum()),
        "max_change_over_larger_estimate": float(either.max()),
        "max_relative_change_plastic_radius": float((np.abs(b1 - b0) / np.abs(b0)).max()),
        "max_estimate_old": float(old["error_estimate"].max()),
        "max_estimate_new": float(new["error_estimate"].max()),
    }
    return change, ratio, summary


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("old")
    parser.add_argument("new")
    args = parser.parse_args()
    with xr.open_dataset(args.old) as old, xr.open_dataset(args.new) as new:
        old, new = old.load(), new.load()
    change, ratio, summary = compare(old, new)
    for key, value in summary.items():
        print(f"{key:36s} {value:.4g}" if isinstance(value, float) else f"{key:36s} {value}")
    worst = ratio.stack(cell=ratio.dims).dropna("cell").sortby(
        ratio.stack(cell=ratio.dims).dropna("cell"), ascending=False)[:5]
    print("largest change / estimate (V m/s, L m: ratio, relative change, estimates old/new):")
    for cell in worst:
        v, d = float(cell["velocity"]), float(cell["depth"])
        print(f"  V = {v:g}, L = {d:.6g}: {float(cell):.3g}, "
              f"{float(change.sel(velocity=v, depth=d)):.3g}, "
              f"{float(old['error_estimate'].sel(velocity=v, depth=d)):.3g} / "
              f"{float(new['error_estimate'].sel(velocity=v, depth=d)):.3g}")


if __name__ == "__main__":
    main()
