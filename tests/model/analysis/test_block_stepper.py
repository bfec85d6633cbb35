"""The nonlinear step loop's block solve (model/analysis/block_stepper.py) against its one-step form.

With ``SUB_STEPS = 1`` every block is a single step: the plain implicit one-step scheme (Newton on
the five channel values of one step). The default solves 32 steps together; both solve the same
equations, so they must agree to the Newton tolerance (1e-12 relative on the channel values),
propagated through the run: 1e-9 of each output's perturbation peak leaves room for that
propagation over 2 s (measured ≈ 1e-12). The anti-slip case with zero delay makes the block cut
where the torque reduction starts (it starts in the step after the detection).
"""

from __future__ import annotations

import numpy as np
import pytest

import model.analysis.block_stepper as kernel
from model import build_model, default_operating_point, load_parameters
from model.analysis.eigen import forget_systems
from model.analysis.nonlinear import AntiSlip, nonlinear_response


@pytest.fixture(scope="module")
def bogie():
    parameters = load_parameters()
    return parameters, build_model(parameters)


@pytest.mark.slow
@pytest.mark.parametrize(("s0", "anti_slip"), [(0.005, None),
                                               (0.014, AntiSlip(delay=0.0, threshold=0.05))])
def test_block_solve_equals_one_step_solve(bogie, monkeypatch, s0, anti_slip):
    parameters, model = bogie
    op = default_operating_point(parameters, s0, 120.0)
    runs = {}
    for steps in (kernel.SUB_STEPS, 1):
        monkeypatch.setattr(kernel, "SUB_STEPS", steps)
        forget_systems(model)
        runs[steps] = nonlinear_response(model, op, t_end=0.5, fs=10_000.0, anti_slip=anti_slip)
    block, single = runs[32], runs[1]
    if anti_slip is not None:
        assert single.detection_time is not None
        assert block.detection_time == pytest.approx(single.detection_time, abs=1e-12)
    for name in single.outputs:
        peak = np.abs(single.perturbation(name)).max()
        error = np.abs(block.outputs[name] - single.outputs[name]).max()
        assert error <= 1e-9 * peak, (name, error / peak)
