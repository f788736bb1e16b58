"""Finite-difference check of an assembled tangent (shared by the kernel and contribution tests)."""
import numpy as np


def tangent_and_fd(system, values: np.ndarray, load_factor: float, h: float = 1e-7):
    """(K, K_fd) at the configuration ``values`` (the array the residual reads, set in place): the
    assembled tangent as a dense array, and −∂r/∂x by central differences of step h."""
    x0 = values.copy()
    system.residual(load_factor)
    system.jacobian()
    K = system.A.convert("dense").getDenseArray().copy()
    n = len(x0)
    Kfd = np.zeros((n, n))
    for j in range(n):
        r = []
        for sign in (1, -1):
            values[:] = x0
            values[j] += sign * h
            system.residual(load_factor)
            r.append(system.b.array.copy())
        Kfd[:, j] = -(r[0] - r[1]) / (2 * h)
    values[:] = x0
    return K, Kfd


def free_part(system, K: np.ndarray, Kfd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(K, K_fd) on the dofs that ``system`` does not constrain (its constrained columns are
    eliminated from K, so only the free block compares)."""
    fixed = np.concatenate([bc.dof_indices()[0] for bc in system.bcs])
    free = np.setdiff1d(np.arange(len(K)), fixed)
    return K[np.ix_(free, free)], Kfd[np.ix_(free, free)]
