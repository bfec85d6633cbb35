"""The rail–wheel deviation histories of the nonlinear response: values and derivatives of both
kinds, and the one-line errors of bad input.

Tolerances, and why:

* harmonic values: 1e-12 of a, a ω, a ω² (closed form; the rounding of the phase ωt, up to
  24 rad here, is a few 1e-15);
* sampled history of a sinusoid at 1 ms samples, 5 Hz: the cubic spline's error away from the
  ends is about (ω Δt)⁴/384 for Δ, (ω Δt)³/24 for Δ̇ and (ω Δt)²/12 for Δ̈ (ω Δt = 0.031: 2.5e-9,
  1.3e-6, 8e-5) of the scales a, a ω, a ω²: bounds 1e-8, 1e-6 and 2e-4 (measured 2.5e-9, 2.4e-7
  and 6.6e-5).
"""

from __future__ import annotations

import numpy as np
import pytest

from model import build_model, load_parameters
from model.analysis.nonlinear_inputs import WHEELS, IrregularityHistory, NonlinearError
from model.mechanics.irregularity import irregularity_inputs


def test_the_wheels_are_the_models_irregularity_inputs():
    assert WHEELS == irregularity_inputs(build_model(load_parameters()))


def test_harmonic_values_and_derivatives():
    f, a, phase = 12.5, 2e-4, 30.0
    d = IrregularityHistory.harmonic(f, {"ID2.rim14.irregularity": a},
                                     {"ID2.rim14.irregularity": phase})
    t = np.linspace(0.0, 0.3, 301)
    delta, rate, acceleration = d.values(t)
    w, phi = 2 * np.pi * f, np.radians(phase)
    assert delta.shape == rate.shape == acceleration.shape == (len(t), 4)
    assert np.all(delta[:, :3] == 0.0)
    assert np.allclose(delta[:, 3], a * np.cos(w * t + phi), rtol=0, atol=1e-12 * a)
    assert np.allclose(rate[:, 3], -a * w * np.sin(w * t + phi), rtol=0, atol=1e-12 * a * w)
    assert np.allclose(acceleration[:, 3], -a * w * w * np.cos(w * t + phi), rtol=0,
                       atol=1e-12 * a * w * w)
    assert d.is_harmonic
    assert d.span == (-np.inf, np.inf)


def test_sampled_values_follow_the_spline():
    f, a = 5.0, 1e-3
    w = 2 * np.pi * f
    times = np.arange(0.0, 1.0 + 1e-9, 1e-3)
    d = IrregularityHistory.sampled(times, {"ID1.rim12.irregularity": a * np.sin(w * times)})
    t = np.linspace(0.1, 0.9, 777)  # away from the ends
    delta, rate, acceleration = d.values(t)
    assert np.abs(delta[:, 0] - a * np.sin(w * t)).max() <= 1e-8 * a
    assert np.abs(rate[:, 0] - a * w * np.cos(w * t)).max() <= 1e-6 * a * w
    assert np.abs(acceleration[:, 0] + a * w * w * np.sin(w * t)).max() <= 2e-4 * a * w * w
    assert np.all(delta[:, 1:] == 0.0)
    assert d.span == (0.0, times[-1])
    assert not d.is_harmonic
    # an array of all four wheels is the same history
    full = np.zeros((len(times), 4))
    full[:, 0] = a * np.sin(w * times)
    assert np.array_equal(IrregularityHistory.sampled(times, full).values(t)[2], acceleration)


@pytest.mark.parametrize(("build", "message"), [
    (lambda: IrregularityHistory.harmonic(-1.0, 1e-4), "frequency must be ≥ 0"),
    (lambda: IrregularityHistory.harmonic(10.0, [1e-4, 0.0]), "one per wheel"),
    (lambda: IrregularityHistory.harmonic(10.0, np.nan), "finite"),
    (lambda: IrregularityHistory.harmonic(10.0, {"ID3.rim12.irregularity": 1e-4}), "unknown"),
    (lambda: IrregularityHistory.harmonic(10.0, "a"), "numbers"),
    (lambda: IrregularityHistory.sampled([0.0, 0.1, 0.2], np.zeros((3, 4))), "at least 4"),
    (lambda: IrregularityHistory.sampled([0.0, 0.2, 0.1, 0.3], np.zeros((4, 4))), "increasing"),
    (lambda: IrregularityHistory.sampled(np.arange(5.0), np.zeros((5, 3))), "5 x 4"),
    (lambda: IrregularityHistory.sampled(np.arange(5.0), np.full((5, 4), np.inf)), "finite"),
    (lambda: IrregularityHistory.sampled(np.arange(5.0), {"ID1.rim12.irregularity": [0.0] * 4}),
     "5 values"),
    (lambda: IrregularityHistory.sampled(np.arange(5.0), {"x": np.zeros(5)}), "unknown"),
])
def test_bad_histories(build, message):
    with pytest.raises(NonlinearError, match=message) as error:
        build()
    assert "\n" not in str(error.value)
