"""Polygonal wheels: the steady response over speed against the single-wheel frequency responses
of :mod:`model.analysis.frequency_response` combined by hand with the wheels' phases (the rear
wheelset a wheelbase later), the polygon's frequency n v / (2π r0), bad input."""

from __future__ import annotations

import math

import numpy as np
import pytest

from model import build_model, default_operating_point, load_parameters
from model.analysis.frequency_response import direct_response
from model.analysis.wheel_excitation import (
    WheelExcitationError,
    parse_polygon,
    polygon_frequency_hz,
    polygon_response,
    wheel_phases,
)
from model.mechanics.operating_point import KMH

OUTPUTS = ["ID1.driving_shaft.torque", "ID1.disc_clutch.torque", "ID2.axle.wheel_seat_14.torque"]


@pytest.fixture(scope="module")
def setup():
    parameters = load_parameters()
    model = build_model(parameters)
    # s0 = 0.002: the running system is stable over the speeds used here
    op = default_operating_point(parameters, s0=0.002)
    return model, op


def test_phases_delay_the_rear_wheelset_by_the_wheelbase(setup):
    model, op = setup
    omega = 2 * math.pi * 37.0
    phases = wheel_phases(model, omega, op.v)
    wheelbase = model.parameters["wheelbase"]
    assert list(model.rims) == ["ID1.rim12", "ID1.rim14", "ID2.rim12", "ID2.rim14"]
    assert phases[:2] == pytest.approx([0.0, 0.0], abs=0)
    assert phases[2:] == pytest.approx([-omega * wheelbase / op.v] * 2, rel=1e-14)


def test_polygon_response_is_the_phased_sum_of_the_wheels_frequency_responses(setup):
    """Per order: a |Σ_j H_j(2π f) e^(i φ_j)| with H_j from each wheel's input alone (the
    frequency response's direct solve of the running system), f = n v / (2π r0), φ_j = −n Δx_j /
    r0; the sum over orders; a refined speed is a local maximum of the response."""
    model, op = setup
    r0 = model.parameters["wheel_radius"]
    polygon = parse_polygon("7=40,20=25")
    assert polygon == {7: pytest.approx(40e-6), 20: pytest.approx(25e-6)}
    speeds = np.linspace(60, 120, 7) * KMH
    result = polygon_response(model, op, speeds, polygon, outputs=OUTPUTS)
    assert set(speeds) <= set(result.v)
    wheelbase = model.parameters["wheelbase"]
    for k, n in enumerate(result.orders):
        assert result.phases_deg[k] == pytest.approx(
            np.degrees([0, 0, -n * wheelbase / r0, -n * wheelbase / r0]), rel=1e-14)
    for i in (0, 3, len(result.v) - 1):
        v = float(result.v[i])
        point = default_operating_point(model.parameters, s0=op.s0, v_kmh=v / KMH)
        expected = np.zeros(len(OUTPUTS))
        for k, n in enumerate(result.orders):
            f = float(polygon_frequency_hz(n, v, r0))
            assert result.frequencies_hz[k, i] == pytest.approx(n * v / (2 * math.pi * r0))
            H = sum(direct_response(model, point, [f], input=name, outputs=OUTPUTS)[:, 0]
                    * np.exp(1j * math.radians(phase))
                    for name, phase in zip(result.inputs, result.phases_deg[k], strict=True))
            amplitude = result.amplitudes[k] * np.abs(H)
            assert result.by_order[k, :, i] == pytest.approx(amplitude, rel=1e-9)
            expected += amplitude
        assert result.total[:, i] == pytest.approx(expected, rel=1e-9)
    assert result.unstable_kmh == ()


@pytest.mark.parametrize(("text", "message"), [
    ("", "no wheel polygon"), ("20", "order=amplitude"), ("2.5=10", "whole number"),
    ("0=10", "not allowed"), ("20=-1", "amplitude must be"), ("20=10,20=5", "twice"),
])
def test_bad_polygon(text, message):
    with pytest.raises(WheelExcitationError, match=message):
        parse_polygon(text)


@pytest.mark.parametrize("v_kmh", [20.0, 120.0, 200.0])
def test_modal_wheels_equal_the_direct_solves(setup, v_kmh):
    """The modal form of the phased wheel sum (ModalWheels: what the random track integrates)
    equals the dense solve of the dynamic stiffness (WheelTransfer) to 1e-7 of each output's
    largest value over the band (the modal tolerance is 1e-8 of it; a factor 10 for the dense
    solves' own rounding).  Above the lowest speeds every frequency is modal; at 20 km/h the
    band reaches down to where the rigid-body modes' cancelling terms exceed the tolerance and
    those frequencies are solved directly."""
    from model.analysis.frequency_response import output_indices
    from model.analysis.track_spectrum import LOW
    from model.analysis.wheel_excitation import ModalWheels, WheelTransfer

    model, op0 = setup
    op = default_operating_point(model.parameters, s0=op0.s0, v_kmh=v_kmh)
    _, rows = output_indices(model, op, OUTPUTS)
    f = np.geomspace(*LOW.band_hz(op.v), 60)
    modal = ModalWheels(model, op, rows)
    H = modal.combined(f)
    direct = WheelTransfer(model, op, rows)
    reference = np.column_stack([direct.combined(float(x))[0] for x in f])
    scale = np.abs(reference).max(axis=1, keepdims=True)
    assert np.max(np.abs(H - reference) / scale) < 1e-7
    if v_kmh >= 120:
        assert modal.direct_points == 0
