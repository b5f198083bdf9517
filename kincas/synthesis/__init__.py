"""Optimisation of dimensions, path synthesis and the expression language."""
