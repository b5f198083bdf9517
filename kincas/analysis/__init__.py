"""Sweeps, singular positions, assembly modes, sensitivities and tolerances."""
