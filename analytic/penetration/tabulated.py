r"""Penetration resistance from an FE table of the cavity-wall stress ``sigma_r(V, L)``.

``force(L, V)`` is the nose integral of Eq. (7), ``F = sum_k w_k sigma_r(V cos(phi_k), L)``
(:func:`cavex.analytic.penetration.nose.nose_rule`), with ``sigma_r`` interpolated from the table:

- in ``L``: a monotone cubic (PCHIP) in ``L`` on each wall-layer segment separately. The
  table's depth grid contains the switch depths ``H_i + l - r`` (where ``sigma_r`` is continuous
  but its slope is not: the shell of the upper layer thins to nothing), so no piece straddles a
  kink of that kind; PCHIP does not overshoot at the kinks inside a segment (the plastic zone
  reaching an interface);
- in ``V``: a PCHIP in ``V^2``. ``sigma_r`` is affine in ``V^2`` in the quasi-static closed
  form, which PCHIP in ``V^2`` reproduces exactly, and nearly so in the dynamic one and the FE.
  The table must contain ``V = 0``: the nose tip sees ``V cos(phi) -> 0`` and nothing is
  extrapolated.

Measured interpolation errors are in ``docs/verification.md`` and ``tests/test_table.py``; a
shot's own estimate (the table with every other node in ``V`` and in ``L``) is
:func:`cavex.analytic.penetration.table_error.interpolation_error`.
The crater stage uses the table's first-layer-alone column, as the closed form uses the
single-medium model of the first layer (paper Eq. 34).

The resistance refuses a table built for another target (fingerprint mismatch), with failed
cells, or queried outside its depth or velocity range, with a one-line
:class:`~cavex.errors.CavexInputError`.
"""

import json

import numpy as np
from scipy.interpolate import PchipInterpolator

from cavex.analytic.geometry import switch_depths, wall_layer
from cavex.analytic.penetration.integrator import penetrate
from cavex.analytic.penetration.nose import nose_rule
from cavex.analytic.penetration.resistance import Resistance
from cavex.config import fingerprint, fingerprint_data
from cavex.errors import CavexInputError, require_choice
from cavex.netcdf3 import read_netcdf3

METHODS = ("pchip", "linear")
NODE_TOLERANCE = 1e-6  # m: a switch node this close to a segment end belongs to both segments


class TabulatedResistance(Resistance):
    """The integrator's :class:`~cavex.analytic.penetration.resistance.Resistance` from a
    ``sigma_r`` table.

    Parameters
    ----------
    table : xarray.Dataset or cavex.netcdf3.PlainDataset
        From :func:`cavex.verification.fedata.table.build_table` (``tabulate``),
        :func:`load_table` or :func:`read_table`.
    target, projectile : Target, Projectile
        Must be those the table was built for (checked by fingerprint).
    depth_method, velocity_method : {"pchip", "linear"}
        Interpolation in ``L`` (per wall-layer segment) and in ``V^2``; "pchip" is the
        default and the measured choice, "linear" is kept for the error study.
    """

    def __init__(self, table, target, projectile, *, depth_method="pchip",
                 velocity_method="pchip"):
        require_choice(depth_method, METHODS, "depth_method")
        require_choice(velocity_method, METHODS, "velocity_method")
        self.name = table.attrs.get("source", "in-memory table")
        check_fingerprint(table, target, projectile, self.name)
        self.target, self.projectile = target, projectile
        self.velocity_method = velocity_method
        self.velocities = np.asarray(table["velocity"], dtype=float)
        self._v2 = self.velocities ** 2
        self.depths = np.asarray(table["depth"], dtype=float)
        _check_table(table, self.name, switch_depths(target, projectile))
        sigma = np.asarray(table["sigma_r"], dtype=float)  # (velocity, depth)
        self._bounds, self._pieces = _depth_pieces(self.depths, sigma.T, target, projectile,
                                                   depth_method)
        self._first = np.asarray(table["sigma_r_first_layer"], dtype=float)
        self._cosines, self._weights = nose_rule(projectile)
        last = switch_depths(target, projectile)
        self._last_layer_alone = not last or self.depths[-1] >= last[-1]

    def wall_stress(self, depth, velocities):
        """Interpolated ``sigma_r`` (Pa) at nose depth ``depth`` for an array of velocities."""
        depth = self._check_depth(depth)
        k = min(max(int(np.searchsorted(self._bounds, depth, side="right")) - 1, 0),
                len(self._pieces) - 1)
        return self._in_velocity(self._pieces[k](depth), velocities)

    @property
    def max_velocity(self):
        """Largest projectile velocity (m/s) the table answers for: the nose sees at most
        ``V cos(phi_1)`` at the first quadrature node (0.543 for the Table 1 ogive)."""
        return self.velocities[-1] / self._cosines.max()

    def force(self, depth, velocity):
        """Axial nose force (N), Eq. (7) with the tabulated ``sigma_r``."""
        self._check_velocity(velocity)
        return float(self._weights @ self.wall_stress(depth, velocity * self._cosines))

    def label(self, depth, velocity):
        """Wall layer name and "(table)": phases end where the wall layer changes."""
        self._check_depth(depth)
        index = wall_layer(self.target, self.projectile, depth)
        return f"{self.target.layer_name(index)} (table)"

    def crater_force(self, velocity):
        """Nose force of the first layer alone (the table's first-layer column)."""
        self._check_velocity(velocity)
        return float(self._weights @ self._in_velocity(self._first, velocity * self._cosines))

    def _in_velocity(self, column, velocities):
        v = np.asarray(velocities, dtype=float)
        top = self.velocities[-1]
        if np.any(v > top * (1.0 + 1e-12)) or np.any(v < 0.0):
            bad = float(v.max() if np.any(v > top) else v.min())
            raise CavexInputError(f"velocity V = {bad:.6g} m/s is outside the table's range "
                                  f"[0, {top:g}] m/s (table '{self.name}')")
        x, xq = self._v2, np.minimum(v ** 2, self._v2[-1])
        if self.velocity_method == "linear":
            return np.interp(xq, x, column)
        return pchip(x, column, xq)

    def _check_velocity(self, velocity):
        if not 0.0 <= velocity <= self.max_velocity:
            raise CavexInputError(
                f"velocity V = {velocity:.6g} m/s is outside the table's range [0, "
                f"{self.max_velocity:.6g}] m/s (the nose sees up to V cos(phi) = "
                f"{self._cosines.max():.4f} V; table velocities reach {self.velocities[-1]:g} "
                f"m/s; table '{self.name}')")

    def _check_depth(self, depth):
        """The depth to interpolate at; refuses depths outside the table.

        Past the last switch depth the spherical problem is the last layer alone, the same
        for every ``L``, so a table reaching it answers for all deeper ``L`` exactly.
        """
        lo, hi = self.depths[0], self.depths[-1]
        if lo <= depth <= hi:
            return depth
        if depth > hi and self._last_layer_alone:
            return hi
        top = "inf" if self._last_layer_alone else f"{hi:g}"
        raise CavexInputError(f"nose depth L = {depth:.6g} m is outside the table's depth "
                              f"range [{lo:g}, {top}] m (table '{self.name}')")


def pchip(x, y, xq):
    """Monotone cubic (Fritsch-Butland slopes, as :class:`scipy.interpolate.PchipInterpolator`)
    through ``(x, y)`` evaluated at ``xq`` inside ``[x[0], x[-1]]``; a lean version for the hot
    path (``scipy``'s constructor costs ~1 ms per call, this ~30 us).
    """
    h = np.diff(x)
    delta = np.diff(y) / h
    d = np.zeros_like(y)
    if x.size == 2:
        d[:] = delta[0]
    else:
        w1, w2 = 2.0 * h[1:] + h[:-1], h[1:] + 2.0 * h[:-1]
        same = (delta[:-1] * delta[1:]) > 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            harmonic = (w1 + w2) / (w1 / delta[:-1] + w2 / delta[1:])
        d[1:-1] = np.where(same, harmonic, 0.0)
        d[0] = _pchip_end(h[0], h[1], delta[0], delta[1])
        d[-1] = _pchip_end(h[-1], h[-2], delta[-1], delta[-2])
    k = np.clip(np.searchsorted(x, xq, side="right") - 1, 0, x.size - 2)
    t = (xq - x[k]) / h[k]
    h00, h10 = (1.0 + 2.0 * t) * (1.0 - t) ** 2, t * (1.0 - t) ** 2
    h01, h11 = t ** 2 * (3.0 - 2.0 * t), t ** 2 * (t - 1.0)
    return h00 * y[k] + h10 * h[k] * d[k] + h01 * y[k + 1] + h11 * h[k] * d[k + 1]


def _pchip_end(h0, h1, m0, m1):
    """One-sided three-point end slope with the shape-preserving limits (as scipy)."""
    d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1)
    if np.sign(d) != np.sign(m0):
        return 0.0
    if np.sign(m0) != np.sign(m1) and abs(d) > abs(3.0 * m0):
        return 3.0 * m0
    return d


def _depth_pieces(depths, sigma, target, projectile, method):
    """Interpolants in ``L`` between consecutive switch depths: bounds and callables.

    ``sigma`` has shape ``(depth, velocity)``; each piece returns the column at ``L``.
    """
    cuts = [s for s in switch_depths(target, projectile) if depths[0] < s < depths[-1]]
    bounds = [depths[0], *cuts, depths[-1]]
    pieces = []
    for lo, hi in zip(bounds[:-1], bounds[1:], strict=True):
        inside = (depths >= lo - NODE_TOLERANCE) & (depths <= hi + NODE_TOLERANCE)
        x, y = depths[inside], sigma[inside]
        pieces.append(PchipInterpolator(x, y, axis=0) if method == "pchip" and x.size > 2
                      else _linear(x, y))
    return np.array(bounds[:-1]), pieces


def _linear(x, y):
    def column(depth):
        return np.array([np.interp(depth, x, y[:, i]) for i in range(y.shape[1])])

    return column


def _check_table(table, name, switches):
    """Refuse tables that cannot be interpolated honestly."""
    v, d = np.asarray(table["velocity"]), np.asarray(table["depth"])
    if not (np.all(np.isfinite(v)) and np.all(np.isfinite(d))):
        raise CavexInputError(f"table '{name}' has non-finite velocity or depth coordinates")
    if v.size < 2 or v[0] != 0.0 or np.any(np.diff(v) <= 0):
        raise CavexInputError(f"table '{name}' velocities must increase from V = 0 (the nose "
                              f"tip sees V cos(phi) -> 0); it has {v[0]:g}..{v[-1]:g} m/s")
    if d.size < 2 or np.any(np.diff(d) <= 0):
        raise CavexInputError(f"table '{name}' needs at least two increasing depths")
    missing = [s for s in switches
               if d[0] < s < d[-1] and not np.any(np.abs(d - s) <= NODE_TOLERANCE)]
    if missing:
        raise CavexInputError(f"table '{name}' lacks the wall-layer switch depth(s) "
                              f"{', '.join(f'{s:g}' for s in missing)} m; rebuild it with "
                              "build_table, which inserts them")
    failed = int(np.sum(table["failed"])) + int(np.sum(table["failed_first_layer"]))
    values = np.concatenate([np.ravel(table["sigma_r"]),
                             np.ravel(table["sigma_r_first_layer"])])
    missing = int(np.sum(~np.isfinite(values)))
    if failed or missing:
        raise CavexInputError(f"table '{name}' has {failed} failed FE cell(s) and {missing} "
                              "non-finite wall stress(es); see its 'failures' attribute and "
                              "rebuild those cells")
    if np.any(values <= 0.0):
        raise CavexInputError(f"table '{name}' has {int(np.sum(values <= 0.0))} wall "
                              "stress(es) <= 0 (cavex tables hold compressive sigma_r > 0, Pa)")


def check_fingerprint(table, target, projectile, name="in-memory table"):
    """Raise :class:`CavexInputError` naming what differs if ``table`` is for another target."""
    if table.attrs.get("fingerprint") == fingerprint(target, projectile):
        return
    stored = json.loads(table.attrs.get("fingerprint_data", "{}"))
    differences = _differences(stored, fingerprint_data(target, projectile))
    raise CavexInputError(f"table '{name}' was built for another target: "
                          f"{'; '.join(differences[:3]) or 'fingerprint differs'}")


def _differences(table, given, where=""):
    """``path: table X, given Y`` for every differing leaf of two nested dicts/lists."""
    if isinstance(table, dict) and isinstance(given, dict):
        keys = sorted(set(table) | set(given))
        return [d for k in keys for d in _differences(table.get(k), given.get(k),
                                                      f"{where}.{k}" if where else k)]
    if isinstance(table, list) and isinstance(given, list) and len(table) == len(given):
        return [d for i, (a, b) in enumerate(zip(table, given, strict=True))
                for d in _differences(a, b, f"{where}[{i}]")]
    if table == given:
        return []
    if isinstance(table, list) and isinstance(given, list):
        return [f"{where}: table has {len(table)}, given {len(given)}"]
    return [f"{where}: table {table!r}, given {given!r}"]


# --- penetration and comparison ---------------------------------------------------------------

def penetrate_with_table(target, projectile, table_path, crater="nose-base"):
    """Trajectory through ``target`` with the FE-tabulated resistance read from ``table_path``."""
    resistance = TabulatedResistance(read_table(table_path), target, projectile)
    return penetrate(target, projectile, resistance, crater=crater)


def trajectory_summary(trajectory, target):
    """Phase ends, final depth and time, and the state when the nose tip reaches ``H1``."""
    phases = [{"label": p.label, "end_depth_m": float(p.end_depth),
               "end_velocity_m_s": float(p.end_velocity), "end_time_s": float(p.end_time),
               "end_reason": p.end_reason} for p in trajectory.phases]
    at_h1 = None
    if target.interface_depths:
        at_h1 = next(({"depth_m": p["end_depth_m"], "velocity_m_s": p["end_velocity_m_s"],
                       "time_s": p["end_time_s"]} for p in phases
                      if p["end_reason"] == "nose tip reached interface 1"), None)
    return {"phases": phases, "final_depth_m": float(trajectory.depth[-1]),
            "final_time_s": float(trajectory.t[-1]), "at_H1": at_h1}


def read_table(path):
    """Read a table written by ``write_table`` as a :class:`cavex.netcdf3.PlainDataset`
    (fully into memory; the file is closed; no xarray), with its path in the attribute
    ``source``; a file that is not a cavex table is refused (:class:`CavexInputError`)."""
    try:
        table = read_netcdf3(path)
    except Exception as exc:  # a truncated or foreign file fails in many ways inside the reader
        reason = str(exc).strip().splitlines()[0] if str(exc).strip() else type(exc).__name__
        raise CavexInputError(f"table '{path}' cannot be read as a netCDF3 table: "
                              f"{reason}") from None
    missing = [k for k in ("velocity", "depth", "sigma_r", "sigma_r_first_layer",
                           "wall_layer", "failed", "failed_first_layer") if k not in table]
    if missing or "fingerprint" not in table.attrs:
        raise CavexInputError(f"'{path}' is not a cavex table (missing "
                              f"{', '.join(missing) or 'fingerprint attribute'})")
    table.attrs["source"] = str(path)
    return table


def load_table(path):
    """:func:`read_table` as an :class:`xarray.Dataset`."""
    return read_table(path).dataset()
