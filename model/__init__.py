"""Linearized model of a locomotive bogie with two individual wheelset drives: the library.

Everything a script needs is importable from ``model`` (SI units inside: speeds in m/s,
eigenvalues in 1/s, frequencies in Hz only where a name says ``_hz``; results are frozen
dataclasses of plain arrays)::

    from model import load_parameters, build_model, default_operating_point, eigen_analysis
    parameters = load_parameters()                      # the calibrated default set
    model = build_model(parameters)                     # constant M, B, K and the DOF names
    op = default_operating_point(parameters, s0=0.005, v_kmh=120)
    result = eigen_analysis(model, op)                  # .stable, .complex_pairs, .real_eigenvalues

The entry points, each with a runnable example in its docstring (``tests/docs/test_api.py`` runs
them):

* parameters and model: :func:`load_parameters`, :class:`Parameters`, :func:`build_model`,
  :class:`OperatingPoint`, :func:`default_operating_point`;
* eigenvalues and stability: :func:`eigen_analysis`, :func:`mode_character`,
  :func:`stability_limit`, :func:`root_locus`;
* the short circuit: :func:`short_circuit_response` (linear, closed form),
  :func:`nonlinear_response` with :class:`AntiSlip` (nonlinear creep, anti-slip protection) and
  :class:`IrregularityHistory` (rail–wheel deviations, varying wheel forces),
  :func:`required_reaction_time`;
* sensitivities: :func:`eigen_sensitivities`, :func:`limit_sensitivity`,
  :func:`peak_load_sensitivities`;
* design loads: :class:`EnvelopeStudy` and :func:`run_envelope` (max and min over a grid of
  scenarios and fault instants), :func:`history_spectra` (rainflow, equivalent ranges);
* resonances: :func:`frequency_response`, :func:`campbell`;
* a variant beside its baseline: :func:`compare_designs`.
"""

from model.analysis.antislip import ReactionTime, required_reaction_time
from model.analysis.campbell import CampbellDiagram, campbell
from model.analysis.eigen import EigenResult, eigen_analysis, state_matrix
from model.analysis.frequency_response import FrequencyResponse, frequency_response
from model.analysis.load_spectrum import LoadSpectrum, history_spectra, load_spectrum
from model.analysis.locus import RootLocus, root_locus
from model.analysis.modes import ModeCharacter, characterize, mode_character
from model.analysis.nonlinear import (
    AntiSlip,
    IrregularityHistory,
    NonlinearResult,
    nonlinear_response,
)
from model.analysis.peak_sensitivity import PeakLoadSensitivity, peak_load_sensitivities
from model.analysis.response import ResponseResult, ShortCircuit, short_circuit_response
from model.analysis.sensitivity import (
    EigenSensitivities,
    LimitSensitivity,
    eigen_sensitivities,
    limit_sensitivity,
)
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
from model.mechanics.parameters import (
    ParameterError,
    Parameters,
    load_parameters,
    parameter_hash,
    save_parameters,
)
from model.studies.compare import DesignComparison, compare_designs
from model.studies.envelope import Envelope, EnvelopeStudy, run_envelope

__all__ = [
    "KMH", "AntiSlip", "BogieModel", "CampbellDiagram", "DesignComparison", "EigenResult",
    "EigenSensitivities", "Envelope", "EnvelopeStudy", "FrequencyResponse", "IrregularityHistory",
    "LimitSensitivity",
    "LoadSpectrum", "ModeCharacter", "NoStabilityLimit", "NonlinearResult", "OperatingPoint",
    "OperatingPointError", "OutputMatrices", "ParameterError", "Parameters", "PeakLoadSensitivity",
    "ReactionTime", "ResponseResult", "RootLocus", "ShortCircuit", "StabilityLimit",
    "adhesion_moment", "build_model", "campbell", "characterize", "compare_designs",
    "creep_coefficients", "creep_law", "damping_matrix", "default_operating_point",
    "eigen_analysis", "eigen_sensitivities", "frequency_response", "history_spectra",
    "limit_sensitivity", "load_parameters", "load_spectrum", "mode_character", "motor_torque",
    "nonlinear_response", "output_matrices", "parameter_hash", "peak_load_sensitivities",
    "required_reaction_time", "root_locus", "run_envelope", "save_parameters",
    "short_circuit_response", "stability_limit", "state_matrix",
]
