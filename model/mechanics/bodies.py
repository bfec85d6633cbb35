"""Bodies: how a reference point's 6 small displacements follow from the generalized coordinates.

Every inertia and every connection refers to a :class:`Body`: a reference point ``origin`` [m]
and a linear map ``W`` (6 x n) from the global coordinates q to the body's 6-vector
``[u_x, u_y, u_z, θ_x, θ_y, θ_z]`` at that point.  A free rigid body or beam node owns six
coordinates (W selects them); a *carried* body (rotor, pinion, gear in the gear housing) moves
with its carrier and adds its own spin; the ground has W = 0.  Small-rotation kinematics:
``u_P = u + θ × (P − origin)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from model.mechanics.dofs import AXES6, DofMap


def _coordinates(values) -> np.ndarray:
    """Float array of a point or vector; complex if a value is complex (complex-step
    sensitivities carry a parameter's perturbation through the geometry, :mod:`model.analysis.sensitivity`)."""
    values = np.asarray(values)
    return values.astype(complex if np.iscomplexobj(values) else float)


def skew(r: np.ndarray) -> np.ndarray:
    """Matrix S(r) with S(r) a = r × a."""
    x, y, z = r
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])


def point_map(offset: np.ndarray) -> np.ndarray:
    """3 x 6 map from a body's 6-vector at its origin to the displacement of a point at ``offset``:
    ``u_P = u + θ × r = [I, −S(r)] [u; θ]``."""
    return np.hstack([np.eye(3), -skew(_coordinates(offset))])


@dataclass(frozen=True)
class Body:
    """A reference point whose 6-vector is ``W @ q``."""

    name: str  # e.g. "ID1.stator"
    origin: np.ndarray  # reference point (centre of mass for rigid bodies) [m]
    W: np.ndarray  # 6 x n map from q

    def point(self, position: np.ndarray) -> np.ndarray:
        """3 x n map from q to the displacement of the material point at ``position`` [m]."""
        return point_map(_coordinates(position) - self.origin) @ self.W

    def rotation(self) -> np.ndarray:
        """3 x n map from q to the body's small rotation vector."""
        return self.W[3:]


def free_body(name: str, origin, dofs: DofMap, axes=AXES6) -> Body:
    """A body owning the coordinates ``name.<axis>`` for the given axes (others stay zero)."""
    W = np.zeros((6, len(dofs)))
    for axis in axes:
        W[AXES6.index(axis), dofs.index(f"{name}.{axis}")] = 1.0
    return Body(name, _coordinates(origin), W)


def carried_body(name: str, origin, carrier: Body, dofs: DofMap, spin_axis: str = "ry") -> Body:
    """A body borne in ``carrier``: it translates and tilts with the carrier and owns only its
    rotation about ``spin_axis`` (coordinate ``name.<spin_axis>``)."""
    origin = _coordinates(origin)
    carried = carrier.point(origin)
    W = np.zeros((6, len(dofs)), dtype=carried.dtype)
    W[:3] = carried
    W[3:] = carrier.rotation()
    k = AXES6.index(spin_axis)
    W[k] = 0.0
    W[k, dofs.index(f"{name}.{spin_axis}")] = 1.0
    return Body(name, origin, W)


def ground(n: int) -> Body:
    return Body("ground", np.zeros(3), np.zeros((6, n)))


def rigid_mass_matrix(mass: float, inertia) -> np.ndarray:
    """6 x 6 mass matrix of a rigid body about its centre of mass, principal axes along x, y, z
    [kg, kg m^2]."""
    return np.diag([mass, mass, mass, *inertia])
