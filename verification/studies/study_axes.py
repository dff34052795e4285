"""Axes for the oblique study's figures where a few large values would swamp the small ones:
a symmetric-log axis whose ticks are labelled on both sides of zero (plain numbers, the linear
part's halves and ones, then decades), and a broken axis (two stacked panels sharing x) that
gives the large values their own panel.
"""

import math

import numpy as np


def symlog_axis(ax, values, linthresh=1.0):
    """Make the y axis of ``ax`` symmetric-log (linear within ``+-linthresh``) around
    ``values`` (the data drawn), with ticks labelled as plain numbers on each side the data
    reach: ``0``, ``+-linthresh/2``, ``+-linthresh``, then ``+-linthresh 10^k`` up to the
    first beyond the data. The limits hold the data and at least ``+-linthresh`` on a side
    with data, so the negative side is labelled as the positive one is."""
    from matplotlib.ticker import FixedLocator, FuncFormatter, NullLocator

    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    ax.set_yscale("symlog", linthresh=linthresh)
    lo, hi = float(min(v.min(), 0.0)), float(max(v.max(), 0.0))
    ticks, limits = [0.0], [0.0, 0.0]
    for side, end in ((1.0, hi), (-1.0, -lo)):
        if end <= 0.0:
            continue
        ticks += [side * 0.5 * linthresh, side * linthresh]
        k = 1
        while linthresh * 10.0 ** (k - 1) < end:
            ticks.append(side * linthresh * 10.0 ** k)
            k += 1
        reach = max(end * 1.25, linthresh * 1.1)  # a margin in the log part, or past +-1
        limits[side > 0] = side * reach
    if lo == 0.0:  # nothing below zero: a margin under it in the linear part
        limits[0] = -0.1 * linthresh
    if hi == 0.0:
        limits[1] = 0.1 * linthresh
    ax.set_ylim(*limits)
    ax.yaxis.set_major_locator(FixedLocator([t for t in ticks
                                             if limits[0] <= t <= limits[1]]))
    ax.yaxis.set_major_formatter(FuncFormatter(lambda x, _: f"{x:g}"))
    ax.yaxis.set_minor_locator(NullLocator())


def split_at_gap(values, factor=2.5, most=0.25):
    """The magnitude that separates the few large ``values`` from the rest: the widest gap
    (as a ratio) between successive magnitudes, if it is wider than ``factor`` and at most
    ``most`` of the values lie above it; None when no such gap (one panel is enough)."""
    m = np.sort(np.abs([x for x in values if x is not None and math.isfinite(x)]))
    m = m[m > 0.0]
    if m.size < 2:
        return None
    ratios = m[1:] / m[:-1]
    best = None
    for k in np.argsort(ratios)[::-1]:
        above = m.size - (k + 1)
        if ratios[k] < factor:
            break
        if above <= most * m.size:
            best = float(math.sqrt(m[k] * m[k + 1]))
            break
    return best


def broken_axes(fig, cell, values, heights=(1, 2)):
    """Two stacked axes in the gridspec ``cell`` of ``fig`` sharing x, for data ``values``
    split by :func:`split_at_gap`: the upper panel (``heights[0]``) for the large values, the
    lower (``heights[1]``) for the rest, the usual diagonal marks between them; draw every
    curve on both. Returns ``(upper, lower)``, or ``(None, axes)`` when there is no gap."""
    cut = split_at_gap(values)
    if cut is None:
        return None, fig.add_subplot(cell)
    inner = cell.subgridspec(2, 1, height_ratios=heights, hspace=0.08)
    lower = fig.add_subplot(inner[1])
    upper = fig.add_subplot(inner[0], sharex=lower)
    v = np.asarray([x for x in values if x is not None and math.isfinite(x)], dtype=float)
    small, large = v[np.abs(v) < cut], v[np.abs(v) >= cut]
    pad = 0.08 * max(np.ptp(small), 1e-9)
    lower.set_ylim(min(small.min(), 0.0) - pad, max(small.max(), 0.0) + pad)
    if large.min() > 0.0:  # from the cut up: a curve leaving the lower panel continues
        upper.set_ylim(cut, large.max() + 0.08 * (large.max() - cut))
    else:
        pad = 0.08 * max(np.ptp(large), 0.1 * np.abs(large).max())
        upper.set_ylim(large.min() - pad, large.max() + pad)
    upper.spines["bottom"].set_visible(False)
    lower.spines["top"].set_visible(False)
    upper.tick_params(axis="x", which="both", bottom=False, labelbottom=False)
    marks = {"marker": [(-1, -0.5), (1, 0.5)], "markersize": 9, "linestyle": "none",
             "color": "k", "mec": "k", "mew": 1, "clip_on": False}
    upper.plot([0, 1], [0, 0], transform=upper.transAxes, **marks)
    lower.plot([0, 1], [1, 1], transform=lower.transAxes, **marks)
    return upper, lower
