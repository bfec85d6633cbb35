"""The random track: the spectrum's variance in space and in time, the outputs' PSD with the
wheels' cross terms against single-wheel frequency responses, the RMS against adaptive
quadrature, the damage against the spectral-fatigue module."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import running_system
from model.analysis.frequency_response import direct_response, output_indices
from model.analysis.spectral_fatigue import SNCurve, SpectralMoments, dirlik_damage_rate
from model.analysis.track_spectrum import (
    LOW,
    TrackSpectrumError,
    random_response,
    spectral_damage,
    track_spectrum,
)
from model.analysis.wheel_excitation import combined_response

OUTPUTS = ["ID1.disc_clutch.torque", "ID2.axle.wheel_seat_14.torque"]


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    model = build_model(parameters)
    op = default_operating_point(parameters, s0=0.002, v_kmh=120.0)  # a stable running system
    return model, op, random_response(model, op, outputs=OUTPUTS)


def test_variance_is_the_same_in_space_and_in_time():
    """∫ S dΩ in closed form against quadrature, and ∫ G(f) df at 120 km/h against it (the
    change of variable f = Ω v / 2π)."""
    low, high = 2 * math.pi / LOW.wavelength_max, 2 * math.pi / LOW.wavelength_min
    spatial, _ = quad(lambda x: float(LOW.spatial(x)), low, high, limit=200, epsrel=1e-12)
    assert LOW.variance() == pytest.approx(spatial, rel=1e-9)
    v = 120 / 3.6
    f_lo, f_hi = LOW.band_hz(v)
    temporal, _ = quad(lambda f: float(LOW.temporal(f, v)), f_lo, f_hi * (1 - 1e-12), limit=200,
                       epsrel=1e-12)
    assert temporal == pytest.approx(spatial, rel=1e-9)
    assert track_spectrum("low") is LOW
    with pytest.raises(TrackSpectrumError, match="unknown track spectrum"):
        track_spectrum("class 9")


def test_psd_has_every_cross_term_of_the_four_wheels(setup):
    """G_y = Σ_j Σ_k H_j G e^(i(φ_j − φ_k)) H_k*: the input matrix written out with H_j from each
    wheel's frequency response alone and the phases −ω x-delay / v by hand."""
    model, op, result = setup
    assert result.stable
    wheelbase = model.parameters["wheelbase"]
    for k in (5, len(result.f_hz) // 2, len(result.f_hz) - 3):
        f = float(result.f_hz[k])
        omega = 2 * math.pi * f
        phases = np.array([0.0, 0.0, -omega * wheelbase / op.v, -omega * wheelbase / op.v])
        H = np.column_stack([direct_response(model, op, [f], input=name, outputs=OUTPUTS)[:, 0]
                             for name in ("ID1.rim12.irregularity", "ID1.rim14.irregularity",
                                          "ID2.rim12.irregularity", "ID2.rim14.irregularity")])
        G = LOW.temporal(f, op.v) * np.exp(1j * (phases[:, None] - phases[None, :]))
        expected = np.einsum("pj,jk,pk->p", H, G, H.conj()).real
        # to 1e-7 of each output's largest PSD: a value far below its peak (the torque of a
        # wheel seat where the four wheels' contributions nearly cancel) loses relative digits
        # in either sum
        largest = result.psd.max(axis=1)
        assert np.all(np.abs(result.psd[:, k] - expected) <= 1e-7 * largest)


@pytest.mark.slow
def test_rms_against_adaptive_quadrature(setup):
    """The RMS against scipy's scalar adaptive quadrature of the one output's PSD (its own
    direct solves, the running system's resonances as break points, relative error 1e-6): to
    1e-3, the vector quadrature's requested accuracy (which the largest outputs' highest moment
    controls, so this output's m0 is usually better)."""
    model, op, result = setup
    row = result.output("ID1.disc_clutch.torque")
    f_lo, f_hi = LOW.band_hz(op.v)
    lam = running_system(model, op).eigen[0]
    breaks = sorted(x for x in lam.imag / (2 * math.pi) if f_lo < x < f_hi)
    matrices, _ = output_indices(model, op)
    full_row = matrices.names.index("ID1.disc_clutch.torque")

    def psd_row(f: float) -> float:
        H, _ = combined_response(model, op, f, np.array([full_row]))
        return float(LOW.temporal(f, op.v) * abs(H[0]) ** 2)

    variance, _ = quad(psd_row, f_lo, f_hi * (1 - 1e-12), points=breaks[:50], limit=500,
                       epsrel=1e-6)
    assert result.rms[row] == pytest.approx(math.sqrt(variance), rel=1e-3)


def test_damage_is_dirliks_of_the_psd(setup):
    _, _, result = setup
    row = result.output("ID1.disc_clutch.torque")
    curve = SNCurve(fatigue_limit=0.5 * float(result.rms[row]), knee_cycles=1e6, slope=6.0)
    damage = spectral_damage(result, "ID1.disc_clutch.torque", curve)
    moments = SpectralMoments(*result.moments[row])
    assert damage.rms == pytest.approx(result.rms[row], rel=1e-12)
    assert damage.dirlik_rate == pytest.approx(dirlik_damage_rate(moments, curve), rel=1e-12)
    assert damage.dirlik_rate > 0
    assert damage.narrow_band_rate >= damage.dirlik_rate
