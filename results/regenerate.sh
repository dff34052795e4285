#!/usr/bin/env bash
# Regenerate every committed result with the commands a user runs (from the repository root, with
# cavex installed): penetration (derived and the paper's model), the calibrations and the
# validation against the Forrestal et al. (1994) shots, the verification report, the oblique
# study and the concrete study. Afterwards `git status results` shows what changed (on another
# CPU: nothing; see cavex.verification.output.number_format for the digits written).
# To see on this machine what a CPU with other vector maths would write (numpy 2.x on x86-64:
# its AVX2 and AVX-512 loops of exp, log, pow... round differently; numba compiled for a generic
# CPU; nothing reused from the caches):
#   NPY_DISABLE_CPU_FEATURES="X86_V3 X86_V4 AVX512_ICL" NUMBA_CPU_NAME=generic \
#   NUMBA_CACHE_DIR=$(mktemp -d) CAVEX_CACHE_DIR=$(mktemp -d) bash results/regenerate.sh
# (2026-11-26, numpy 2.4.6 on an AVX-512 machine, 27 min: every file byte-identical but one
# 6th digit of results/concrete/grid_depths.csv, since written with 4; docs/concrete.md)
# The emulation leaves Python's scalar libm (math.exp, math.log ...) as it is, which the 1-D
# penetration runs on: it rewrote results/penetration* byte for byte (2026-11-27), yet another
# CPU changed their velocities near the stop. tests/test_committed_results.py reruns them under
# a model of another libm (1-ulp changes of the force); the trajectory CSVs are written
# to the quanta number_format.TRAJECTORY_QUANTA sets from that spread. Their rows are equally
# spaced in time within each phase (integrator.ROWS_PER_PHASE), not the integrator's steps, whose
# number changed under that model.
set -euo pipefail
cd "$(dirname "$0")/.."
cavex penetrate --out results/penetration > results/penetration/summary.txt
cavex penetrate --resistance paper --epsilon cylindrical-sigma_c --out results/penetration_paper \
  > results/penetration_paper/summary.txt
ids="F94-52 F94-49 F94-51 F94-40 F94-48 F94-39 F94-42 F94-53 F94-47"
for spec in "derived-dynamic:--resistance derived --boundary dynamic" \
            "derived-quasi-static:--resistance derived --boundary quasi-static" \
            "table:--resistance table" "paper:--resistance paper"; do
  label=${spec%%:*}
  # shellcheck disable=SC2086  # the options are words
  cavex calibrate --shots examples/shots_forrestal1994.csv \
    --out "results/validation/calibration_$label.toml" ${spec#*:} \
    --params lam strength_factor --ids $ids --no-progress > /dev/null
done
cavex validate --shots examples/shots_forrestal1994.csv --calibration \
  results/validation/calibration_derived-quasi-static.toml results/validation/calibration_paper.toml \
  results/validation/calibration_table.toml results/validation/calibration_derived-dynamic.toml \
  --out results/validation --no-progress > /dev/null
cavex validate --shots examples/shots_compilation_dev.csv --cross-validate \
  --out results/validation/compilation_dev --no-progress > /dev/null
cavex verify --no-progress > /dev/null
python -m cavex.verification.studies.oblique_study --no-progress > /dev/null
# the same study with debonded interfaces: on another CPU the rows its report.md lists under
# "Reproducibility" (one_ulp_stable = no in study.csv) may read differently
python -m cavex.verification.studies.oblique_study --interfaces debonded --no-progress \
  --out results/oblique/debonded > /dev/null
shot=$(mktemp -d)  # the command's own figures of the paper's 20 deg, 600 m/s shot (PNGs only)
cavex trajectory --obliquity 20 --velocity 600 --compare-homogeneous --out "$shot" > /dev/null
cp "$shot"/*.png results/oblique/shot_20deg_600/ && rm -r "$shot"
python -m cavex.verification.studies.concrete_validation --workers 2 > /dev/null
python -m cavex.verification.studies.concrete_fe > /dev/null
python -m cavex.verification.studies.rigid_form > /dev/null
python -m cavex.verification.studies.erosion_study > /dev/null
python -m cavex.verification.studies.concrete_table_convergence --workers 2 > /dev/null
python -m cavex.verification.studies.concrete_band > /dev/null
python -m cavex.verification.studies.confinement_selection --workers 2 > /dev/null
# Table 2 under the Mohr-Coulomb layers and the realistic concrete (FE tables through the
# FE-table cache: 7.3 min on two shared cores when built, ~25 s when cached; docs/table2.md)
python -m cavex.verification.studies.table2_realistic --workers 2 > /dev/null
git status --short results
