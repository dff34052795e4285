"""Verification reports, FE-tabulated resistance and batch sweeps."""
