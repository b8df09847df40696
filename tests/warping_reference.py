"""The direct 1-D warping search, the reference of :mod:`homebench.methods.warping.search`:
every (rho, alpha, psi) hypothesis warped and compared on its own, with ``np.interp``.

Shared by tests/test_warping.py and benchmarks/bench_warping.py.
"""

from __future__ import annotations

import numpy as np

from homebench.geometry import TWO_PI
from homebench.methods.warping.method import Warping


def direct_costs(method: Warping, current: np.ndarray, goal: np.ndarray) -> np.ndarray:
    """Cost (n_rho, n_alpha, n_psi) of ``method``'s distance, one warped prediction per triple."""
    n = method.n_columns
    theta_prime = TWO_PI * np.arange(n) / n
    support, periodic = np.arange(n + 1), np.append(goal, goal[0])  # interpolation on [0, n]
    cost = np.empty((method.n_rho, method.n_alpha, method.n_psi))
    for r, rho in enumerate(method.rho):
        for a in range(method.n_alpha):
            alpha = TWO_PI * a / method.n_alpha
            for p in range(method.n_psi):
                phi = theta_prime + TWO_PI * p / method.n_psi
                theta = (phi - np.arcsin(rho * np.sin(phi - alpha))) % TWO_PI
                predicted = np.interp(theta * n / TWO_PI, support, periodic)
                if method.distance == "dot":
                    cost[r, a, p] = -np.sum(current * predicted)
                else:
                    cost[r, a, p] = np.sum((current - predicted) ** 2)
    return cost
