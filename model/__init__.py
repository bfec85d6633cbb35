"""Linearized model of a locomotive bogie with two individual wheelset drives.

Public API (SI units inside; speeds in m/s, frequencies of eigenvalues in rad/s unless a name
says ``_hz``)::

    from model import load_parameters, build_model, OperatingPoint, eigen_analysis
    p = load_parameters()                      # calibrated default set
    m = build_model(p)                         # constant M, B, K
    op = OperatingPoint.from_kmh(0.005, 120, p["wheel_force"], p["motor_slope"])
    r = eigen_analysis(m, op)                  # r.stable, r.complex_pairs, r.real …
"""

from model.analysis.eigen import EigenResult, eigen_analysis, state_matrix
from model.analysis.modes import ModeCharacter, characterize, mode_character
from model.analysis.stability import NoStabilityLimit, StabilityLimit, stability_limit
from model.mechanics.assembly import BogieModel, build_model
from model.mechanics.operating_point import (
    KMH,
    OperatingPoint,
    OperatingPointError,
    adhesion_moment,
    creep_coefficients,
    creep_law,
    damping_matrix,
    default_operating_point,
    motor_torque,
)
from model.mechanics.outputs import OutputMatrices, output_matrices
from model.mechanics.parameters import ParameterError, Parameters, load_parameters

__all__ = [
    "KMH", "BogieModel", "EigenResult", "ModeCharacter", "NoStabilityLimit", "OperatingPoint",
    "OperatingPointError", "OutputMatrices", "ParameterError", "Parameters", "StabilityLimit",
    "adhesion_moment", "build_model", "characterize", "creep_coefficients", "creep_law",
    "damping_matrix", "default_operating_point", "eigen_analysis", "load_parameters",
    "mode_character", "motor_torque", "output_matrices", "stability_limit", "state_matrix",
]
