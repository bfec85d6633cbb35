"""Unit tests of the modes' energy bookkeeping (model.analysis.modes)."""

from __future__ import annotations

import numpy as np

from model import build_model, default_operating_point, eigen_analysis, load_parameters
from model.analysis.modes import _energy_forms, merge_rims


def test_energy_forms_are_the_parts_quadratic_forms():
    """The kinetic energy per component and the strain energy per element group, all parts at
    once, equal each part's own Re(xᴴ P x) summed per name (the mode shapes of the default point:
    complex, every coordinate moving), to rounding: 1e-10 of the mode's total energy (the
    summation order differs; a stiff beam's terms, large and of both signs, cancel to a small
    energy, which leaves about 1e-12 of the total between the two orders).  The energy shares a
    description reads differ by that much at most."""
    parameters = load_parameters()
    model = build_model(parameters)
    result = eigen_analysis(model, default_operating_point(parameters))
    kinetic, strain = _energy_forms(model)
    for index in result.complex_index[:10]:
        q = result.vectors[:model.n, int(index)]

        def form(part, q=q):
            x = q[part.index]
            return float(np.real(np.conj(x) @ part.matrix @ x))

        by_part = {c: sum(form(model.mass_parts[n]) for n in names)
                   for c, names in merge_rims(model).items()}
        together = kinetic(q)
        assert together.keys() == by_part.keys()
        total = sum(by_part.values())
        for name, value in by_part.items():
            assert abs(together[name] - value) <= 1e-10 * total, name
        by_part = {g: form(part) for g, part in model.stiffness_parts.items()}
        together = strain(q)
        assert together.keys() == by_part.keys()
        total = sum(by_part.values())
        for name, value in by_part.items():
            assert abs(together[name] - value) <= 1e-10 * total, name
