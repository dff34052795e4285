"""The figures of ``cavex validate``: predicted against measured depth (log-log, 1:1, +-20 %)
and the ratio predicted/measured against the striking velocity, as small multiples (the
uncalibrated models with the empirical formula, then each calibrated model with its fitted
shots filled and its held-out shots open); predicted against measured by regime and
``ln(predicted/measured)`` against ``V0`` and ``f_c`` (shots flagged non-rigid open).

Each panel is drawn by a function of an ``Axes`` and the validation's result
(:func:`draw_models`, :func:`draw_regime`, :func:`draw_residuals`), so that the Python API
draws the same panels; :func:`write_figures` lays them out and writes the PNGs.
"""

import math
import textwrap

import numpy as np

from cavex.analytic.models import labels, names, parse_label
from cavex.verification.output.files import save_figure
from cavex.verification.validation.predict import FE_PARTNER
from cavex.verification.validation.regimes import NON_RIGID, REGIME_TITLES, REGIMES

BAND = 0.2  # +-20 % band on the predicted-against-measured figure
FIGURES = ("predicted_vs_measured.png", "ratio_vs_velocity.png")
REGIME_FIGURES = ("by_regime.png", "residuals.png")
# a model's marker and colour by its place in the registry (cycled beyond eight models)
MARKERS = ["o", "s", "^", "D", "v", "X", "h", "*"]
COLOURS = ["tab:blue", "tab:orange", "tab:green", "tab:red", "tab:purple", "tab:brown",
           "tab:pink", "black"]


def model_style(column):
    """``(base label, marker, colour)`` of a column: the registry's label it starts with (a
    calibrated column, ``"<label> calibrated"``, is drawn like its model)."""
    offered = labels(predicts_shots=True)
    index, base = next((i, b) for i, b in enumerate(offered) if column.startswith(b))
    return base, MARKERS[index % len(MARKERS)], COLOURS[index % len(COLOURS)]


def write_figures(result, out):
    """Predicted against measured (log-log, 1:1, +-20 %) and ratio against striking velocity,
    each as small multiples (:func:`panels`): the cavex models as they are beside the
    empirical formula, then one panel per calibrated model with its fitted shots filled and
    its held-out shots open. One legend below the panels, off the data. Then
    :func:`write_regime_figures`; returns the paths written."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    shown = panels(result)
    columns = min(3, len(shown))
    rows = -(-len(shown) // columns)
    written = []
    for name, title in zip(FIGURES, ("Predicted against measured penetration depth",
                                     "Ratio predicted / measured against striking velocity"),
                           strict=True):
        fig, axes = plt.subplots(rows, columns, figsize=(max(4.6 * columns, 8.0), 4.2 * rows + 1.2),
                                 squeeze=False, sharex=True, sharey=True)
        for ax, (heading, models) in zip(axes.flat, shown, strict=False):
            draw_models(ax, result, models, predicted=name.startswith("predicted"))
            ax.set_title(heading, fontsize=9)
        for ax in list(axes.flat)[len(shown):]:
            ax.set_visible(False)
        handles, labels = axes.flat[0].get_legend_handles_labels()
        if len(shown) > 1:
            handles += _fitted_keys()
            labels += ["calibrated: fitted shot", "calibrated: held-out shot"]
        fig.suptitle(title, fontsize=11)
        fig.legend(handles, labels, loc="lower center", ncol=4, fontsize=8, frameon=False)
        fig.tight_layout(rect=(0, 0.1 if rows == 1 else 0.06, 1, 0.97))
        written.append(save_figure(fig, out / name, dpi=110))
    return (written + write_regime_figures(result, out, plt)
            + write_cross_validation_figure(result, out, plt))


def panels(result):
    """``[(title, models)]``: the cavex models as they are with the empirical formula, then
    one panel per calibrated model."""
    offered = labels(predicts_shots=True)
    plain = [m for m in result["models"] if m in offered]
    return [("cavex models (uncalibrated), empirical formula", plain),
            *((m, [m]) for m in result["models"] if m not in offered)]


def draw_models(ax, result, models, predicted=True):
    """One panel: each of ``models``' predicted depth (mm) against the measured one with the
    1:1 line and the +-20 % band (``predicted``), else its ratio predicted/measured against
    the striking velocity with the band around 1."""
    measured = _column(result, "measured_m")
    velocity = None if predicted else _column(result, "V0_m_s")
    for model in models:
        _draw_model(ax, result, model, measured, velocity)
    _frame(ax, measured, predicted)


def regime_models(result):
    """The models of the regime figures: the concrete model, the empirical formulas and, drawn
    last (on top of the one it equals in a regime), the recommended one (those that ran, each
    once)."""
    chosen = (*names(regime_figure=True), result["recommended_model"])
    return [m for k, m in enumerate(chosen) if m in result["models"] and m not in chosen[k + 1:]]


def regime_members(result):
    """``{regime: boolean mask over the shots}`` of every regime other than ``all`` that has
    a shot (:data:`cavex.verification.validation.regimes.REGIMES`)."""
    rows = result["shots"]
    member = {n: np.array([REGIMES[n](r["fc_Pa"], r["V0_m_s"], r.get("flag")) for r in rows])
              for n in REGIMES if n != "all"}
    return {n: chosen for n, chosen in member.items() if chosen.any()}


def write_regime_figures(result, out, plt):
    """``by_regime.png``: predicted against measured for the :func:`regime_models`, one panel
    per regime (:func:`draw_regime`); ``residuals.png``: ``ln(predicted/measured)`` against
    ``V0`` and ``f_c`` (:func:`draw_residuals`). One legend below the panels; returns the paths
    written (none without a model or a shot)."""
    models = regime_models(result)
    if not models or not result["shots"]:
        return []
    flagged = _flagged(result).any()
    members = regime_members(result)
    written = []
    fig, axes = plt.subplots(1, len(members), figsize=(4.4 * len(members), 5.0), squeeze=False)
    for ax, (name, chosen) in zip(axes.flat, members.items(), strict=True):
        draw_regime(ax, result, models, name, chosen)
    _legend_below(fig, axes.flat[0], flagged)
    fig.suptitle("Predicted against measured depth, by regime", fontsize=11)
    fig.tight_layout(rect=(0, 0.12, 1, 0.95))
    written.append(save_figure(fig, out / REGIME_FIGURES[0], dpi=110))

    fig, axes = plt.subplots(1, 2, figsize=(10.0, 4.8), sharey=True)
    for ax, against in zip(axes, ("velocity", "strength"), strict=True):
        draw_residuals(ax, result, models, against)
    axes[0].set_ylabel("ln(predicted / measured)")
    _legend_below(fig, axes[0], flagged)
    fig.suptitle("Residuals against striking velocity and concrete strength", fontsize=11)
    fig.tight_layout(rect=(0, 0.12, 1, 0.95))
    written.append(save_figure(fig, out / REGIME_FIGURES[1], dpi=110))
    return written


def draw_regime(ax, result, models, name, chosen):
    """One regime's panel: ``models``' predicted against measured depth (mm) over the shots
    ``chosen`` (a mask, :func:`regime_members`), shots flagged non-rigid open; titled with the
    regime and its number of shots."""
    measured, flagged = _column(result, "measured_m"), _flagged(result)
    for model in models:
        _scatter(ax, measured[chosen] * 1e3, _depths(result, model)[chosen] * 1e3,
                 flagged[chosen], model)
    _frame(ax, measured[chosen], True)
    ax.set_title(f"{REGIME_TITLES[name]} ({int(chosen.sum())} shots)", fontsize=9)


#: what the residuals are drawn against: the shot's column, its unit (divisor), the axis label
#: and scale
RESIDUAL_AXES = {"velocity": ("V0_m_s", 1.0, "striking velocity V0 (m/s)", "linear"),
                 "strength": ("fc_Pa", 1e6, "f_c (MPa)", "log")}


def draw_residuals(ax, result, models, against):
    """``models``' ``ln(predicted/measured)`` against the striking velocity (``against``
    "velocity") or ``f_c`` ("strength", log axis), shots flagged non-rigid open, with 0 and
    the +-20 % band."""
    key, unit, label, scale = RESIDUAL_AXES[against]
    x = _column(result, key) / unit
    measured, flagged = _column(result, "measured_m"), _flagged(result)
    for model in models:
        _scatter(ax, x, np.log(_depths(result, model) / measured), flagged, model)
    ax.axhline(0.0, color="k", linewidth=1)
    ax.axhspan(math.log(1 - BAND), math.log(1 + BAND), color="grey", alpha=0.2, label="+-20 %")
    ax.set(xlabel=label, xscale=scale)
    ax.autoscale_view()
    if scale == "log":
        plain_log_ticks(ax.xaxis)
    ax.grid(alpha=0.3, which="both")


def _column(result, key):
    """One number of every shot (``measured_m``, ``V0_m_s``, ``fc_Pa``) as an array."""
    return np.array([row[key] for row in result["shots"]])


def _flagged(result):
    """Which shots are flagged non-rigid."""
    return np.array([row.get("flag") == NON_RIGID for row in result["shots"]])


def _depths(result, model):
    """``model``'s predicted depth (m) of every shot, NaN where it failed."""
    return np.array([np.nan if row["predicted_m"][model] is None
                     else row["predicted_m"][model] for row in result["shots"]])


def plain_log_ticks(axis):
    """Ticks of a log axis written as plain numbers: decades (1, 10, 100), and 2 and 5 times
    them where the axis spans less than two decades; minor ticks unlabelled (their default
    labels overprint)."""
    from matplotlib.ticker import FuncFormatter, LogLocator, NullFormatter

    lo, hi = sorted(axis.get_view_interval())
    if lo > 0.0 and hi / lo < 100.0:
        axis.set_major_locator(LogLocator(base=10.0, subs=(1.0, 2.0, 5.0)))
    axis.set_major_formatter(FuncFormatter(lambda value, _: f"{value:g}"))
    axis.set_minor_formatter(NullFormatter())


def _size_and_order(model, scale=1.0):
    """``{"markersize", "zorder"}`` of a model's points: the registry's ``marker_size`` times
    ``scale``, a larger marker drawn behind a smaller one, so that the points of two models
    that predict alike (Li and Chen's and Forrestal's formulas) both show."""
    size = scale * parse_label(model)[0].marker_size
    return {"markersize": size, "zorder": 2.0 + 10.0 / size}


def _scatter(ax, x, y, flagged, model):
    """One model's points, the shots flagged non-rigid open."""
    _, marker, colour = model_style(model)
    style = {"marker": marker, "color": colour, "linestyle": "none", "alpha": 0.8,
             **_size_and_order(model, scale=5.0 / 7.0)}
    ax.plot(x[~flagged], y[~flagged], label=model, **style)
    ax.plot(x[flagged], y[flagged], markerfacecolor="white", **style)


def _legend_below(fig, ax, flagged):
    handles, labels = ax.get_legend_handles_labels()
    if flagged:
        from matplotlib.lines import Line2D

        handles.append(Line2D([], [], marker="o", color="0.3", markerfacecolor="white",
                              linestyle="none"))
        labels.append("open: flagged non-rigid")
    fig.legend(handles, labels, loc="lower center", ncol=min(6, len(labels)), fontsize=8,
               frameon=False)


def _fitted_keys():
    """Legend keys for a calibrated model's fitted (filled) and held-out (open) shots."""
    from matplotlib.lines import Line2D

    style = {"marker": "o", "color": "0.3", "linestyle": "none", "markersize": 7}
    return [Line2D([], [], **style),
            Line2D([], [], markerfacecolor="white", markeredgewidth=1.5, **style)]


def fitted_ids(result, model):
    """The ids of the shots ``model`` (a calibrated column) was fitted to (the compressibility
    column uses the derived-dynamic calibration's mapping, hence its shots)."""
    for calibration in result["calibrations"]:
        if calibration["column"] == model or (
                model == result.get("compressibility_column")
                and calibration["model"] == FE_PARTNER):
            return set(calibration["shots"])
    return set()


def _draw_model(ax, result, model, measured, velocity):
    """One model's points: predicted depth (mm) against measured (``velocity`` None), else the
    ratio predicted/measured against ``velocity``; a calibrated model's fitted shots filled
    and its held-out shots open; the compressibility column (FE with the derived-dynamic
    calibration's mapping) marked "P"."""
    base, marker, colour = model_style(model)
    y = _depths(result, model)
    x = measured * 1e3 if velocity is None else velocity
    y = y * 1e3 if velocity is None else y / measured
    marker = "P" if model == result.get("compressibility_column") else marker
    style = {"marker": marker, "color": colour, "linestyle": "none", **_size_and_order(base)}
    if model in labels(predicts_shots=True):
        ax.plot(x, y, label=model, markerfacecolor=colour, **style)
        return
    fitted = np.array([row["id"] in fitted_ids(result, model) for row in result["shots"]])
    ax.plot(x[fitted], y[fitted], **style)
    ax.plot(x[~fitted], y[~fitted], markerfacecolor="white", markeredgewidth=1.5, **style)


def _frame(ax, measured, predicted):
    """The 1:1 line and +-20 % band, scales and labels of one panel."""
    if predicted:
        lo, hi = 0.5 * measured.min() * 1e3, 2.0 * measured.max() * 1e3
        line = np.array([lo, hi])
        ax.plot(line, line, "k-", linewidth=1, label="1:1")
        ax.fill_between(line, line * (1 - BAND), line * (1 + BAND), color="grey", alpha=0.2,
                        label="+-20 %")
        ax.set(xscale="log", yscale="log", xlim=(lo, hi), ylim=(lo / 2, hi * 1.5),
               xlabel="measured depth (mm)", ylabel="predicted depth (mm)")
        plain_log_ticks(ax.xaxis)
        plain_log_ticks(ax.yaxis)
    else:
        ax.axhline(1.0, color="k", linewidth=1)
        ax.axhspan(1 - BAND, 1 + BAND, color="grey", alpha=0.2, label="+-20 %")
        ax.set(xlabel="striking velocity (m/s)", ylabel="predicted / measured depth")
    ax.grid(alpha=0.3, which="both")


CROSS_VALIDATION_FIGURE = "cross_validation.png"


def write_cross_validation_figure(result, out, plt):
    """``cross_validation.png`` (with ``--cross-validate``): mean ``|ln ratio|`` (top) and bias
    (bottom) of every model, by regime over the reference folds (left, :func:`draw_cv_regimes`;
    the plain score a black tick) and per fold left out (right, :func:`draw_cv_folds`).
    Returns the paths written (none without a cross-validation)."""
    cv = result.get("cross_validation")
    if not cv:
        return []
    left = "regimes" in cv
    fig, axes = plt.subplots(2, 2 if left else 1, figsize=(15.0 if left else 10.0, 8.5),
                             squeeze=False,
                             gridspec_kw={"width_ratios": [1, 1.6]} if left else None)
    for row, key in enumerate(("mean_abs_log_ratio", "mean_log_ratio")):
        if left:
            draw_cv_regimes(axes[row, 0], result, key)
        draw_cv_folds(axes[row, -1], result, key)
    for ax in axes[0]:
        ax.tick_params(labelbottom=False)
    handles, labels = axes[0, 0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="lower center", ncol=min(5, len(labels)), fontsize=8,
               frameon=False)
    fig.suptitle("Cross-validated: each fold predicted by the choices made without it",
                 fontsize=11)
    fig.tight_layout(rect=(0, 0.07, 1, 0.96))
    return [save_figure(fig, out / CROSS_VALIDATION_FIGURE, dpi=110)]


_CV_LABELS = {"mean_abs_log_ratio": "mean |ln(predicted/measured)|",
              "mean_log_ratio": "bias, mean ln(predicted/measured)"}


def draw_cv_regimes(ax, result, key):
    """Grouped bars: each model's cross-validated ``key`` (``mean_abs_log_ratio`` or
    ``mean_log_ratio``) by regime over the reference folds, the plain one a black tick."""
    cv, columns = result["cross_validation"], result["models"]
    regimes = list(cv["regimes"])
    width = 0.8 / len(columns)
    for k, column in enumerate(columns):
        _, _, colour = model_style(column)
        x = np.arange(len(regimes)) + (k - (len(columns) - 1) / 2) * width
        values = [cv["regimes"][r][column][key] for r in regimes]
        plain = [result["regimes"].get(r, {}).get(column, {}).get(key) for r in regimes]
        ax.bar(x, [np.nan if v is None else v for v in values], width, color=colour,
               label=column)
        ax.plot(x, [np.nan if v is None else v for v in plain], "k_", markersize=6)
    ax.axhline(0.0, color="k", linewidth=0.8)
    ax.set_xticks(np.arange(len(regimes)))
    ax.set_xticklabels([textwrap.fill(REGIME_TITLES[r], 14) for r in regimes], fontsize=8)
    ax.set_ylabel(_CV_LABELS[key])
    ax.set_title("each reference left out, by regime (tick: plain)", fontsize=9)
    ax.grid(alpha=0.3, axis="y")


def draw_cv_folds(ax, result, key):
    """Each model's ``key`` over each fold's shots left out (the kinds first, then the
    references), a point per model and fold."""
    cv, columns = result["cross_validation"], result["models"]
    folds = sorted(cv["folds"], key=lambda f: f["family"] == "reference")  # stable
    x = np.arange(len(folds))
    for k, column in enumerate(columns):
        _, marker, colour = model_style(column)
        values = [f["models"][column][key] for f in folds]
        ax.plot(x + (k - (len(columns) - 1) / 2) * 0.08,
                [np.nan if v is None else v for v in values], marker=marker, color=colour,
                linestyle="none", markersize=5, label=column)
    ax.axhline(0.0, color="k", linewidth=0.8)
    ax.set_xticks(x)
    ax.set_xticklabels([f"{f['name'].removeprefix('reference ')} ({f['n']})"
                        for f in folds], rotation=70, ha="right", fontsize=7)
    ax.set_ylabel(_CV_LABELS[key])
    ax.set_title("each fold left out (n shots)", fontsize=9)
    ax.grid(alpha=0.3)
