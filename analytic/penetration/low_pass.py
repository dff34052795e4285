"""The lateral overload averaged over one nose length of travel: the raw samples of the 3-D
model switch as the discrete nose points and shank rings enter and leave contact (steps that
the integrator's dense output shows too, not a sampling artefact), and a reader of a figure or
a study wants the load the body feels over its own length.
"""

import numpy as np


def low_pass(history, length):
    """Lateral overload averaged over the time the body takes to travel ``length`` (the nose
    length) around each sample (trapezoidal mean over ``[t - T/2, t + T/2]``, ``T = length /
    speed``): the raw samples switch with the shank's contact."""
    t, g, v = history["t_s"], history["lateral_g"], history["speed_m_s"]
    out = np.empty_like(g)
    for i in range(t.size):
        half = 0.5 * length / max(v[i], 1e-9)
        lo, hi = t[i] - half, t[i] + half
        grid = np.concatenate([[max(lo, t[0])], t[(t > lo) & (t < hi)], [min(hi, t[-1])]])
        values = np.interp(grid, t, g)
        span = grid[-1] - grid[0]
        area = float(np.sum(0.5 * (values[1:] + values[:-1]) * np.diff(grid)))
        out[i] = area / span if span > 0 else g[i]
    return out
