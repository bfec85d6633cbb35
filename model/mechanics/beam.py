"""3-D Euler–Bernoulli beam finite element (axial, torsion, two bending planes; 6 DOF per node).

Local axes: ``x`` along the beam from node 1 to node 2, ``y``/``z`` principal axes of the cross
section.  Local DOF order per node ``[u, v, w, θx, θy, θz]``.  Consistent mass matrix (Przemieniecki,
Theory of Matrix Structural Analysis, 1968, §11), without rotary inertia of the cross section.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class TubeSection:
    """Circular (hollow) cross section of a steel shaft."""

    outer_radius: float  # [m]
    inner_radius: float = 0.0  # [m], 0 for a solid shaft

    @property
    def area(self) -> float:  # [m^2]
        return np.pi * (self.outer_radius**2 - self.inner_radius**2)

    @property
    def second_moment(self) -> float:  # I_y = I_z [m^4]
        return np.pi / 4 * (self.outer_radius**4 - self.inner_radius**4)

    @property
    def polar_moment(self) -> float:  # J = I_y + I_z [m^4]
        return 2 * self.second_moment


def beam_local_matrices(length: float, section: TubeSection, young: float, poisson: float,
                        density: float) -> tuple[np.ndarray, np.ndarray]:
    """Local 12 x 12 stiffness [N/m, N, N m] and consistent mass [kg, kg m, kg m^2] matrices."""
    L = length
    E, G = young, young / (2 * (1 + poisson))
    A, Iyz, J = section.area, section.second_moment, section.polar_moment
    # complex if a value is complex (complex-step sensitivities, model.analysis.sensitivity)
    dtype = np.result_type(L, E, poisson, density, A, Iyz, float)
    K = np.zeros((12, 12), dtype=dtype)
    K[np.ix_([0, 6], [0, 6])] = E * A / L * np.array([[1, -1], [-1, 1]])
    K[np.ix_([3, 9], [3, 9])] = G * J / L * np.array([[1, -1], [-1, 1]])
    bend = E * Iyz / L**3 * np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L * L, -6 * L, 2 * L * L],
                                    [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L * L, -6 * L, 4 * L * L]])
    flip = np.diag([1, -1, 1, -1])  # the x-z plane: w with θy = −dw/dx
    K[np.ix_([1, 5, 7, 11], [1, 5, 7, 11])] = bend
    K[np.ix_([2, 4, 8, 10], [2, 4, 8, 10])] = flip @ bend @ flip

    m = density * A * L
    M = np.zeros((12, 12), dtype=dtype)
    M[np.ix_([0, 6], [0, 6])] = m / 6 * np.array([[2, 1], [1, 2]])
    M[np.ix_([3, 9], [3, 9])] = density * J * L / 6 * np.array([[2, 1], [1, 2]])
    mb = m / 420 * np.array([[156, 22 * L, 54, -13 * L], [22 * L, 4 * L * L, 13 * L, -3 * L * L],
                             [54, 13 * L, 156, -22 * L], [-13 * L, -3 * L * L, -22 * L, 4 * L * L]])
    M[np.ix_([1, 5, 7, 11], [1, 5, 7, 11])] = mb
    M[np.ix_([2, 4, 8, 10], [2, 4, 8, 10])] = flip @ mb @ flip
    return K, M


def _length(vector: np.ndarray):
    """Euclidean length √(v·v), analytic in a complex perturbation (``np.linalg.norm`` is not)."""
    return np.sqrt(vector @ vector) if np.iscomplexobj(vector) else float(np.linalg.norm(vector))


def local_frame(start: np.ndarray, end: np.ndarray) -> np.ndarray:
    """3 x 3 rotation whose rows are the local axes in global coordinates (local x along the beam;
    local y chosen perpendicular to it, preferring the global z axis)."""
    ex = np.asarray(end) - np.asarray(start)
    ex = ex / _length(ex)
    helper = np.array([0.0, 0.0, 1.0]) if abs(ex[2].real) < 0.9 else np.array([1.0, 0.0, 0.0])
    ey = helper - ex * (helper @ ex)
    ey = ey / _length(ey)
    return np.vstack([ex, ey, np.cross(ex, ey)])


def beam_global_matrices(start, end, section: TubeSection, young: float, poisson: float,
                         density: float) -> tuple[np.ndarray, np.ndarray]:
    """12 x 12 stiffness and mass of a beam between two nodes, in global axes (DOF order per node
    ``[x, y, z, rx, ry, rz]``)."""
    length = _length(np.asarray(end) - np.asarray(start))
    K, M = beam_local_matrices(length, section, young, poisson, density)
    T = np.kron(np.eye(4), local_frame(start, end))
    return T.T @ K @ T, T.T @ M @ T
