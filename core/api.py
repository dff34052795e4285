"""The Python API in the ecosystem's types: FE tables as :class:`xarray.Dataset`, phase tables,
trajectories and validations as :class:`pandas.DataFrame`, figures drawn on a matplotlib
``Axes`` you give.

A thin layer over the commands' own job functions and figure panels: every function here
calls what the command of the same name calls, so that a result from Python and the files of
the command hold the same numbers (tested in ``tests/test_api.py``):

- :func:`penetrate`: :func:`cavex.verification.commands.penetrate.penetration_job`;
- :func:`fly`: :func:`cavex.verification.commands.trajectory.trajectory_job`;
- :func:`validate`: :func:`cavex.verification.commands.validate.job`;
- :func:`build_table`: :func:`cavex.verification.fedata.table.tabulate` (``cavex table``);
  :func:`open_table`: :func:`cavex.analytic.penetration.tabulated.read_table`;
- ``plot_*``: the panels of :mod:`cavex.verification.report` the commands draw their PNGs with.

The module sits on the top floor of the package, beside the command line
(``tests/test_layering.py``): nothing in cavex imports it. SI units, compression positive.

Units of a table. The files carry CF ``units`` in UDUNITS spelling; :func:`open_table` and
:func:`build_table` return them spelled as pint's default registry reads them as well
(``m/s``, ``kg/m^3``: also UDUNITS; :func:`cavex.verification.output.cf_metadata.pint_readable`),
so that ``ds.pint.quantify()`` (pint-xarray) works without cf-xarray's registry.

Examples
--------
>>> from cavex import api
>>> result = api.penetrate()                      # the paper's runway, derived closed form
>>> result.phases[["label", "end_depth_m"]]       # doctest: +SKIP
>>> import matplotlib.pyplot as plt
>>> fig, ax = plt.subplots()
>>> api.plot_velocity(result, ax)                 # doctest: +SKIP
"""

from dataclasses import dataclass

__all__ = ["Penetration", "Shot", "Validation", "build_table", "fly", "open_table",
           "penetrate", "plot_deceleration", "plot_pitch", "plot_residuals", "plot_table",
           "plot_trajectory", "plot_validation", "plot_velocity", "plot_view_3d", "validate"]


def _target(target, projectile, interfaces=None):
    """``(target, projectile)``: the given ones, a missing one the paper's Table 1
    (:func:`cavex.config.load_config`); ``interfaces`` ("bonded" or "debonded") set on every
    interface where given."""
    from cavex.config import load_config

    default_target, default_projectile = load_config()
    target = default_target if target is None else target
    projectile = default_projectile if projectile is None else projectile
    if interfaces is not None:
        target = target.with_interfaces(interfaces)
    return target, projectile


# --- tables -----------------------------------------------------------------------------------

def open_table(path):
    """Read an FE table written by ``cavex table`` (or :func:`build_table` and ``to_netcdf``).

    Parameters
    ----------
    path : str or os.PathLike
        A netCDF-3 table (``cavex table -o FILE``).

    Returns
    -------
    xarray.Dataset
        ``sigma_r``, ``S``, ``error_estimate``, ``plastic_radius``, ``failed`` on
        ``(velocity, depth)``, ``wall_layer`` on ``depth``, the closed forms
        ``sigma_r_dynamic`` and ``sigma_r_quasi_static`` and the first layer alone
        (docs/verification.md, "FE tables"), fully in memory. Units are CF ``units``
        attributes that pint reads as they are: ``ds.pint.quantify()`` works with pint's
        default registry (module docstring).

    Raises
    ------
    cavex.CavexInputError
        The file cannot be read or is not a cavex table.
    """
    from cavex.analytic.penetration.tabulated import load_table
    from cavex.verification.output.cf_metadata import pint_readable

    return pint_readable(load_table(path))


def build_table(velocities, depths, target=None, projectile=None, *, nu=None, numerics=None,
                workers=1, progress=False):
    """Tabulate the FE cavity-wall stress ``sigma_r(V, L)`` of a target, as ``cavex table``
    does, in memory.

    Parameters
    ----------
    velocities : sequence of float
        Cavity expansion velocities ``V`` (m/s), in [0, 1500]; must include 0.
    depths : sequence of float
        Nose-tip depths ``L`` (m); the depths where the wall layer switches are added
        (``cavex table`` states them).
    target, projectile : cavex.Target, cavex.Projectile, optional
        Default: the paper's Table 1 (:func:`cavex.load_config`).
    nu : float, optional
        Poisson's ratio of every layer (default: each layer's own).
    numerics : dict, optional
        Settings of :class:`cavex.fem.Numerics` (e.g. ``{"n_elements": 200}``).
    workers : int, default 1
        Local processes; 1 runs in this process (no pool to start: the fastest for a small
        grid), None one per CPU.
    progress : bool, default False
        A progress bar on stderr.

    Returns
    -------
    xarray.Dataset
        As :func:`open_table` returns it: FE ``sigma_r`` (Pa) and ``S = sigma_r / tau`` of the
        wall layer, their error estimate, and the closed forms beside them.
    """
    from cavex.verification.fedata.table import build_table as tabulated
    from cavex.verification.output.cf_metadata import pint_readable

    target, projectile = _target(target, projectile)
    return pint_readable(tabulated(target, projectile, velocities, depths, nu=nu,
                                   numerics=numerics, workers=workers, progress=progress))


# --- 1-D penetration --------------------------------------------------------------------------

@dataclass(frozen=True, repr=False)
class Penetration:
    """The rigid projectile through the target and through its first layer alone: the job of
    ``cavex penetrate`` (:func:`penetrate`).

    Attributes
    ----------
    job : dict
        :func:`cavex.verification.commands.penetrate.penetration_job`'s result (``runs``:
        the :class:`~cavex.analytic.penetration.integrator.Trajectory` of ``"runway"`` and
        ``"first_layer_only"``; the settings).
    """

    job: dict

    @property
    def phases(self):
        """The target's phase table as ``cavex penetrate`` prints and writes it
        (``phases_target.csv``): one row per phase, ``phase``, ``stage``, ``label``,
        ``end_depth_m``, ``end_velocity_m_s``, ``end_time_s``, ``end_reason``
        (:class:`pandas.DataFrame`)."""
        import pandas as pd

        from cavex.verification.commands.penetrate import phases_as_dicts

        return pd.DataFrame(phases_as_dicts(self.job["runs"]["runway"]))

    @property
    def trajectory(self):
        """The target's trajectory, the rows of ``trajectory_target.csv`` at full precision:
        ``t_s``, ``depth_m``, ``velocity_m_s``, ``deceleration_m_s2``, ``phase``
        (:class:`pandas.DataFrame`)."""
        return _frame(self.job["runs"]["runway"].rows())

    @property
    def first_layer_trajectory(self):
        """The same shot into the first layer alone (``trajectory_first_layer_only.csv``),
        :class:`pandas.DataFrame`."""
        return _frame(self.job["runs"]["first_layer_only"].rows())

    @property
    def final_depth(self):
        """The target's final nose-tip depth (m)."""
        return float(self.job["runs"]["runway"].depth[-1])

    def __repr__(self):
        phases = len(self.job["runs"]["runway"].phases)
        return (f"Penetration({self.job['model']}, {self.job['target_label']}: "
                f"{phases} phases, final depth {self.final_depth:.4g} m)")

    @property
    def summary(self):
        """What ``cavex penetrate --json`` prints (a JSON-able dict)."""
        from cavex.verification.commands.penetrate import summary

        return summary(self.job)


def _frame(columns):
    import pandas as pd

    return pd.DataFrame({name: list(values) if not hasattr(values, "shape") else values
                         for name, values in columns.items()})


def penetrate(target=None, projectile=None, *, resistance="derived", boundary=None,
              epsilon="quasi-static", table=None, law_A=None, law_B=None, crater="nose-base",
              interfaces=None, erosion="none"):
    """Fly the rigid projectile through the target at normal incidence (1-D), as
    ``cavex penetrate``: the nose force ``F = integral of sigma_n over the ogive`` with the
    resistance ``S(V, L)`` of ``resistance``, ``m dV/dt = -F``, and the same shot into the
    first layer alone.

    Parameters
    ----------
    target, projectile : cavex.Target, cavex.Projectile, optional
        Default: the paper's Table 1 (striking velocity ``projectile.V0``).
    resistance : {"derived", "paper", "table", "law"}, default "derived"
        The flown model (docs/models.md).
    boundary : {"dynamic", "quasi-static"}, optional
        The derived closed form's yield-at-boundary convention (default dynamic).
    epsilon : str, default "quasi-static"
        The paper model's strain setting.
    table : str or os.PathLike, optional
        With ``resistance="table"``: an FE table of this target (``cavex table``).
    law_A, law_B : float, optional
        With ``resistance="law"``: ``S = A + B rho V^2 / tau`` (``law_A`` in Pa, ``law_B`` in
        kg/m^3), else each layer's ``law_A``, ``law_B`` keys.
    crater : {"nose-base", "nose-tip"}, default "nose-base"
        Where the crater depth ``4.5 r`` is measured from.
    interfaces : {"bonded", "debonded"}, optional
        Every interface's bonding (default: the target's own).
    erosion : {"none", "silling-forrestal"}, default "none"
        Nose erosion by abrasion (docs/erosion.md).

    Returns
    -------
    Penetration
        ``.phases`` and ``.trajectory`` as :class:`pandas.DataFrame`, ``.final_depth`` (m),
        ``.summary`` (the JSON of ``cavex penetrate --json``).
    """
    from cavex.verification.commands.penetrate import penetration_job

    target, projectile = _target(target, projectile, interfaces)
    return Penetration(penetration_job(target, projectile, resistance=resistance,
                                       boundary=boundary, epsilon=epsilon, crater=crater,
                                       table=table, law_A=law_A, law_B=law_B,
                                       erosion=erosion))


# --- 3-D oblique shot -------------------------------------------------------------------------

@dataclass(frozen=True, repr=False)
class Shot:
    """One oblique shot of the rigid body in 3-D: the job of ``cavex trajectory``
    (:func:`fly`).

    Attributes
    ----------
    job : dict
        :func:`cavex.verification.commands.trajectory.trajectory_job`'s result (``runs``:
        ``"runway"`` and, with ``compare_homogeneous``, ``"first layer only"``, each a
        :class:`~cavex.analytic.penetration.oblique.Result`; ``settings``; ``target``).
    """

    job: dict

    @property
    def history(self):
        """The target's history, the columns of ``history_target.csv`` at full precision
        (time, centre of mass and nose tip, attitude, velocities, overloads),
        :class:`pandas.DataFrame`."""
        return _frame(self.job["runs"]["runway"].history)

    @property
    def phases(self):
        """The target's phases (label, end time, nose-tip depth, pitch, pitch change, ...),
        :class:`pandas.DataFrame`."""
        import pandas as pd

        return pd.DataFrame(self.job["runs"]["runway"].phases)

    @property
    def end(self):
        """The end state: ``state``, ``nose_tip_m`` (x, y, z), ``pitch_deg``, ... (dict)."""
        return self.job["runs"]["runway"].end

    @property
    def summary(self):
        """What ``cavex trajectory --json`` prints (a JSON-able dict)."""
        from cavex.verification.commands.trajectory import summary

        return summary(self.job)

    def __repr__(self):
        settings, end = self.job["settings"], self.end
        return (f"Shot({settings['speed_m_s']:g} m/s at {settings['obliquity_deg']:g} deg, "
                f"{settings['resistance']}: {end['state']}, nose tip at z = "
                f"{end['nose_tip_m'][2]:.4g} m, pitch {end['pitch_deg']:.4g} deg)")


def fly(target=None, projectile=None, *, velocity=None, obliquity=0.0, attack=0.0,
        attack_plane=0.0, spin=0.0, resistance="derived", interfaces=None,
        compare_homogeneous=False, **options):
    """Fly the rigid projectile through the target in 3-D, as ``cavex trajectory``: the
    differential-area force law over the nose and shank, integrated for position, attitude
    and their rates (docs/oblique.md).

    Parameters
    ----------
    target, projectile : cavex.Target, cavex.Projectile, optional
        Default: the paper's Table 1.
    velocity : float, optional
        Striking speed (m/s; default ``projectile.V0``).
    obliquity, attack, attack_plane : float, default 0
        Angle of the velocity from the target normal, angle of attack and its plane (deg).
    spin : float, default 0
        Spin about the axis (rad/s).
    resistance : {"derived", "paper", "table", "law"}, default "derived"
        The flown model.
    interfaces : {"bonded", "debonded"}, optional
        Every interface's bonding (default: the target's own).
    compare_homogeneous : bool, default False
        Also the same shot into the first layer alone.
    **options
        The other keywords of :func:`cavex.verification.commands.trajectory.trajectory_job`
        (``boundary``, ``contact_ramp``, ``contact_hold``, ``entry_crater``, ``table``, ...).

    Returns
    -------
    Shot
        ``.history`` and ``.phases`` as :class:`pandas.DataFrame`, ``.end`` (dict).
    """
    from cavex.analytic.penetration.strike import Strike
    from cavex.verification.commands.trajectory import trajectory_job

    target, projectile = _target(target, projectile, interfaces)
    speed = projectile.V0 if velocity is None else velocity
    strike = Strike(speed, obliquity, attack, attack_plane, spin)
    return Shot(trajectory_job(target, projectile, strike, resistance,
                               compare_homogeneous=compare_homogeneous, **options))


# --- validation -------------------------------------------------------------------------------

@dataclass(frozen=True, repr=False)
class Validation:
    """Predicted against measured penetration depths: the result of ``cavex validate``
    (:func:`validate`).

    Attributes
    ----------
    result : dict
        :func:`cavex.verification.commands.validate.job`'s result (``shots``, ``models``,
        ``summary``, ``regimes``, ``recommended_model``, ...; ``validation.json``).
    """

    result: dict

    @property
    def predictions(self):
        """One row per shot, the columns of ``predictions.csv`` at full precision: ``id``,
        ``V0_m_s``, ``fc_Pa``, ``rho_kg_m3``, ``measured_m``, ``flag`` (a rigid-regime flag,
        else empty), then per model ``<model>_m`` (predicted depth, NaN where the model
        cannot predict the shot) and ``<model>_ratio`` (predicted / measured); model labels
        with every character other than a letter or digit as ``_`` (``forrestal_1994_m``).
        :class:`pandas.DataFrame`."""
        import pandas as pd

        from cavex.verification.commands.validate import slug

        models = self.result["models"]
        rows = [{"id": row["id"], "V0_m_s": row["V0_m_s"], "fc_Pa": row["fc_Pa"],
                 "rho_kg_m3": row["rho_kg_m3"], "measured_m": row["measured_m"],
                 "flag": row.get("flag") or ""}
                | {f"{slug(m)}_m": _number(row["predicted_m"][m]) for m in models}
                | {f"{slug(m)}_ratio": _number(row["ratio"][m]) for m in models}
                for row in self.result["shots"]]
        return pd.DataFrame(rows)

    @property
    def statistics(self):
        """Per model over all shots: ``n``, ``mean_ratio``, ``std_ratio`` and
        ``mean_abs_log_ratio`` of predicted / measured (rounded to 6 significant digits, as
        ``validation.json``), one row per model, :class:`pandas.DataFrame`."""
        import pandas as pd

        return pd.DataFrame({m: {k: _number(v) for k, v in s.items()}
                             for m, s in self.result["summary"].items()}).T

    @property
    def summary(self):
        """What ``cavex validate --json`` prints (``validation.json``; a JSON-able dict)."""
        from cavex.verification.commands.validate import summary

        return summary(self.result)

    def __repr__(self):
        return (f"Validation({len(self.result['shots'])} shots, models "
                f"{', '.join(self.result['models'])})")


def _number(value):
    return float("nan") if value is None else value


def validate(shots, *, models=None, calibrations=(), erosion="none", workers=None):
    """Predict the measured depths of ``shots`` with every model (or those named), as
    ``cavex validate``.

    Parameters
    ----------
    shots : str, os.PathLike or pandas.DataFrame
        A shot file (CSV as ``examples/shots_forrestal1994.csv``; docs/validation.md), or a
        DataFrame with its columns (written as that CSV and read by the same reader, with the
        same checks).
    models : sequence of str, optional
        Labels of the models to run (default: all; ``cavex validate --help`` lists them).
        The FE-table models build their tables once into the cache (``$CAVEX_CACHE_DIR``).
    calibrations : sequence of str or os.PathLike, optional
        Calibration files of ``cavex calibrate``.
    erosion : {"none", "silling-forrestal"}, default "none"
        Nose erosion by abrasion.
    workers : int, optional
        Local processes for FE tables (default one per CPU).

    Returns
    -------
    Validation
        ``.predictions`` and ``.statistics`` as :class:`pandas.DataFrame`, ``.result``.

    Raises
    ------
    cavex.CavexInputError
        A bad shot or calibration file, an unknown model.
    """
    from cavex.verification.commands.validate import check_models, job
    from cavex.verification.validation.calibration import read_calibration
    from cavex.verification.validation.shots import parse_shots, read_shots

    checked = check_models(None if models is None else list(models))
    if hasattr(shots, "to_csv"):
        shot_file = parse_shots(shots.to_csv(index=False), "<DataFrame>")
    else:
        shot_file = read_shots(shots)
    cals = [read_calibration(p) for p in calibrations]
    return Validation(job(shot_file, cals, models=checked, erosion=erosion, workers=workers,
                          progress=False))


# --- figures ----------------------------------------------------------------------------------

def plot_table(ds, ax):
    """Draw ``S(V, L)`` of a table on ``ax``: one line per depth coloured by depth, styled
    by the wall layer, the wall-layer switches (the interfaces as the cavity meets them)
    marked on the colour bar; the figure of ``cavex table``
    (:func:`cavex.verification.report.table_figures.draw_table`).

    Parameters
    ----------
    ds : xarray.Dataset
        A table (:func:`open_table`, :func:`build_table`), quantified or not.
    ax : matplotlib.axes.Axes

    Returns
    -------
    matplotlib.colorbar.Colorbar
    """
    from cavex.verification.report.table_figures import draw_table

    if any(hasattr(v.data, "units") for v in ds.variables.values()):  # pint-quantified
        ds = ds.pint.dequantify()
    return draw_table(ax, ds)


def plot_velocity(result, ax):
    """Velocity against time of a :class:`Penetration`, the target beside its first layer
    alone (``velocity_time.png``; :func:`cavex.verification.report.penetration_figures.
    draw_velocity`).

    Parameters
    ----------
    result : Penetration
        From :func:`penetrate`.
    ax : matplotlib.axes.Axes
        Of a figure with a renderer (pyplot's, or an Agg canvas), as every ``plot_*`` here.
    """
    from cavex.verification.report.penetration_figures import draw_velocity

    draw_velocity(ax, result.job)


def plot_deceleration(result, ax):
    """Deceleration against nose-tip depth of a :class:`Penetration`, the interfaces dotted
    and the layers named (``deceleration_depth.png``;
    :func:`cavex.verification.report.penetration_figures.draw_deceleration`).

    Parameters
    ----------
    result : Penetration
        From :func:`penetrate`.
    ax : matplotlib.axes.Axes
    """
    from cavex.verification.report.penetration_figures import draw_deceleration

    draw_deceleration(ax, result.job)


def plot_trajectory(shot, ax):
    """The side view of a :class:`Shot` to scale: centre-of-mass path and the body's outline
    at 9 equal time intervals, the interfaces and layers (``path_side.png``;
    :func:`cavex.verification.report.trajectory_figures.draw_side_view`).

    Parameters
    ----------
    shot : Shot
        From :func:`fly`.
    ax : matplotlib.axes.Axes
        Set to equal aspect (the view is to scale).
    """
    from cavex.verification.report.trajectory_figures import draw_side_view

    draw_side_view(ax, shot.job)


def plot_pitch(shot, ax):
    """Pitch against time of a :class:`Shot`, phase ends dotted (``pitch_time.png``;
    :func:`cavex.verification.report.trajectory_figures.draw_pitch`).

    Parameters
    ----------
    shot : Shot
        From :func:`fly`.
    ax : matplotlib.axes.Axes
    """
    from cavex.verification.report.trajectory_figures import draw_pitch

    draw_pitch(ax, shot.job)


def plot_view_3d(shot, ax):
    """The 3-D view of a :class:`Shot` in the layered block to scale (``path_3d.png``;
    :func:`cavex.verification.report.trajectory_figures.draw_view_3d`).

    Parameters
    ----------
    shot : Shot
    ax : mpl_toolkits.mplot3d.axes3d.Axes3D
        A 3-D axes: ``fig.add_subplot(projection="3d", computed_zorder=False)``.

    Returns
    -------
    list
        The legend's handles (``fig.legend(handles=...)``).
    """
    from cavex.verification.report.trajectory_figures import draw_view_3d

    return draw_view_3d(ax, shot.job)


def plot_validation(validation, ax, models=None, predicted=True):
    """Predicted against measured depth (mm, log-log, the 1:1 line and +-20 % band), or with
    ``predicted`` False the ratio predicted / measured against the striking velocity, of
    ``models`` (default: every model that ran) of a :class:`Validation`
    (``predicted_vs_measured.png``, ``ratio_vs_velocity.png``;
    :func:`cavex.verification.report.validation_figures.draw_models`).

    Parameters
    ----------
    validation : Validation
        From :func:`validate`.
    ax : matplotlib.axes.Axes
    models : sequence of str, optional
        Model labels among ``validation.result["models"]``.
    predicted : bool, default True
        Predicted against measured; False: the ratio against the striking velocity.
    """
    from cavex.verification.report.validation_figures import draw_models

    draw_models(ax, validation.result, list(models or validation.result["models"]),
                predicted=predicted)


def plot_residuals(validation, ax, models=None, against="velocity"):
    """``ln(predicted / measured)`` against the striking velocity (``against="velocity"``)
    or ``f_c`` (``"strength"``) of ``models`` (default: every model that ran) of a
    :class:`Validation` (``residuals.png``;
    :func:`cavex.verification.report.validation_figures.draw_residuals`).

    Parameters
    ----------
    validation : Validation
        From :func:`validate`.
    ax : matplotlib.axes.Axes
    models : sequence of str, optional
        Model labels among ``validation.result["models"]``.
    against : {"velocity", "strength"}, default "velocity"
    """
    from cavex.verification.report.validation_figures import draw_residuals

    draw_residuals(ax, validation.result, list(models or validation.result["models"]),
                   against)
