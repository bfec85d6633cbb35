"""Degrees of freedom: one naming scheme for the whole project.

Axes (vehicle-fixed, right-handed): ``x`` longitudinal in the running direction, ``y`` lateral
(along the axles, to the left), ``z`` vertical upwards.  The origin is the bogie centre at the
height of the axle centres.  A 6-DOF body or beam node has the coordinates ``x, y, z`` (small
translations of its reference point [m]) and ``rx, ry, rz`` (small rotations about axes parallel
to x, y, z [rad]: roll, pitch/spin, yaw).  A name is ``<subsystem>.<part>.<coordinate>``, e.g.
``ID1.rotor.ry``, ``ID2.rim14.z``, ``BF.rz``, ``CB.z``.  The massless inner coordinate of a
Maxwell element (a yaw damper with its end bushes) is its damper's elongation
``<element>.stroke`` [m], e.g. ``secondary.yaw_damper_left.stroke``.  The massless coordinate of
a converter's torque control is its filter's output ``<drive>.converter.filtered_angle`` [rad]
(the rotor's angle relative to the stator and to the vehicle's rolling, high-passed at the
control's bandwidth), e.g. ``ID2.converter.filtered_angle``.

The published study writes a wheel rim's coordinates as ``[u, v, w, φ, ϑ, ψ]`` =
``[y, z, x, ry, rz, rx]`` here (see :data:`PAPER_RIM_ORDER`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

AXES6 = ("x", "y", "z", "rx", "ry", "rz")
# the SI unit of each coordinate, by the name's last part; stroke: a Maxwell element's damper
# elongation, filtered_angle: a converter's torque-control filter (both massless coordinates)
UNITS = {"x": "m", "y": "m", "z": "m", "rx": "rad", "ry": "rad", "rz": "rad",
         "stroke": "m", "filtered_angle": "rad"}
FILTERED_ANGLE = "filtered_angle"  # the last part of a converter filter's coordinate
PAPER_RIM_ORDER = ("y", "z", "x", "ry", "rz", "rx")  # the study's [u, v, w, φ, ϑ, ψ]


@dataclass(frozen=True)
class DofMap:
    """Ordered list of generalized coordinates with name lookup."""

    names: tuple[str, ...]  # coordinate names, in the order of the coordinate vector q

    def __post_init__(self) -> None:
        if len(set(self.names)) != len(self.names):
            raise ValueError("duplicate DOF names")
        object.__setattr__(self, "_index", {name: i for i, name in enumerate(self.names)})

    def __len__(self) -> int:
        return len(self.names)

    def index(self, name: str) -> int:
        """Position of a coordinate in q (KeyError with the name if unknown)."""
        try:
            return self._index[name]  # type: ignore[attr-defined]
        except KeyError:
            raise KeyError(f"unknown DOF '{name}'") from None

    def indices(self, names: list[str] | tuple[str, ...]) -> np.ndarray:
        return np.array([self.index(name) for name in names], dtype=int)

    def unit(self, name: str) -> str:
        """SI unit of a coordinate ('m' or 'rad', by the name's last part, :data:`UNITS`)."""
        return UNITS[name.rsplit(".", 1)[1]]

    def select(self, prefix: str) -> np.ndarray:
        """Indices of all coordinates whose name starts with ``prefix``."""
        return np.array([i for i, n in enumerate(self.names) if n.startswith(prefix)], dtype=int)

    def subsystem(self, name: str) -> str:
        return name.split(".", 1)[0]

    def part(self, name: str) -> str:
        """``'ID1.rim12'`` for ``'ID1.rim12.z'``."""
        return name.rsplit(".", 1)[0]
