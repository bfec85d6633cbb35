"""Connections between bodies: one general point-to-point spring–damper.

A :class:`SpringDamper` joins the same material point ``position`` of two bodies.  It has
translational springs/dampers along given unit directions and rotational ones about given unit
axes (small-rotation kinematics, see :mod:`model.mechanics.bodies`).  Silent blocks, primary and secondary
suspension, wheelset guides, disc and claw clutches, the driving shaft, the gear mesh (a spring
along the line of action) and the rim springs of the elastic wheels are all built from it.
Each spring direction is an *output channel*: its force (or torque) is ``k·δ + c·δ̇`` with δ the
relative displacement (body b minus body a) along/about that direction.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from model.mechanics.bodies import Body


@dataclass(frozen=True)
class Spring:
    """One spring–damper direction of a connection."""

    direction: np.ndarray  # unit vector (translation) or unit axis (rotation), global
    stiffness: float  # [N/m] or [N m/rad]
    damping: float = 0.0  # [N s/m] or [N m s/rad]
    rotational: bool = False
    channel: str = ""  # output name suffix, e.g. "torque" (empty: not an output)


@dataclass(frozen=True)
class SpringDamper:
    """Point-to-point connection of body ``b`` to body ``a`` at ``position``."""

    name: str  # e.g. "ID1.disc_clutch"
    group: str  # energy bookkeeping group, e.g. "ID1.disc_clutch"
    a: Body
    b: Body
    position: np.ndarray  # [m]
    springs: tuple[Spring, ...] = field(default_factory=tuple)

    def relative(self, spring: Spring) -> np.ndarray:
        """1 x n map from q to the relative displacement (b − a) along/about the spring [m, rad]."""
        if spring.rotational:
            G = self.b.rotation() - self.a.rotation()
        else:
            G = self.b.point(self.position) - self.a.point(self.position)
        return spring.direction @ G

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Global stiffness and damping contributions (n x n)."""
        n = self.a.W.shape[1]
        values = [self.a.W, self.b.W, self.a.origin, self.b.origin, self.position]
        for spring in self.springs:
            values += [spring.direction, np.asarray(spring.stiffness), np.asarray(spring.damping)]
        dtype = np.result_type(*values)
        K = np.zeros((n, n), dtype=dtype)  # complex for complex-step sensitivities
        B = np.zeros((n, n), dtype=dtype)
        for spring in self.springs:
            g = self.relative(spring)
            outer = np.outer(g, g)
            K += spring.stiffness * outer
            B += spring.damping * outer
        return K, B


def _scalar(value) -> float | complex:
    """float, or complex if complex (complex-step sensitivities, :mod:`model.analysis.sensitivity`)."""
    return complex(value) if np.iscomplexobj(value) else float(value)


def axis_springs(stiffness_xyz, damping_xyz=(0.0, 0.0, 0.0), rotational=False,
                 channels=("", "", "")) -> tuple[Spring, ...]:
    """Springs along (or about) the global x, y, z axes; zero stiffness and damping are skipped."""
    springs = []
    for axis, k, c, channel in zip(np.eye(3), stiffness_xyz, damping_xyz, channels, strict=True):
        if k or c:
            springs.append(Spring(axis, _scalar(k), _scalar(c), rotational, channel))
    return tuple(springs)
