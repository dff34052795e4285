r"""Several radial models concatenated into one model of disconnected copies (a *stack*).

Every computation of :mod:`cavex.fem` runs on a stack; a single problem is a stack of one. The
cases are concatenated element by element and dof by dof; the compiled kernel
(:func:`cavex.fem.element.assemble_cases`) then runs once per Newton iteration over all
(case, element, point) triples. The global tangent is block diagonal with the bandwidth of one
case, solved block by block by the compiled LU of :mod:`cavex.fem.banded`; the prescribed dofs
become identity rows and columns. Every block is factorised with the same operations as alone:
a case gives the same bits alone and inside any stack.
"""

import numpy as np
from scipy.sparse import csr_matrix

from cavex.fem.banded import solve_blocks
from cavex.fem.element import assemble_cases
from cavex.fem.records import Assembly, Layout, PointResponse


def ranges(starts, counts):
    """Concatenated ``arange(s, s + c)`` for every pair (vectorised)."""
    counts = np.asarray(counts)
    total = int(counts.sum())
    if total == 0:
        return np.zeros(0, dtype=int)
    first = np.repeat(np.asarray(starts) - np.concatenate([[0], np.cumsum(counts)[:-1]]), counts)
    return first + np.arange(total)


def starts(counts):
    """Offsets of consecutive blocks of the given sizes."""
    return np.concatenate([[0], np.cumsum(counts)[:-1]]).astype(int)


class Stack:
    """Discretisations of several cases concatenated into one model of disconnected copies.

    Case ``c`` owns dofs ``dof_start[c] : dof_start[c] + dof_count[c]`` (its radial order) and
    elements ``el_start[c] : el_start[c] + el_count[c]``.

    Parameters
    ----------
    discs : sequence of Discretisation
        All of one degree.
    outer_fixed : bool
        The outermost dof of every case is held at zero displacement (else traction-free).
    wall_control : {"displacement", "pressure"}
        The wall dof is prescribed (displacement) or free and loaded by a follower pressure.
    """

    def __init__(self, discs, outer_fixed=True, wall_control="displacement"):
        d0 = discs[0]
        self.discs = list(discs)
        self.degree = p = d0.degree
        self.N = d0.N
        self.n_cases = k = len(discs)
        self.dof_count = np.array([d.ndof for d in discs])
        self.el_count = np.array([d.n_elements for d in discs])
        self.dof_start = starts(self.dof_count)
        self.el_start = starts(self.el_count)
        self.ndof = n = int(self.dof_count.sum())
        self.element_dofs = np.concatenate([d.element_dofs + o
                                            for d, o in zip(discs, self.dof_start, strict=True)])
        for name in ("dNdR", "R_points", "weights", "force_weights", "R_dofs", "mass_band"):
            setattr(self, name, np.concatenate([getattr(d, name) for d in discs],
                                               axis=1 if name == "mass_band" else 0))
        self.material = np.concatenate([d.material for d in discs])  # one record per element
        self.element_case = np.repeat(np.arange(k), self.el_count)
        self.dof_case = np.repeat(np.arange(k), self.dof_count)
        nnz = np.array([d.mass.nnz for d in discs])
        indptr = np.concatenate([d.mass.indptr[:-1] + o for d, o in zip(discs, starts(nnz),
                                                                         strict=True)]
                                + [[nnz.sum()]])
        self.mass = csr_matrix((np.concatenate([d.mass.data for d in discs]),
                                np.concatenate([d.mass.indices + o for d, o in
                                                zip(discs, self.dof_start, strict=True)]),
                                indptr), shape=(n, n))
        self.wall_mass = self.mass[self.dof_start]  # rows of the wall dofs (wall forces)
        self.outer_fixed = outer_fixed
        self.wall_control = wall_control
        self.pressure_control = wall_control == "pressure"
        self.wall = self.dof_start
        self.outer = self.dof_start + self.dof_count - 1
        fixed = [] if self.pressure_control else [self.wall]
        fixed = np.concatenate(fixed + ([self.outer] if outer_fixed else []) + [[]]).astype(int)
        self.fixed = fixed
        self.free = np.ones(n, dtype=bool)
        self.free[fixed] = False
        # band entries of the fixed dofs' rows and columns (cleared, then a unit diagonal)
        rows = np.arange(2 * p + 1)
        col_entries = (rows[:, None] * n + fixed[None, :]).ravel()
        j = fixed[None, :] + np.arange(-p, p + 1)[:, None]
        row_entries = ((p + fixed[None, :] - j) * n + j)[(j >= 0) & (j < n)]
        self.fixed_entries = np.concatenate([col_entries, row_entries])
        self.fixed_diagonal = p * n + fixed
        self.layout = Layout(
            element_dofs=self.element_dofs, dNdR=self.dNdR, N=self.N, R_points=self.R_points,
            weights=self.weights, force_weights=self.force_weights, el_start=self.el_start,
            el_count=self.el_count, dof_start=self.dof_start, dof_count=self.dof_count,
            free=self.free, R_dofs=self.R_dofs, mass_band=self.mass_band,
            fixed_entries=self.fixed_entries, fixed_diagonal=self.fixed_diagonal,
            wall_indptr=self.wall_mass.indptr, wall_indices=self.wall_mass.indices,
            wall_data=self.wall_mass.data, degree=int(p), pressure=self.pressure_control,
            outer_fixed=bool(outer_fixed))

    def subset(self, cases):
        """``(stack, dof_map, element_map)`` of the cases ``cases`` (indices into this stack)."""
        cases = np.asarray(cases)
        sub = Stack([self.discs[c] for c in cases], self.outer_fixed, self.wall_control)
        return (sub, ranges(self.dof_start[cases], self.dof_count[cases]),
                ranges(self.el_start[cases], self.el_count[cases]))

    def dofs(self, c):
        """Slice of case ``c``'s dofs."""
        return slice(self.dof_start[c], self.dof_start[c] + self.dof_count[c])

    def elements(self, c):
        """Slice of case ``c``'s elements."""
        return slice(self.el_start[c], self.el_start[c] + self.el_count[c])

    def new_buffers(self):
        """Output arrays of :meth:`assemble`: an :class:`~cavex.fem.records.Assembly` and a
        :class:`~cavex.fem.records.PointResponse`."""
        shape = self.R_points.shape
        return (Assembly(f=np.zeros(self.ndof), band=np.zeros((2 * self.degree + 1, self.ndof)),
                         folded=np.zeros(self.n_cases, dtype=bool),
                         force_scale=np.zeros(self.n_cases), Gr=np.zeros(shape),
                         Gt=np.zeros(shape)),
                PointResponse.zeros(shape))

    def assemble(self, u, theta_p, gamma_p, skip=None, out=None):
        """``(assembly, response)`` at ``u`` for the start-of-step plastic strains: the
        :class:`~cavex.fem.records.Assembly` (``f, band, folded, force_scale``, gradients) and
        the :class:`~cavex.fem.records.PointResponse`; cases with ``skip`` set keep the values
        they have in ``out`` (the previous call's result, reused in place; new arrays when
        None)."""
        if out is None:
            out = self.new_buffers()
        if skip is None:
            skip = np.zeros(self.n_cases, dtype=bool)
        assembly, response = out
        if skip.any():
            keep = ~skip[self.dof_case]
            assembly.f[keep] = 0.0
            assembly.band[:, keep] = 0.0
        else:
            assembly.f[:] = 0.0
            assembly.band[:] = 0.0
        assemble_cases(u, tuple(self.layout), self.material, theta_p, gamma_p, skip,
                       tuple(assembly), tuple(response))
        return out

    def per_case_all(self, dof_flags):
        return np.logical_and.reduceat(dof_flags, self.dof_start)

    def per_case_sum(self, point_values):
        """Sum over every case's points of a (element, point) array."""
        return np.add.reduceat(point_values.sum(axis=1), self.el_start)

    def solve(self, band, rhs, skip):
        """Solve the block-diagonal banded system for the cases without ``skip`` (bool per
        case; their increment is zero); fixed dofs get identity rows. Returns the increment and
        the cases whose block is singular. ``band`` is overwritten (pass a scratch copy).

        Each block is factorised alone (:func:`cavex.fem.banded.solve_blocks`), so a case gets
        the same bits in any stack.
        """
        flat = band.reshape(-1)
        flat[self.fixed_entries] = 0.0
        flat[self.fixed_diagonal] = 1.0
        rhs = np.where(self.free, rhs, 0.0)
        du = np.zeros_like(rhs)
        singular = np.zeros(self.n_cases, dtype=bool)
        solve_blocks(band, rhs, self.degree, self.dof_start, self.dof_count, ~skip, du,
                     singular)
        return du, singular
