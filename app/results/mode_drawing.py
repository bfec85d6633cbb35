"""Where the drawn points of the bogie move in a mode shape (the Modes view's drawing).

The translation of every drawn point of ``model.positions`` is linear in the displacement vector
Δq: u + θ × r for a point carried by a rigid body.  The map is built once per model.
"""

from __future__ import annotations

import numpy as np


def drawing_owner(model_, point: str) -> tuple[str, bool]:
    """(body whose coordinates move ``point``, whether the point has its own translations)."""
    names = set(model_.dofs.names)
    if f"{point}.x" in names:
        return point, True
    if point.startswith("secondary."):
        return "BF", False
    drive = point.split(".")[0]
    return f"{drive}.stator", False


def _point_displacements_direct(model_, q: np.ndarray) -> dict[str, np.ndarray]:
    """:func:`point_displacements` point by point (u + θ × r for points carried by a body);
    used once per model to build the linear map, and by the test that checks the map."""
    index = {name: i for i, name in enumerate(model_.dofs.names)}
    out: dict[str, np.ndarray] = {}
    for point, position in model_.positions.items():
        if point == "CB":  # longitudinal and vertical (its yaw turns it about its own point)
            out[point] = np.array([q[index["CB.x"]].real, 0.0, q[index["CB.z"]].real])
            continue
        owner, own = drawing_owner(model_, point)
        u = np.array([q[index[f"{owner}.{a}"]].real for a in ("x", "y", "z")])
        theta = np.array([q[index[f"{owner}.{a}"]].real for a in ("rx", "ry", "rz")])
        if not own:
            u = u + np.cross(theta, np.asarray(position) - model_.positions[owner])
        out[point] = u
    return out


def _displacement_map(model_) -> tuple[list[str], np.ndarray]:
    """(drawn points, D) with the translations of all points = D Δq (3·points x n), built once
    per model from the kinematics above (it is linear in Δq)."""
    cached = model_.__dict__.get("_displacement_map")
    if cached is None:
        names = list(model_.positions)
        columns = []
        for j in range(model_.n):
            unit = np.zeros(model_.n)
            unit[j] = 1.0
            moved = _point_displacements_direct(model_, unit)
            columns.append(np.concatenate([moved[name] for name in names]))
        cached = (names, np.array(columns).T)
        model_.__dict__["_displacement_map"] = cached
    return cached


def point_displacements(model_, q: np.ndarray) -> dict[str, np.ndarray]:
    """Real translation (x, y, z) [m per unit mode amplitude] of every drawn point of
    ``model.positions`` for the displacement vector Δq (rigid-body kinematics for points carried
    by a body: u + θ × r)."""
    names, D = _displacement_map(model_)
    moved = (D @ np.real(q)).reshape(len(names), 3)
    return dict(zip(names, moved, strict=True))
