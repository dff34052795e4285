"""Spherically symmetric Lagrangian elastoplastic finite-element solver (scikit-fem)."""
