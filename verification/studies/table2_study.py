r"""Which reading of She (2020) reproduces which row of its Table 2 (issue 2, item 6).

The paper leaves several choices undefined or ambiguous. Each *reading* below fixes every one of
them to a discrete alternative that the paper's text (or the cavity-expansion literature it
cites) allows; nothing is a continuous parameter fitted to the table.

- ``epsilon`` — ``eps_i = V/c_i`` is never given a formula (Eq. 18). The elastic zone yields at
  ``b`` when ``(2E/3)(a/b)^k = Y``: ``k = 3`` for the incompressible sphere (the paper's printed
  ``2/3`` in ``A``), ``k = 2`` for the incompressible cylinder (the cylindrical cavity-expansion
  theory of its ref. 1); ``Y`` is either the yield limit ``tau`` of Eq. (2) or the uniaxial
  strength ``sigma_c = 3 tau/(3 - lam)`` of the same equation.
- ``crater`` — ``L_c = 4.5 r`` measured from the nose base (tip at ``4.5 r + l``) or the tip.
- ``crater_medium`` — Eq. (34) says ``C_A, C_B`` come "from Eq. (29)", which is printed with the
  soil's subscripts; the text means the concrete ("single concrete medium"), but the literal
  reading (soil) is also run.
- ``crater_law`` — ``"linear"``: ``m L'' = -K L`` (Eqs. 31-34); ``"tunnel"``: no linear stage,
  the Eq. (29) force ``C_A + C_B V^2`` of the concrete acts from the surface to ``L_c`` (what
  Eq. 15 gives if the crater is not treated separately).
- ``eq19`` — ``"corrected"`` (``3 tau/(rho eps^2 E)``, as Eqs. 23, 25, 26, 28) or ``"printed"``.
- ``eq29`` — ``"printed"`` (with its stray ``+ eps^(-alpha lam)``) or ``"derived"`` (without).
- ``normalise`` — which ``tau_0i``, ``rho_i`` enter ``C_A``, ``C_B`` (Eqs. 13-14): ``"own"``,
  those the equation normalises ``S`` by (so ``sigma_r`` is the printed one); ``"wall"``, those of
  the layer the nose is in (``i`` read as the medium being penetrated), paired with the printed
  ``A``, ``B`` — this changes ``sigma_r`` in Eqs. 23-25 and 28.
- ``switch`` — when the equations of the next layer take over: ``"nose-tip"`` (the paper's
  section titles, "entering the macadam layer") or ``"cavity"`` (the cavity of Fig. 3, centred at
  the warhead bottom, keeps concrete at its wall until ``h1 = H1 - L + l`` falls to ``r``; the
  three-layer equations are used until then).

The rows are mapped as :func:`cavex.verification.studies.table2.table2_rows` does: crater end; end
of state (a) (``L = L1``); nose tip at ``H1``; rest. Besides the end-to-end run, every reading is
also run *segment by segment* from the paper's own previous row (``segment_rows``), which
isolates the law of each phase from the error accumulated before it.
"""

import itertools
from dataclasses import asdict, dataclass, replace
from functools import partial

from cavex.analytic import paper_model as pm
from cavex.analytic.penetration.integrator import (
    ATOL,
    RTOL,
    crater_depth,
    integrate,
    penetrate,
)
from cavex.analytic.penetration.nose import ogive_coefficients
from cavex.analytic.penetration.resistance import ClosedFormResistance, Resistance
from cavex.errors import require
from cavex.verification.studies.table2 import (
    PAPER_REF10_EXIT_VELOCITY,
    PAPER_TABLE2,
    ROW_KEYS,
    phase_row,
    row_score,
    table2_rows,
)

CHOICES = {
    "epsilon": pm.EPSILON_READINGS,
    "crater": ("nose-base", "nose-tip"),
    "crater_medium": ("concrete", "soil"),
    "crater_law": ("linear", "tunnel"),
    "eq19": ("corrected", "printed"),
    "eq29": ("printed", "derived"),
    "normalise": ("own", "wall"),
    "switch": ("nose-tip", "cavity"),
}
# The choices the text allows. The others are diagnostics the text contradicts: Lc from the nose
# tip (Table 2's own 0.12 m / 0.12 ms rule it out), the soil in the crater (the text: the crater
# is that of the single concrete medium, Fig. 4) and no linear crater stage (Eqs. 31-34).
ADMISSIBLE = {**CHOICES, "crater": ("nose-base",), "crater_medium": ("concrete",),
              "crater_law": ("linear",)}
SEGMENT_RTOL = 1e-10  # the segments' relative tolerance (the full runs: the integrator's own)


@dataclass(frozen=True)
class Reading:
    """One discrete reading of the paper's undefined choices (see the module docstring)."""

    name: str
    epsilon: str = "cylindrical"
    crater: str = "nose-base"
    crater_medium: str = "concrete"
    crater_law: str = "linear"
    eq19: str = "corrected"
    eq29: str = "printed"
    normalise: str = "own"
    switch: str = "nose-tip"

    def __post_init__(self):
        for key, options in CHOICES.items():
            value = getattr(self, key)
            require(value in options, key, "one of " + ", ".join(map(repr, options)), value)

    def differences(self):
        """Choices that differ from the base reading ``C`` (cylindrical, tau, nose base)."""
        base = asdict(Reading("base"))
        return {k: v for k, v in asdict(self).items() if k != "name" and v != base[k]}


def _readings():
    base = Reading("C: cylindrical eps (tau), Lc from nose base")
    return (
        Reading("Q: quasi-static eps (tau)", epsilon="quasi-static"),
        Reading("Qs: quasi-static eps (sigma_c)", epsilon="quasi-static-sigma_c"),
        base,
        Reading("Cs: cylindrical eps (sigma_c)", epsilon="cylindrical-sigma_c"),
        replace(base, name="C-tip: Lc from nose tip", crater="nose-tip"),
        replace(base, name="C-soil: crater Eq. 29 with soil (literal)", crater_medium="soil"),
        replace(base, name="C-tunnel: Eq. 29 force over the crater", crater_law="tunnel"),
        replace(base, name="C-19p: Eq. 19 as printed", eq19="printed"),
        replace(base, name="C-29d: Eq. 29 without stray term", eq29="derived"),
        replace(base, name="C-wall: tau, rho of the nose's layer", normalise="wall"),
        Reading("Cs-29d: sigma_c eps, Eq. 29 derived", epsilon="cylindrical-sigma_c",
                eq29="derived"),
        Reading("Cs-tunnel: sigma_c eps, Eq. 29 over crater", epsilon="cylindrical-sigma_c",
                crater_law="tunnel"),
    )


READINGS = _readings()


def phase_depth_l1(target, projectile, epsilon):
    """``L1 = H1 + l - r/eps1`` (Eq. 18) under a reading of ``eps``."""
    eps1 = pm.layer_epsilon(target.layers[0], epsilon)
    return target.interface_depths[0] + projectile.l - projectile.r / eps1


def eq19_printed(m1, m2, m3, eps1, eps2, eps3, r, h1, h2):
    """Eq. (19) with ``B``'s elastic-zone inertia as printed, ``3 tau01/(rho1 E1)[...]``."""
    A, B, tau, rho = pm.eq19(m1, m2, m3, eps1, eps2, eps3, r, h1, h2)
    bracket = m1.rho + r / (eps1 * h1) * (m2.rho - m1.rho) + r / (eps1 * h2) * (m3.rho - m2.rho)
    inertia = 3 * m1.tau / (m1.rho * m1.E) * bracket
    p1 = pm.alpha_lambda(m1)
    return A, B + inertia * (1.0 - eps1 ** -2) * eps1 ** -p1, tau, rho


def eq29_reading(material, eps, variant):
    """Eq. (29) ``(A, B, tau, rho)``: ``"printed"`` or ``"derived"`` (stray term removed)."""
    A, B, tau, rho = pm.eq29(material, eps)
    if variant == "derived":
        B -= eps ** -pm.alpha_lambda(material)
    return A, B, tau, rho


class ReadingResistance(Resistance):
    """The paper model (Eqs. 19-29, 34) under one :class:`Reading`, as the integrator's
    :class:`~cavex.analytic.penetration.resistance.Resistance`. The case selection is that of
    :func:`cavex.analytic.paper_model.paper_coefficients` (nose-tip switch, ``L1``-``L4``), with
    the reading's ``eps`` per layer and its variants of Eqs. 19 and 29 and of ``tau_0i``,
    ``rho_i`` in Eqs. 13-14.
    """

    def __init__(self, target, projectile, reading):
        pm.check_target(target)
        for index, material in enumerate(target.layers):
            pm.check_paper_material(material, index)
        self.target, self.projectile, self.reading = target, projectile, reading
        self.eps = [pm.layer_epsilon(m, reading.epsilon) for m in target.layers]
        self._crater_medium = None

    def first_layer(self, depth):
        """Index of the layer whose equations apply at nose-tip depth ``depth``."""
        if self.reading.switch == "nose-tip":
            return self.target.layer_at(depth)
        r, nose = self.projectile.r, self.projectile.l
        return sum(1 for H in self.target.interface_depths if H - depth + nose <= r)

    def coefficients(self, depth):
        """``(A, B, tau, rho, equation, state)`` at nose-tip depth ``depth``."""
        first = self.first_layer(depth)
        forms = {29: partial(eq29_reading, variant=self.reading.eq29)}
        if self.reading.eq19 == "printed":
            forms[19] = eq19_printed
        return pm.select_equation(self.target.layers[first:], self.eps[first:], self.projectile.r,
                                  self.projectile.l, depth, self.target.interface_depths[first:],
                                  forms)

    def _force_coefficients(self, depth):
        A, B, tau, rho, _, _ = self.coefficients(depth)
        if self.reading.normalise == "wall":
            wall = self.target.layers[self.first_layer(depth)]
            tau, rho = wall.tau, wall.rho
        return ogive_coefficients(self.projectile, A, B, tau, rho)

    def force(self, depth, velocity):
        """Axial nose force (N), ``C_A + C_B V^2`` (Eqs. 12-14)."""
        c_a, c_b = self._force_coefficients(depth)
        return c_a + c_b * velocity ** 2

    def label(self, depth, velocity):
        """The paper's equation and response state, e.g. ``"Eq. 19 (a)"``."""
        _, _, _, _, equation, state = self.coefficients(depth)
        return f"Eq. {equation} ({state})"

    def crater_force(self, velocity):
        """Eq. (29) force of the crater medium alone (concrete, or the soil in the literal
        reading): this reading's force on the single-medium target of that layer."""
        if self._crater_medium is None:
            index = 0 if self.reading.crater_medium == "concrete" else -1
            self._crater_medium = ReadingResistance(self.target.single(index), self.projectile,
                                                    self.reading)
        return self._crater_medium.force(0.0, velocity)


class CraterAsTunnel(Resistance):
    """Wraps a resistance: the crater force ``crater_force(V)`` acts from the surface to ``L_c``.

    Used with ``penetrate(..., crater=None)``: above ``L_c`` the label is ``"crater"`` and the
    force is the single-medium Eq. (29) force; below, the wrapped resistance.
    """

    def __init__(self, resistance, depth):
        self.inner, self.depth = resistance, depth

    def force(self, depth, velocity):
        """Crater force above ``L_c``, the wrapped force below."""
        if depth < self.depth:
            return self.inner.crater_force(velocity)
        return self.inner.force(depth, velocity)

    def label(self, depth, velocity):
        """``"crater"`` above ``L_c``, the wrapped label below."""
        return "crater" if depth < self.depth else self.inner.label(depth, velocity)

    def crater_force(self, velocity):
        """The wrapped crater force."""
        return self.inner.crater_force(velocity)


def run_reading(target, projectile, reading, rtol=RTOL, atol=ATOL):
    """Trajectory of the paper model under ``reading``."""
    resistance = ReadingResistance(target, projectile, reading)
    if reading.crater_law == "tunnel":
        wrapped = CraterAsTunnel(resistance, crater_depth(projectile, reading.crater))
        return penetrate(target, projectile, wrapped, crater=None, rtol=rtol, atol=atol)
    return penetrate(target, projectile, resistance, crater=reading.crater, rtol=rtol, atol=atol)


def _paper_start(row):
    """The integrator's start state ``(t, L, V)`` of a row of the paper's Table 2."""
    return row["time_s"], row["depth_m"], row["velocity_m_s"]


def segment_rows(target, projectile, reading):
    """Rows 2-4 each integrated from the paper's previous row (row 1 as in the full run).

    Row 2 runs from the paper's crater exit to this reading's ``L1``, row 3 from the paper's
    ``(0.40 m, 506.4 m/s)`` to ``H1``, row 4 from the paper's ``(0.65 m, 284.3 m/s)`` to rest.
    """
    resistance = ReadingResistance(target, projectile, reading)
    ends = (phase_depth_l1(target, projectile, reading.epsilon), target.interface_depths[0],
            None)
    return [phase_row(integrate(resistance, projectile.m, _paper_start(PAPER_TABLE2[k]),
                                stop_depth=end, rtol=SEGMENT_RTOL)[0])
            for k, end in enumerate(ends)]


def _compare(name, ours, detail):
    rows = []
    for paper, mine in zip(PAPER_TABLE2, ours, strict=True):
        rows.append({"reading": name, "row": paper["phase"], "detail": detail,
                     "paper": {k: paper[k] for k in ROW_KEYS}, "ours": mine})
    return rows


def table2_study(target, projectile, readings=READINGS, derived=("quasi-static", "dynamic"),
                 segments=True):
    """Run every reading and return its four rows beside the paper's Table 2.

    Parameters
    ----------
    target, projectile : Target, Projectile
        The paper's Table 1 (``cavex.config.load_config()``).
    readings : sequence of Reading
        Paper-model readings to run end to end.
    derived : sequence of str
        Boundary conventions of the derived model to run as well ("quasi-static", "dynamic").
    segments : bool
        Also run rows 2-4 of each reading from the paper's previous row (``segment_rows``).

    Returns
    -------
    list of dict
        One dict per (run, row): ``reading``, ``row`` (1-4), ``detail`` (``"full"`` or
        ``"segment"``), ``paper`` and ``ours`` (``{"depth_m", "velocity_m_s", "time_s"}``, or
        ``None`` where the trajectory has no such phase).
    """
    rows = []
    for reading in readings:
        full = table2_rows(run_reading(target, projectile, reading))
        rows += _compare(reading.name, full, "full")
        if segments:
            rows += _compare(reading.name, [full[0], *segment_rows(target, projectile, reading)],
                             "segment")
    for boundary in derived:
        resistance = ClosedFormResistance(target, projectile, "derived", boundary)
        trajectory = penetrate(target, projectile, resistance, crater="nose-base")
        rows += _compare(f"derived ({boundary}), Lc from nose base",
                         table2_rows(trajectory),
                         "full")
    return rows


def relative_error(ours, paper, key):
    """``ours/paper - 1`` (``None`` for the stop velocity, where the paper's value is 0)."""
    if ours is None or paper[key] == 0.0:
        return None
    return ours[key] / paper[key] - 1.0


def factorial_readings(axes=CHOICES):
    """Every combination of the discrete choices in ``axes`` as a :class:`Reading`."""
    keys = tuple(axes)
    readings = []
    for values in itertools.product(*(axes[k] for k in keys)):
        choice = dict(zip(keys, values, strict=True))
        name = " ".join(f"{k}={v}" for k, v in choice.items()
                        if v != getattr(Reading("base"), k))
        readings.append(Reading(name or "base (C)", **choice))
    return readings


def best_per_row(rows, detail="full"):
    """For each Table 2 row, the run with the smallest :func:`row_score`, and that score."""
    best = {}
    for row in (r for r in rows if r["detail"] == detail):
        key = (round(row_score(row), 6), row["reading"].count("="))  # ties: fewer changes
        if row["row"] not in best or key < best[row["row"]][1]:
            best[row["row"]] = (row, key)
    return [(row, key[0]) for row, key in (best[k] for k in sorted(best))]


def best_overall(rows, detail="full"):
    """The run whose worst row score over all four rows is smallest: ``(name, score)``."""
    worst = {}
    for row in (r for r in rows if r["detail"] == detail):
        worst[row["reading"]] = max(worst.get(row["reading"], 0.0), row_score(row))
    name = min(worst, key=worst.get)
    return name, worst[name]


def format_study(rows):
    """The study as a fixed-width text table (one line per run and row)."""
    lines = [f"{'reading':46s} {'run':7s} row  {'L':>6s} {'paper':>5s}  {'V':>6s} {'paper':>6s}"
             f" {'dV':>7s}  {'t ms':>5s} {'paper':>5s}"]
    for row in rows:
        p, o = row["paper"], row["ours"]
        if o is None:
            body = f"{'-':>6s} {p['depth_m']:5.2f}  {'-':>6s}"
        else:
            dv = relative_error(o, p, "velocity_m_s")
            body = (f"{o['depth_m']:6.3f} {p['depth_m']:5.2f}  {o['velocity_m_s']:6.1f} "
                    f"{p['velocity_m_s']:6.1f} {'' if dv is None else f'{dv:+.1%}':>7s}  "
                    f"{o['time_s'] * 1e3:5.2f} {p['time_s'] * 1e3:5.2f}")
        lines.append(f"{row['reading'][:46]:46s} {row['detail']:7s} {row['row']:3d}  {body}")
    return "\n".join(lines)


def main():
    """Print the study for the paper's Table 1 (``python -m
    cavex.verification.studies.table2_study``)."""
    from cavex.config import load_config

    target, projectile = load_config()
    print("L1 = H1 + l - r/eps1 by reading of eps (Table 2: 0.40 m):")
    for epsilon in pm.EPSILON_READINGS:
        eps1 = pm.layer_epsilon(target.layers[0], epsilon)
        print(f"  {epsilon:22s} eps1 = {eps1:.5f}  L1 = "
              f"{phase_depth_l1(target, projectile, epsilon):.4f} m")
    print(format_study(table2_study(target, projectile)))
    print(f"(paper's ref. 10 exit velocity from the concrete: {PAPER_REF10_EXIT_VELOCITY} m/s)")
    for title, axes in (("admissible (allowed by the text)", ADMISSIBLE),
                        ("all, including the diagnostics the text contradicts", CHOICES)):
        _print_factorial(target, projectile, title, axes)


def _print_factorial(target, projectile, title, axes):
    readings = factorial_readings(axes)
    rows = table2_study(target, projectile, readings, derived=())
    print(f"\nFactorial, {title}: {len(readings)} readings. Best per row by the worst "
          "relative error of L, V, t beyond Table 2's printed precision:")
    for detail in ("full", "segment"):
        for row, score in best_per_row(rows, detail):
            print(f"  {detail:7s} row {row['row']}: {score:6.2%}  [{row['reading']}]")
            print("    " + format_study([row]).splitlines()[1][47:])
        name, score = best_overall(rows, detail)
        print(f"  {detail:7s} best over all four rows: worst {score:.2%}  [{name}]")
        print(format_study([r for r in rows if r["reading"] == name and r["detail"] == detail]))


if __name__ == "__main__":
    main()
