"""Ready-made metrics for `hooke.sweep`: functions of a finished `Simulation`. Being defined in
an importable module, they reach process-pool workers and Ray tasks alike."""

import numpy as np


def lowest_point(sim) -> float:
    """The height of the lowest particle, metres (how far a cloth drapes)."""
    return float(sim.positions[:, 1].min())


def mean_height(sim) -> float:
    """The mean height of the particles, metres (how far a body sags)."""
    return float(sim.positions[:, 1].mean())


def max_speed(sim) -> float:
    """The fastest particle's speed, m/s (whether a body has come to rest)."""
    return float(np.linalg.norm(sim.velocities, axis=1).max())
