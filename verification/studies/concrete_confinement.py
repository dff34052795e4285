r"""The shear limit and the hydrostat of :mod:`cavex.concrete_confinement` beside the data they
come from (issue 31, item 2).

``python -m cavex.verification.studies.concrete_confinement [--out DIR]`` writes
``DIR/confinement.png`` and ``DIR/confinement.md``; default folder ``results/concrete``.

- left: the meridian ``q(p)`` to 2 GPa for ``f_c`` in :data:`STRENGTHS`: the published
  flattening meridians (RHT and HJC, normalised by ``f_c``; RHT without the normalisation, the
  same for every ``f_c``), the cavity model's line capped at ``7 f_c`` (cavex today), Attard
  and Setunge's law over the confinements it was fitted on, and the one high-confinement datum
  in the stored literature (Bažant et al. 1996: a lower bound);
- middle: the porosity law against the six porosities it is fitted to and HJC's ``mu_lock``;
- right: the hydrostat ``p(mu)`` for the same strengths.

The markdown gives the triaxial strength of each option at the datum and the hydrostat's
constants at each strength.
"""

import argparse
import sys
from pathlib import Path

import numpy as np

from cavex.concrete import mohr_coulomb_lambda
from cavex.concrete_confinement import (
    MERIDIANS,
    POROSITY_FC_RANGE,
    attard_setunge_strength,
    hydrostat,
    load_data,
    porosity,
    shear_limit,
    triaxial_strength,
)
from cavex.verification.output.files import agg_figure, save_figure, write_text_atomic
from cavex.verification.studies.inputs import output_folder

ROOT = Path(__file__).resolve().parents[2]
DEFAULT_OUT = ROOT / "results" / "concrete"
STRENGTHS = (30e6, 48e6, 100e6, 200e6)
RHO = 2400.0
CAP = 7.0
ATTARD_SETUNGE_MAX_CONFINEMENT = 20e6  # the confinements of its data (Leppanen 2004, 4.3)
MPA = 1e6
OPTIONS = (("rht", "fc"), ("hjc", "fc"), ("rht", "none"))


def cavex_today(p, fc):
    """The cavity model's strength today: ``q = tau_0 + lam p``, ``tau_0 = (1 - lam/3) f_c``,
    capped at ``7 f_c`` (:mod:`cavex.concrete`)."""
    lam = mohr_coulomb_lambda()
    return np.minimum((1.0 - lam / 3.0) * fc + lam * p, CAP * fc)


def attard_setunge_meridian(fc):
    """``(p, q)`` of Attard and Setunge's law for confinements 0 to 20 MPa."""
    s3 = np.linspace(0.0, ATTARD_SETUNGE_MAX_CONFINEMENT, 41)
    s1 = np.array([attard_setunge_strength(s, fc) for s in s3])
    return (s1 + 2.0 * s3) / 3.0, s1 - s3


def datum_rows():
    """The triaxial lower bound(s) of the data file with each option's strength there."""
    rows = []
    for d in load_data():
        if d["kind"] != "triaxial_lower_bound":
            continue
        fc, s3, s1 = d["fc_MPa"] * MPA, d["sigma3_MPa"] * MPA, d["sigma1_MPa"] * MPA
        for meridian, scaling in OPTIONS:
            rows.append((d["id"], meridian, scaling, s1,
                         triaxial_strength(s3, fc, meridian, scaling)))
        rows.append((d["id"], "cavex today", "fc", s1, s3 + cavex_today_at(s3, fc)))
    return rows


def cavex_today_at(sigma3, fc):
    """``q`` of :func:`cavex_today` in a triaxial test at ``sigma3`` (the line's root, then
    the cap)."""
    lam = mohr_coulomb_lambda()
    q_line = ((1.0 - lam / 3.0) * fc + lam * sigma3) / (1.0 - lam / 3.0)
    return min(q_line, CAP * fc)


def figure(path):
    fig = agg_figure(figsize=(15, 4.8), layout="constrained")
    ax_q, ax_phi, ax_h = fig.subplots(1, 3)
    p = np.linspace(0.0, 2e9, 400)
    colors = dict(zip(STRENGTHS, ("tab:blue", "tab:orange", "tab:green", "tab:red"),
                      strict=True))
    for fc in STRENGTHS:
        c = colors[fc]
        ax_q.plot(p / 1e9, shear_limit(p, fc, "rht") / MPA, color=c, lw=2,
                  label=f"$f_c$ = {fc / MPA:g} MPa: RHT")
        ax_q.plot(p / 1e9, shear_limit(p, fc, "hjc") / MPA, color=c, ls="--")
        ax_q.plot(p / 1e9, cavex_today(p, fc) / MPA, color=c, ls=":")
        pa, qa = attard_setunge_meridian(fc)
        ax_q.plot(pa / 1e9, qa / MPA, color=c, lw=4, alpha=0.5)
    ax_q.plot(p / 1e9, shear_limit(p, 1.0, "rht", "none") / MPA, color="k", lw=1,
              label="RHT, not scaled ($f_{ref}$ = 46 MPa)")
    ax_q.plot([], [], color="grey", ls="--", label="HJC (1993): $B p^N$, cap 7 $f_c$")
    ax_q.plot([], [], color="grey", ls=":", label="cavex today: Richart line, cap 7 $f_c$")
    ax_q.plot([], [], color="grey", lw=4, alpha=0.5,
              label="Attard & Setunge (1996), $f_l$ ≤ 20 MPa")
    for d in load_data():
        if d["kind"] == "triaxial_lower_bound":
            s3, s1 = d["sigma3_MPa"], d["sigma1_MPa"]
            pd, qd = (s1 + 2 * s3) / 3.0, s1 - s3
            # the strength lies further along the test's path q = 3 (p - sigma_3)
            ax_q.annotate("", xy=(pd / 1e3 + 0.1, qd + 300), xytext=(pd / 1e3, qd),
                          arrowprops={"arrowstyle": "->", "color": "k"})
            ax_q.plot([pd / 1e3], [qd], "ks", ms=7,
                      label=f"Bažant et al. (1996), {d['fc_MPa']:g} MPa: lower bound "
                            "(arrow: the test's path)")
    ax_q.set(xlabel="mean stress p (GPa)", ylabel="q = σ1 − σ3 (MPa)", xlim=(0, 2),
             ylim=(0, 1800), title="Shear limit on the compressive meridian")
    ax_q.legend(fontsize=7, loc="upper left")

    fcs = np.linspace(9e6, 240e6, 300)
    ax_phi.plot(fcs / MPA, [porosity(f) for f in fcs], "k-",
                label="porosity law (held outside the data)")
    lo, hi = POROSITY_FC_RANGE
    ax_phi.axvspan(lo / MPA, hi / MPA, color="0.9", label="f_c range of the data")
    for d in load_data():
        if d["kind"] == "porosity":
            marker = "o" if d["id"].startswith("ansari") else "^"
            ax_phi.plot(d["fc_MPa"], d["porosity"], marker, color="tab:blue", ms=7)
        if d["kind"] == "lock_check":
            mu = d["mu_lock"]
            ax_phi.plot(d["fc_MPa"], mu / (1.0 + mu), "r*", ms=12,
                        label="HJC 1993 (48 MPa): μ_lock = 0.1, not fitted")
    ax_phi.plot([], [], "o", color="tab:blue", label="Ansari & Li (1998) via Imran & P. (2001)")
    ax_phi.plot([], [], "^", color="tab:blue", label="Xie et al. (1995) via Imran & P. (2001)")
    ax_phi.set(xlabel="$f_c$ (MPa)", ylabel="porosity φ", title="Porosity: μ_lock = φ/(1 − φ)")
    ax_phi.legend(fontsize=7)

    for fc in STRENGTHS:
        h = hydrostat(fc, RHO)
        mu = [0.0, h.mu_crush, h.mu_lock, h.mu_lock + 0.02]
        pr = [0.0, h.p_crush, h.p_lock, h.p_lock + h.locked_modulus * 0.02]
        ax_h.plot(mu, np.array(pr) / 1e9, color=colors[fc], label=f"$f_c$ = {fc / MPA:g} MPa")
    ax_h.set(xlabel="μ = ρ/ρ0 − 1", ylabel="p (GPa)", ylim=(0, 2.6),
             title="Hydrostat (HJC form, ρ = 2400 kg/m³)")
    ax_h.legend(fontsize=7)
    save_figure(fig, path, dpi=120)
    return path


def report_md():
    lines = ["# Shear limit and hydrostat at high confinement (issue 31, item 2)", "",
             "Written by `python -m cavex.verification.studies.concrete_confinement`; "
             "equations and sources in `cavex.concrete_confinement` and docs/concrete.md.", "",
             "## The triaxial datum", "",
             "| datum | meridian | scaling | measured σ1 (MPa, lower bound) | σ1 (MPa) |",
             "|---|---|---|---|---|"]
    for ident, meridian, scaling, s1, pred in datum_rows():
        lines.append(f"| {ident} | {meridian} | {scaling} | ≥ {s1 / MPA:.0f} | {pred / MPA:.0f} |")
    lines += ["", "## Hydrostat constants (ρ = 2400 kg/m³)", "",
              "| f_c (MPa) | K (GPa) | p_crush (MPa) | μ_crush | φ | μ_lock | p_lock (GPa) "
              "| compaction modulus (GPa) | K_lock (GPa) |",
              "|---|---|---|---|---|---|---|---|---|"]
    for fc in (9e6, 20e6, 48e6, 100e6, 160e6, 237e6):
        h = hydrostat(fc, RHO)
        lines.append(f"| {fc / MPA:g} | {h.bulk / 1e9:.1f} | {h.p_crush / MPA:.1f} | "
                     f"{h.mu_crush:.5f} | {porosity(fc):.4f} | {h.mu_lock:.4f} | "
                     f"{h.p_lock / 1e9:.2f} | {h.compaction_modulus / 1e9:.1f} | "
                     f"{h.locked_modulus / 1e9:.0f} |")
    lines += ["", "Meridian constants: " + "; ".join(
        f"{m.name}: B = {m.B}, N = {m.N}, S_max = {m.S_max}, f_ref = {m.f_ref / MPA:g} MPa"
        for m in MERIDIANS.values()), ""]
    return "\n".join(lines)


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="python -m cavex.verification.studies.concrete_confinement",
        description=__doc__.splitlines()[0])
    parser.add_argument("--out", default=str(DEFAULT_OUT))
    args = parser.parse_args(argv)
    folder = output_folder(args)
    if folder is None:
        return 2
    folder.mkdir(parents=True, exist_ok=True)
    text = report_md()
    write_text_atomic(folder / "confinement.md", text)
    figure(folder / "confinement.png")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
