"""Residuals, structure, Newton and compiled kernels: the only place casadi is used."""
