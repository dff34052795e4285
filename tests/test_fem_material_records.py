"""The FE's material records: what :func:`cavex.fem.material_records.pack_layers` puts in each
field, that a stack carries its cases' records unchanged, and that no other FE module reads a
layer's constants (the one place where a material becomes kernel data)."""

import ast
import math
from pathlib import Path

import numpy as np
import pytest

from cavex.fem.discretisation import Discretisation
from cavex.fem.material_records import MATERIAL, pack_layers
from cavex.fem.mesh import element_layers, reference_mesh
from cavex.fem.stack import Stack
from cavex.materials import Material

FEM = Path(__file__).resolve().parents[1] / "fem"
SOIL = Material(E=0.12e9, nu=0.3, rho=1600.0, lam=0.5, tau=6e6)
TRESCA = Material(E=70e9, nu=0.33, rho=2700.0, lam=0.0, tau=100e6)
CONCRETE = Material(E=30e9, nu=0.2, rho=2300.0, lam=1.5, sigma_c=40e6, tau_max=80e6,
                    tensile_strength=3e6)


def test_pack_layers_fills_every_field_from_the_layer_and_the_settings():
    layers = [SOIL, TRESCA, CONCRETE]
    records = pack_layers(layers, [2, 0, 1, 0], dilatancy_deg=20.0)
    assert records.dtype == MATERIAL and records.shape == (4,)
    sin_psi = math.sin(math.radians(20.0))
    for record, m in zip(records, [CONCRETE, SOIL, TRESCA, SOIL], strict=True):
        assert record["K"] == m.bulk_modulus and record["G"] == m.shear_modulus
        assert (record["rho"], record["lam"], record["tau"]) == (m.rho, m.lam, m.tau)
        assert record["lam_psi"] == 6.0 * sin_psi / (3.0 - sin_psi)
    # tension cut-off: through the apex tau/lam (none for Tresca) unless the layer has its own
    assert records["tension"][1] == SOIL.tau / SOIL.lam
    assert records["tension"][2] == np.inf
    assert records["tension"][0] == CONCRETE.tensile_strength
    # Tresca cap: the layer's tau_max, else none
    assert records["cap"].tolist() == [80e6, np.inf, np.inf, np.inf]


@pytest.mark.parametrize("cutoff", [2e6, [1e6, 2e6, 3e6]])
def test_the_tension_cutoff_setting_yields_to_a_layers_tensile_strength(cutoff):
    records = pack_layers([SOIL, TRESCA, CONCRETE], [0, 1, 2], tension_cutoff=cutoff)
    expected = [2e6, 2e6] if np.ndim(cutoff) == 0 else [1e6, 2e6]
    assert records["tension"].tolist() == expected + [CONCRETE.tensile_strength]


def test_a_stack_carries_its_cases_records_and_the_mass_their_density():
    discs = []
    for layers, interfaces in (([SOIL, CONCRETE], [0.05]), ([TRESCA], [])):
        mesh, vertices = reference_mesh(0.01, 0.01, interfaces, 0.3, 6.0)
        discs.append(Discretisation(mesh, 2, element_layers(mesh, vertices), layers))
    assert set(discs[0].element_layer) == {0, 1}
    stack = Stack(discs)
    assert np.array_equal(stack.material, np.concatenate([d.material for d in discs]))
    for d in discs:
        assert np.array_equal(d.material, pack_layers(d.layers, d.element_layer))
        rho = [d.layers[i].rho for i in d.element_layer]
        assert np.array_equal(d._rho_mass, np.repeat(np.array(rho)[:, None],
                                                     d._rho_mass.shape[1], axis=1))


def test_no_other_fem_module_reads_a_layers_constants():
    """Only ``pack_layers`` reads a Material's FE constants; the kernels read records."""
    names = {"bulk_modulus", "shear_modulus", "tau_max", "tensile_strength", "rho", "lam",
             "tau", "E", "nu", "sigma_c"}
    readers = {}
    for path in FEM.glob("*.py"):
        if path.name == "material_records.py":
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute) and node.attr in names:
                readers.setdefault(path.name, set()).add(node.attr)
    # the point kernel reads its record's fields (material.lam, material.tau, ...), and the
    # scikit-fem mass form its coefficient w.rho (the records' density, from the Discretisation)
    assert readers == {"constitutive.py": {"lam", "tau"}, "forms.py": {"rho"}}
