"""A model of another CPU's libm, to measure the spread a test's tolerance must cover.

With ``CAVEX_TEST_LIBM_NOISE=<seed>`` set, tests/conftest.py calls :func:`install` before cavex
is imported: every transcendental function of ``math`` and ``numpy`` (``exp``, ``log``, ``sin``,
...) returns its value times ``1 + k eps``, ``k`` in (-1, 0, 0, 0, +1) chosen by a hash of the
argument's bits and the seed. Another CPU's libm or numpy SIMD loop rounds some arguments one ulp
the other way, deterministically: this does the same on about 40 % of the arguments. ``sqrt``
and the arithmetic operators are correctly rounded everywhere and are left alone, and so is
numba-compiled code (the CPU emulation of results/regenerate.sh covers it).

A test whose tolerance is set from one CPU's bits fails under some seed: the suite is run under
a few seeds (``CAVEX_TEST_LIBM_NOISE=1 python -m pytest tests``) when tolerances are set.
"""

import math
import os

import numpy as np

ENV = "CAVEX_TEST_LIBM_NOISE"
NAMES = ("exp", "expm1", "log", "log1p", "log10", "log2", "sin", "cos", "tan", "asin", "acos",
         "atan", "atan2", "sinh", "cosh", "tanh", "arcsin", "arccos", "arctan", "arctan2",
         "power", "cbrt")
_GOLDEN = np.uint64(0x9E3779B97F4A7C15)
_STEPS = np.array([-1.0, 0.0, 0.0, 0.0, 1.0]) * np.finfo(float).eps


def _factor(x, seed):
    """``1 + k eps`` per element of ``x`` (float64 bits hashed with ``seed``)."""
    bits = np.array(x, dtype=np.float64).view(np.uint64)
    with np.errstate(over="ignore"):
        mixed = (bits ^ np.uint64(seed)) * _GOLDEN
    return 1.0 + _STEPS[(mixed >> np.uint64(59)) % np.uint64(5)]


def _noisy_math(function, seed):
    def noisy(*args):
        value = function(*args)
        return value * _factor(float(args[0]), seed).item()
    noisy.__name__ = function.__name__
    return noisy


def _noisy_ufunc(function, seed):
    def noisy(*args, **kwargs):
        value = function(*args, **kwargs)
        if isinstance(value, (np.ndarray, np.floating)) and value.dtype == np.float64:
            first = np.broadcast_to(np.asarray(args[0], dtype=np.float64), np.shape(value))
            noisy_value = value * _factor(first, seed)
            if isinstance(value, np.ndarray) and "out" in kwargs:
                value[...] = noisy_value
                return value
            return noisy_value if isinstance(value, np.ndarray) else np.float64(noisy_value)
        return value
    noisy.__name__ = function.__name__
    return noisy


def install():
    """Replace the functions if ``CAVEX_TEST_LIBM_NOISE`` is set (before cavex is imported)."""
    seed = os.environ.get(ENV)
    if not seed:
        return
    for name in NAMES:
        if hasattr(math, name):
            setattr(math, name, _noisy_math(getattr(math, name), int(seed)))
        if isinstance(getattr(np, name, None), np.ufunc):
            setattr(np, name, _noisy_ufunc(getattr(np, name), int(seed)))
