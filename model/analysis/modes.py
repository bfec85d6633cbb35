"""Mode identification: which parts move, in which direction, what deforms — and a Table-2-style
sentence generated from that.

For a mode shape Δq (complex), the kinetic-energy share of a component is
``Re(Δqᴴ M_c Δq) / Re(Δqᴴ M Δq)`` and the strain-energy share of an element group
``Re(Δqᴴ K_g Δq) / Re(Δqᴴ K Δq)``; ``M_c`` and ``K_g`` are the assembled contributions kept by
:func:`model.mechanics.assembly.build_model`.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from model.analysis.eigen import EigenResult
from model.mechanics.assembly import BogieModel

# component (mass part) -> readable name
COMPONENT_LABELS = {
    "CB": "car body", "BF": "bogie frame", "track": "track",
    **{f"ID{k}.{part}": f"{label} {k}" for k in (1, 2) for part, label in (
        ("stator", "TM"), ("rotor", "rotor"), ("pinion", "pinion"), ("gear", "gear"),
        ("hollow_shaft", "hollow shaft"), ("wheelset", "wheelset"))},
}
# element group (stiffness part) -> what deforms
STRAIN_LABELS = {
    "secondary": "secondary suspension", "track": "track", "yaw_dampers": "yaw dampers",
    "traction_link": "traction link", "anti_roll_bar": "anti-roll bar",
    **{f"ID{k}.{group}": f"{label} {k}" for k in (1, 2) for group, label in (
        ("driving_shaft", "twisting of driving shaft"), ("gear_mesh", "gearing deformation"),
        ("disc_clutch", "twisting of disc clutch"), ("claw_clutch", "claw clutch"),
        ("hollow_shaft", "hollow shaft bending/torsion"), ("axle", "axle bending/torsion"),
        ("rim_springs", "rim springs"), ("silent_blocks", "silent blocks"),
        ("primary", "primary suspension"))},
}
AXIS_WORDS = {"x": "longitudinal", "y": "lateral", "z": "vertical", "rx": "roll", "ry": "pitch",
              "rz": "yaw"}


def merge_rims(model: BogieModel) -> dict[str, list[str]]:
    """Mass parts grouped into components (the rims belong to their wheelset)."""
    groups: dict[str, list[str]] = {}
    for name in model.mass_parts:
        component = name
        if ".rim" in name:
            component = name.split(".")[0] + ".wheelset"
        groups.setdefault(component, []).append(name)
    return groups


@dataclass(frozen=True)
class ModeCharacter:
    """What a mode is made of."""

    eigenvalue: complex  # [1/s]
    kinetic: dict[str, float]  # component -> kinetic-energy share [-]
    strain: dict[str, float]  # element group -> strain-energy share [-]
    directions: dict[str, dict[str, float]]  # component -> axis -> share of its kinetic energy
    description: str
    amplitudes: dict[str, dict[str, complex]] = field(default_factory=dict)  # component -> axis ->
    # largest complex amplitude of that axis among the component's coordinates (for phases)

    def phase_cosine(self, a: str, b: str, axis: str) -> float:
        """cos of the phase angle between components a and b along ``axis`` (1: in phase,
        −1: opposite phase, 0 if either does not move that way)."""
        za = self.amplitudes.get(a, {}).get(axis, 0j)
        zb = self.amplitudes.get(b, {}).get(axis, 0j)
        if za == 0 or zb == 0:
            return 0.0
        return float(np.real(za * np.conj(zb)) / (abs(za) * abs(zb)))

    @property
    def frequency_hz(self) -> float:
        return float(abs(self.eigenvalue.imag) / (2 * np.pi))

    @property
    def damping_ratio(self) -> float:
        return float(-self.eigenvalue.real / abs(self.eigenvalue)) if self.eigenvalue else 0.0


@dataclass(frozen=True)
class _QuadraticForms:
    """Named sums of quadratic forms ``Re(x_pᴴ P x_p)`` of the parts ``P`` of a matrix, each
    name the sum of its parts, all evaluated at once: the parts' entries as one list
    (``group``: the name of each entry's part; ``rows``, ``cols``: its global coordinates)."""

    names: tuple[str, ...]
    group: np.ndarray
    rows: np.ndarray
    cols: np.ndarray
    values: np.ndarray

    def __call__(self, q: np.ndarray) -> dict[str, float]:
        """Each name's energy-like sum for the mode shape ``q`` (complex, n)."""
        products = (self.values * (np.conj(q[self.rows]) * q[self.cols])).real
        sums = np.bincount(self.group, weights=products, minlength=len(self.names))
        return {name: float(value) for name, value in zip(self.names, sums, strict=True)}


def _quadratic_forms(parts: dict, named: dict[str, list[str]]) -> _QuadraticForms:
    """The forms of ``named`` (name -> the keys of its ``parts``; :class:`Part` matrices)."""
    group, rows, cols, values = [], [], [], []
    for k, keys in enumerate(named.values()):
        for key in keys:
            part = parts[key]
            i, j = np.nonzero(part.matrix)
            group.append(np.full(len(i), k))
            rows.append(part.index[i])
            cols.append(part.index[j])
            values.append(part.matrix[i, j])
    return _QuadraticForms(tuple(named), np.concatenate(group), np.concatenate(rows),
                           np.concatenate(cols), np.concatenate(values))


def _energy_forms(model: BogieModel) -> tuple[_QuadraticForms, _QuadraticForms]:
    """(kinetic per component of :func:`merge_rims`, strain per element group), built once per
    model (ten modes' energy shares, a part of the dashboard's fast stage, in one product each
    instead of a product per part)."""
    cached = model.__dict__.get("_energy_forms")
    if cached is None:
        cached = (_quadratic_forms(model.mass_parts, merge_rims(model)),
                  _quadratic_forms(model.stiffness_parts,
                                   {g: [g] for g in model.stiffness_parts}))
        model.__dict__["_energy_forms"] = cached
    return cached


@dataclass(frozen=True)
class _ComponentLayout:
    """One component's coordinates in the order the parts list them, for the per-axis sums."""

    index: np.ndarray  # global coordinate indices (its parts' indices, concatenated)
    mass_diagonal: np.ndarray  # the parts' mass-matrix diagonals, concatenated
    axis_id: np.ndarray  # position in ``axes`` of each coordinate's axis
    axes: tuple[str, ...]  # axis names in order of first appearance
    on_axis: tuple[np.ndarray, ...]  # per axis: positions in ``index`` of its coordinates


def _layouts(model: BogieModel) -> dict[str, _ComponentLayout]:
    """Per component (:func:`merge_rims`), built once per model: the per-axis sums of
    :func:`characterize` then take one ``bincount`` instead of a Python loop over coordinates
    (ten modes' descriptions, a part of the dashboard's fast stage: 12–14 ms instead of 18–20)."""
    cached = model.__dict__.get("_mode_layouts")
    if cached is None:
        cached = {}
        for component, parts in merge_rims(model).items():
            index = np.concatenate([model.mass_parts[n].index for n in parts])
            diagonal = np.concatenate([np.diag(model.mass_parts[n].matrix) for n in parts])
            names = [model.dofs.names[i].rsplit(".", 1)[1] for i in index]
            axes = tuple(dict.fromkeys(names))
            axis_id = np.array([axes.index(a) for a in names], dtype=int)
            on_axis = tuple(np.flatnonzero(axis_id == k) for k in range(len(axes)))
            cached[component] = _ComponentLayout(np.asarray(index, dtype=int), diagonal, axis_id,
                                                 axes, on_axis)
        model.__dict__["_mode_layouts"] = cached
    return cached


def _axis_shares(layout: _ComponentLayout, q: np.ndarray) -> dict[str, float]:
    """Share of each axis in a component's kinetic energy (diagonal of its mass matrix)."""
    energy = np.bincount(layout.axis_id, weights=layout.mass_diagonal * np.abs(q[layout.index]) ** 2,
                         minlength=len(layout.axes))
    total = float(sum(float(e) for e in energy)) or 1.0
    return {axis: float(value) / total for axis, value in zip(layout.axes, energy, strict=True)}


def characterize(model: BogieModel, eigenvalue: complex, q: np.ndarray) -> ModeCharacter:
    """Energy shares and description of one mode shape Δq."""
    groups = merge_rims(model)
    layouts = _layouts(model)
    kinetic_forms, strain_forms = _energy_forms(model)
    kinetic_raw = kinetic_forms(q)
    total = sum(kinetic_raw.values()) or 1.0
    kinetic = {c: value / total for c, value in kinetic_raw.items()}
    strain_raw = strain_forms(q)
    total = sum(strain_raw.values()) or 1.0
    strain = {g: value / total for g, value in strain_raw.items()}
    directions = {c: _axis_shares(layouts[c], q) for c in groups}
    text = _describe(model, q, kinetic, strain, _with_wheelset_yaw(model, q, directions))
    amplitudes = {c: _amplitudes(layouts[c], q) for c in groups}
    return ModeCharacter(complex(eigenvalue), kinetic, strain, directions, text, amplitudes)


def _amplitudes(layout: _ComponentLayout, q: np.ndarray) -> dict[str, complex]:
    """Per axis, the component's largest complex amplitude (the first of equal ones)."""
    best: dict[str, complex] = {}
    values = q[layout.index]
    magnitude = np.abs(values)
    for axis, on_axis in zip(layout.axes, layout.on_axis, strict=True):
        top = on_axis[magnitude[on_axis].argmax()]
        if magnitude[top] > 0:
            best[axis] = complex(values[top])
    return best


def wheelset_yaw_fraction(model: BogieModel, q: np.ndarray) -> dict[str, float]:
    """Per drive: the share of the journals' longitudinal motion that is yaw (journals 11 and 15
    in opposite phase) rather than longitudinal translation (in phase).  The axle is a chain of
    beam nodes, so its yaw shows in the nodes' x translations, not in an ``rz`` coordinate."""
    fractions = {}
    for drive in ("ID1", "ID2"):
        x11 = q[model.dofs.index(f"{drive}.ax11.x")]
        x15 = q[model.dofs.index(f"{drive}.ax15.x")]
        yaw, longitudinal = abs(x15 - x11) ** 2, abs(x15 + x11) ** 2
        fractions[drive] = float(yaw / (yaw + longitudinal)) if yaw + longitudinal > 0 else 0.0
    return fractions


def _with_wheelset_yaw(model: BogieModel, q: np.ndarray,
                       directions: dict[str, dict[str, float]]) -> dict[str, dict[str, float]]:
    """Directions for the *description*: each wheelset's longitudinal share split into
    translation and yaw by :func:`wheelset_yaw_fraction` (``ModeCharacter.directions`` keeps the
    per-coordinate shares the calibration's signatures were fitted with)."""
    out = dict(directions)
    for drive, fraction in wheelset_yaw_fraction(model, q).items():
        component = f"{drive}.wheelset"
        if component not in out:
            continue
        shares = dict(out[component])
        x = shares.get("x", 0.0)
        shares["x"] = x * (1.0 - fraction)
        shares["rz"] = shares.get("rz", 0.0) + x * fraction
        out[component] = shares
    return out


TRANSLATIONS_FIRST = ("x", "y", "z", "rx", "ry", "rz")  # "longitudinal–yaw", as Table 2 writes


def _direction_words(component: str, shares: dict[str, float]) -> str:
    ranked = sorted(shares.items(), key=lambda item: -item[1])
    torsional = component.split(".")[-1] in ("rotor", "pinion", "gear")
    words = []
    for axis, share in ranked[:2]:
        if words and share < 0.3 * ranked[0][1]:
            break
        word = "torsion" if torsional or (axis == "ry" and "hollow" in component) else AXIS_WORDS[axis]
        if word not in words:
            words.append(word)
    if len(words) > 1 and not torsional:
        order = {AXIS_WORDS[axis]: i for i, axis in enumerate(TRANSLATIONS_FIRST)}
        words.sort(key=lambda word: order.get(word, len(order)))
    return ("combined " + "–".join(words)) if len(words) > 1 else words[0]


def _phase_index(model: BogieModel, component: str, axis: str) -> np.ndarray:
    """Indices of the coordinates ``<component>.….<axis>`` (cached per model)."""
    cache = model.__dict__.setdefault("_phase_indices", {})
    if (component, axis) not in cache:
        names = [n for n in model.dofs.names
                 if n.startswith(component + ".") and n.endswith("." + axis)]
        cache[component, axis] = (np.asarray(model.dofs.indices(names), dtype=int) if names
                                  else np.zeros(0, dtype=int))
    return cache[component, axis]


def _phase(model: BogieModel, q: np.ndarray, a: str, b: str, axis: str) -> str:
    """'in phase' / 'opposite phase' of two components' motion along ``axis``."""
    def representative(component: str) -> complex:
        index = _phase_index(model, component, axis)
        if not len(index):
            return 0j
        values = q[index]
        return complex(values[np.argmax(np.abs(values))])

    za, zb = representative(a), representative(b)
    if za == 0 or zb == 0:
        return ""
    return "in phase" if np.real(za * np.conj(zb)) >= 0 else "opposite phase"


def _describe(model, q, kinetic, strain, directions) -> str:
    ranked = [c for c, share in sorted(kinetic.items(), key=lambda item: -item[1]) if share >= 0.1]
    if not ranked:
        ranked = [max(kinetic, key=kinetic.get)]
    lead = ranked[0]
    main_axis = max(directions[lead], key=directions[lead].get)
    sentence = f"{_direction_words(lead, directions[lead])} of {COMPONENT_LABELS.get(lead, lead)}"
    others = []
    for component in ranked[1:4]:
        axis = max(directions[component], key=directions[component].get)
        label = COMPONENT_LABELS.get(component, component)
        if axis == main_axis:
            phase = _phase(model, q, lead, component, axis)
            others.append(f"{label} {phase}".strip())
        else:
            others.append(f"{_direction_words(component, directions[component])} of {label}")
    if others:
        sentence += " with " + ", ".join(others)
    deforms = [STRAIN_LABELS.get(g, g) for g, share in sorted(strain.items(), key=lambda i: -i[1])
               if share >= 0.25][:2]
    if deforms:
        sentence += "; " + ", ".join(deforms)
    return sentence


def describe_modes(model: BogieModel, result: EigenResult, indices) -> list[str]:
    """Descriptions of the modes ``indices`` of an eigen-analysis."""
    return [mode_character(model, result, i).description for i in indices]


def mode_character(model: BogieModel, result: EigenResult, index: int) -> ModeCharacter:
    return characterize(model, result.eigenvalues[index], result.mode_shape(index))


def strongest_strain_modes(model: BogieModel, result: EigenResult, groups,
                           max_frequency_hz: float = 2000.0) -> dict[str, tuple[float, float]]:
    """For each strain group (e.g. ``"ID1.disc_clutch"``): (its strain-energy share [-], the
    frequency Im λ / 2π [Hz]) of the complex mode up to ``max_frequency_hz`` in which its share
    is largest; (0, 0) if no mode strains it."""
    best = {group: (0.0, 0.0) for group in groups}
    for index in result.complex_index:
        lam = result.eigenvalues[index]
        if lam.imag / (2 * np.pi) > max_frequency_hz:
            break
        strain = mode_character(model, result, index).strain
        for group in best:
            share = strain.get(group, 0.0)
            if share > best[group][0]:
                best[group] = (share, float(lam.imag / (2 * np.pi)))
    return best
