"""A compiled LU solver for the block-diagonal banded systems of a stack (partial pivoting).

The Newton matrix of a stack is block diagonal, one block per case, each banded with ``p``
sub- and super-diagonals, given in ``scipy.linalg.solve_banded`` storage
(``band[p + i - j, j] = A[i, j]``). :func:`solve_blocks` factorises and solves the blocks of the
cases asked for, one after the other, with the algorithm of LAPACK's unblocked ``dgbtf2`` and
``dgbtrs``: Gaussian elimination with row interchanges inside the band, the upper bandwidth
growing to ``2p`` by the interchanges. A block whose pivot is zero or not finite is flagged
singular (its increment is left at zero). Compared with ``scipy.linalg.solve_banded`` (LAPACK
``dgbsv``) in ``tests/test_fem_kernels.py``.
"""

import numpy as np
from numba import njit


@njit(cache=True, error_model="numpy")
def solve_blocks(band, rhs, p, starts, counts, solve, du, singular):
    """Solve block ``c`` (dofs ``starts[c]:starts[c] + counts[c]``) for every ``c`` with
    ``solve[c]``; the solution goes into ``du`` and ``singular[c]`` is set where the block is
    singular."""
    kv = 2 * p
    work = np.zeros((3 * p + 1, counts.max()))
    piv = np.zeros(counts.max(), dtype=np.int64)
    b = np.zeros(counts.max())
    for c in range(starts.size):
        if not solve[c]:
            continue
        s0, m = starts[c], counts[c]
        work[:, :m] = 0.0
        for j in range(m):  # A[i, j] -> work[kv + i - j, j]
            for i in range(max(0, j - p), min(m, j + p + 1)):
                work[kv + i - j, j] = band[p + i - j, s0 + j]
            b[j] = rhs[s0 + j]
        ok = True
        ju = 0
        for j in range(m):
            km = min(p, m - 1 - j)
            jp = 0
            largest = abs(work[kv, j])
            for t in range(1, km + 1):
                if abs(work[kv + t, j]) > largest:
                    largest = abs(work[kv + t, j])
                    jp = t
            piv[j] = j + jp
            pivot = work[kv + jp, j]
            if pivot == 0.0 or not np.isfinite(pivot):
                ok = False
                break
            ju = max(ju, min(j + p + jp, m - 1))
            if jp != 0:  # interchange rows j and j + jp in columns j..ju
                for col in range(j, ju + 1):
                    upper = work[kv + j - col, col]
                    work[kv + j - col, col] = work[kv + j + jp - col, col]
                    work[kv + j + jp - col, col] = upper
            if km > 0:
                inverse = 1.0 / work[kv, j]
                for t in range(1, km + 1):
                    work[kv + t, j] *= inverse
                for col in range(j + 1, ju + 1):
                    u_jc = work[kv + j - col, col]
                    if u_jc != 0.0:
                        for t in range(1, km + 1):
                            work[kv + j + t - col, col] -= work[kv + t, j] * u_jc
        if not ok:
            singular[c] = True
            continue
        for j in range(m):  # L y = P b
            km = min(p, m - 1 - j)
            if piv[j] != j:
                other = b[piv[j]]
                b[piv[j]] = b[j]
                b[j] = other
            for t in range(1, km + 1):
                b[j + t] -= work[kv + t, j] * b[j]
        for j in range(m - 1, -1, -1):  # U x = y
            b[j] /= work[kv, j]
            for i in range(max(0, j - kv), j):
                b[i] -= work[kv + i - j, j] * b[j]
        for j in range(m):
            du[s0 + j] = b[j]
