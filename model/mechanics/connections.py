"""Connections between bodies: one general point-to-point spring–damper.

A :class:`SpringDamper` joins the same material point ``position`` of two bodies.  It has
translational springs/dampers along given unit directions and rotational ones about given unit
axes (small-rotation kinematics, see :mod:`model.mechanics.bodies`).  Silent blocks, primary and secondary
suspension, wheelset guides, disc and claw clutches, the driving shaft, the gear mesh (a spring
along the line of action) and the rim springs of the elastic wheels are all built from it.
Each spring direction is an *output channel*: its force (or torque) is ``k·δ + c·δ̇`` with δ the
relative displacement (body b minus body a) along/about that direction.

A :class:`MaxwellDamper` is a damper in series with a spring (the yaw dampers with their end
bushes); its inner node is a massless coordinate of its own.
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

    def channels(self) -> list[tuple[str, str, np.ndarray, np.ndarray]]:
        """The output channels: (name, unit, row on q, row on q̇) of each spring with a channel;
        its force (or torque) is ``k·δ + c·δ̇``."""
        out = []
        for spring in self.springs:
            if spring.channel:
                g = self.relative(spring)
                out.append((f"{self.name}.{spring.channel}", "N m" if spring.rotational else "N",
                            spring.stiffness * g, spring.damping * g))
        return out

    def local_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(index, K, B): the stiffness and damping contributions on the coordinates they touch
        (index: global indices; K, B: len(index) square)."""
        values = [self.a.W, self.b.W, self.a.origin, self.b.origin, self.position]
        for spring in self.springs:
            values += [spring.direction, np.asarray(spring.stiffness), np.asarray(spring.damping)]
        dtype = np.result_type(*values)  # complex for complex-step sensitivities
        rows = np.array([self.relative(spring) for spring in self.springs], dtype=dtype)
        index = np.flatnonzero(np.any(rows != 0, axis=0)) if len(rows) else np.zeros(0, int)
        K = np.zeros((len(index), len(index)), dtype=dtype)
        B = np.zeros((len(index), len(index)), dtype=dtype)
        for spring, row in zip(self.springs, rows[:, index], strict=True):
            outer = np.outer(row, row)  # exactly symmetric, as is a sum of them
            K += spring.stiffness * outer
            B += spring.damping * outer
        return index, K, B

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Global stiffness and damping contributions (n x n)."""
        return _scatter(self.a.W.shape[1], *self.local_matrices())


@dataclass(frozen=True)
class MaxwellDamper:
    """A damper in series with a spring (a Maxwell element) between the same point of two bodies,
    acting along ``direction`` — a yaw damper with its rubber end bushes.

    The inner node between damper and spring has no mass; its coordinate (``stroke_index`` in q)
    is the damper's elongation ``d`` [m], a massless, first-order coordinate
    (:mod:`model.analysis.linear_system`).  With ``δ`` the relative displacement (b − a) along the
    direction, the series spring stretches by ``δ − d`` and

        F = k (δ − d) + c_s (δ̇ − ḋ) = c ḋ          (tension, on b; −F on a)

    (``c_s``: the spring's own loss, stiffness-proportional like the other rubber parts).  In
    ``M q̈ + B q̇ + K q``: ``K += k h hᵀ``, ``B += c_s h hᵀ + c e_d e_dᵀ`` with ``h = g − e_d``
    (``g``: the 1 x n map of δ), both symmetric positive semi-definite; the power dissipated,
    ``c ḋ² + c_s (δ̇ − ḋ)²``, is never negative.  At low frequency (ω ≪ k/c) it is the damper c,
    at high frequency the spring k: a linear damper with end bushes stiffens above k/(2π c)."""

    name: str  # e.g. "secondary.yaw_damper_left"
    group: str  # energy bookkeeping group (the series spring's strain energy)
    a: Body
    b: Body
    position: np.ndarray  # [m]
    direction: np.ndarray  # unit vector, global
    stiffness: float  # series spring k [N/m]
    damping: float  # damper c [N s/m] (> 0: the stroke's equation needs it)
    stroke_index: int  # index of the internal coordinate d in q
    spring_damping: float = 0.0  # c_s of the series spring [N s/m]
    channel: str = "force"  # output name suffix of the force F

    def relative(self) -> np.ndarray:
        """1 x n map from q to δ, the relative displacement (b − a) along the direction [m]."""
        return self.direction @ (self.b.point(self.position) - self.a.point(self.position))

    def spring_elongation(self) -> np.ndarray:
        """1 x n map from q to the series spring's elongation δ − d [m]."""
        h = self.relative().astype(np.result_type(self.relative(), float), copy=True)
        h[self.stroke_index] -= 1.0
        return h

    def channels(self) -> list[tuple[str, str, np.ndarray, np.ndarray]]:
        """The force F = k (δ − d) + c_s (δ̇ − ḋ) [N] as an output channel."""
        h = self.spring_elongation()
        return [(f"{self.name}.{self.channel}", "N", self.stiffness * h, self.spring_damping * h)]

    def local_matrices(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """(index, K, B) on the coordinates the element touches (its stroke included)."""
        h = self.spring_elongation()
        index = np.flatnonzero(h != 0)
        hl = h[index]
        outer = np.outer(hl, hl)
        dtype = np.result_type(outer, np.asarray(self.stiffness), np.asarray(self.damping),
                               np.asarray(self.spring_damping))  # complex for complex steps
        K = (self.stiffness * outer).astype(dtype)
        B = (self.spring_damping * outer).astype(dtype)
        stroke = int(np.flatnonzero(index == self.stroke_index)[0])
        B[stroke, stroke] += self.damping
        return index, K, B

    def matrices(self) -> tuple[np.ndarray, np.ndarray]:
        """Global stiffness and damping contributions (n x n)."""
        return _scatter(len(self.spring_elongation()), *self.local_matrices())


def _scatter(n: int, index: np.ndarray, K: np.ndarray, B: np.ndarray
             ) -> tuple[np.ndarray, np.ndarray]:
    """The local matrices placed in n x n ones."""
    out_K = np.zeros((n, n), dtype=K.dtype)
    out_B = np.zeros((n, n), dtype=B.dtype)
    out_K[np.ix_(index, index)] = K
    out_B[np.ix_(index, index)] = B
    return out_K, out_B


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
