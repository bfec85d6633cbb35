"""Parameter studies as pure descriptions (numpy/scipy only): stability maps over
(s0, v, N0, b_M) and the stability limit s0*(v) for lists of N0 and b_M — each, when given, also
over a list of the converter's torque-control bandwidth f_c (``motor_bandwidth``: a value of the
parameter set, so a model per value; not given: the set's own, and no such dimension in the
store) —, cut into chunks that a
serial loop or the Dask engine (:mod:`model.studies.engine`) runs and a store
(:mod:`model.studies.store`) keeps.

A chunk of a map is one s0-line, computed by :func:`model.studies.s0_line.s0_line` (the methods,
their basis and their checks are described there); a chunk of a limit study is one point, by
:func:`model.analysis.stability.stability_limit`.  The assembled model of a parameter set is
kept per process (:func:`cached_model`).  Units: SI.
"""

from __future__ import annotations

import hashlib
import itertools
import json
import threading
from dataclasses import dataclass, field
from functools import partial

import numpy as np

from model.analysis.stability import NoStabilityLimit, stability_limit
from model.mechanics.assembly import BogieModel, build_model
from model.mechanics.operating_point import OperatingPoint
from model.mechanics.parameters import Parameters, parameter_hash
from model.studies.s0_line import check_s0, s0_line

_MODELS: dict[str, BogieModel] = {}
_MODELS_LOCK = threading.Lock()
_MODEL_SOURCE = None  # where cached_model takes its models from (None: _MODELS)


def set_model_source(source) -> None:
    """Let :func:`cached_model` take its models from ``source(parameters)`` (None: its own
    cache again): a served dashboard's results cache keeps one model per parameter set, which
    the studies and checks it runs in its own process then share."""
    global _MODEL_SOURCE
    _MODEL_SOURCE = source


def cached_model(parameters: Parameters) -> BogieModel:
    """The assembled model of a parameter set, kept per process by the set's hash (a worker
    process assembles it once per study, not once per chunk), or the one of the source set by
    :func:`set_model_source`."""
    if _MODEL_SOURCE is not None:
        return _MODEL_SOURCE(parameters)
    key = parameter_hash(parameters)
    with _MODELS_LOCK:
        if key not in _MODELS:
            if len(_MODELS) >= 4:
                _MODELS.pop(next(iter(_MODELS)))
            _MODELS[key] = build_model(parameters)
        return _MODELS[key]


SET_VALUES = ("motor_bandwidth",)  # the parameter set's values a study may take a list of


def _set_values(values, label: str) -> tuple[float, ...]:
    """A list of one of the parameter set's values (:data:`SET_VALUES`; empty: the set's own):
    finite, distinct, >= 0 (the set's own checks come when a chunk replaces the value)."""
    if values is None or len(values) == 0:
        return ()
    values = _grid(values, label)
    if len(set(values)) != len(values) or min(values) < 0:
        raise ValueError(f"{label}: values must be distinct and >= 0")
    return values


def _chunk_parameters(study, parameters: Parameters, index: int | None) -> Parameters:
    """The set of a chunk: ``parameters`` with the study's value of index ``index`` of each list
    of :data:`SET_VALUES` it has (None: none)."""
    changes = {name: getattr(study, name)[index] for name in SET_VALUES
               if getattr(study, name) and index is not None}
    return parameters.replace(**changes) if changes else parameters


def _grid(values, label: str) -> tuple[float, ...]:
    values = tuple(float(x) for x in np.atleast_1d(np.asarray(values, dtype=float)))
    if not values:
        raise ValueError(f"{label}: empty list")
    if not all(np.isfinite(values)):
        raise ValueError(f"{label}: values must be finite")
    return values


@dataclass(frozen=True)
class MapStudy:
    """A stability map over the grid s0 × v × N0 × b_M (SI).  A chunk is one s0-line."""

    s0: tuple[float, ...]  # creepages [-], increasing
    v: tuple[float, ...]  # speeds [m/s]
    N0: tuple[float, ...]  # wheel forces [N]
    b_M: tuple[float, ...]  # motor slopes [N m s/rad]
    max_frequency_hz: float = 10.0  # reduction basis disc (method "reduced", see s0_line)
    rtol: float = 1e-6  # relative accuracy of the decisive eigenvalues (method "reduced")
    method: str = "reduced"  # s0_line's method: "reduced", "continuation" or "dense"
    # torque-control bandwidths f_c of ID2's converter [Hz] (empty: the parameter set's own)
    motor_bandwidth: tuple[float, ...] = ()
    kind: str = field(default="map", init=False)

    def __post_init__(self) -> None:
        for name in ("s0", "v", "N0", "b_M"):
            object.__setattr__(self, name, _grid(getattr(self, name), name))
        object.__setattr__(self, "motor_bandwidth",
                           _set_values(self.motor_bandwidth, "motor_bandwidth"))
        check_s0(self.s0)
        if self.method not in ("continuation", "reduced", "dense"):
            raise ValueError(f"method must be 'continuation', 'reduced' or 'dense', "
                             f"got '{self.method}'")
        for v in self.v:
            for n0 in self.N0:
                for bm in self.b_M:
                    OperatingPoint(self.s0[0], v, n0, bm)  # validates the ranges
        OperatingPoint(self.s0[-1], self.v[0], self.N0[0], self.b_M[0])

    @property
    def shape(self) -> tuple[int, ...]:
        return (len(self.s0), *self.point_shape)

    @property
    def point_dims(self) -> tuple[str, ...]:
        """The dimensions of a point (a chunk key indexes them): v, N0, b_M and each list of
        the set's values given."""
        return ("v", "N0", "b_M", *(name for name in SET_VALUES if getattr(self, name)))

    @property
    def point_shape(self) -> tuple[int, ...]:
        return tuple(len(getattr(self, name)) for name in self.point_dims)

    def chunks(self) -> list[tuple[int, ...]]:
        """Chunk keys (index of v, of N0, of b_M[, of f_c]): one s0-line each."""
        return list(itertools.product(*(range(n) for n in self.point_shape)))

    def arguments(self) -> dict:
        """The study's arguments (JSON-able; stored with the results, compared on resume; a list
        of the set's values only when given, so a study as before has the same arguments)."""
        return {"kind": self.kind, "s0": list(self.s0), "v": list(self.v), "N0": list(self.N0),
                "b_M": list(self.b_M), "max_frequency_hz": self.max_frequency_hz,
                "rtol": self.rtol, "method": self.method,
                **{name: list(getattr(self, name)) for name in SET_VALUES if getattr(self, name)}}

    def run_chunk(self, parameters: Parameters, key: tuple[int, ...]) -> dict:
        """The s0-line of chunk ``key`` as plain arrays (what the store writes)."""
        i, j, k = key[:3]
        model = cached_model(_chunk_parameters(self, parameters, key[3] if len(key) > 3 else None))
        line = s0_line(model, self.s0, self.v[i], self.N0[j], self.b_M[k],
                       method=self.method, max_frequency_hz=self.max_frequency_hz,
                       rtol=self.rtol)
        return {"largest_real_part": line.largest_real_part, "stable": line.stable,
                "flutter_pairs": line.flutter_pairs.astype(np.int16),
                "divergent_real": line.divergent_real.astype(np.int16),
                "s0_limit": line.s0_limit, "dense_points": line.dense_points,
                "outside_max_real_part": line.outside_max_real_part}


@dataclass(frozen=True)
class LimitStudy:
    """The stability limit s0*(v) for lists of N0 and b_M (SI).  A chunk is one point."""

    v: tuple[float, ...]  # speeds [m/s]
    N0: tuple[float, ...]  # wheel forces [N]
    b_M: tuple[float, ...]  # motor slopes [N m s/rad]
    xtol: float = 1e-7  # s0* to this absolute tolerance [-]
    # torque-control bandwidths f_c of ID2's converter [Hz] (empty: the parameter set's own)
    motor_bandwidth: tuple[float, ...] = ()
    kind: str = field(default="limit", init=False)

    def __post_init__(self) -> None:
        for name in ("v", "N0", "b_M"):
            object.__setattr__(self, name, _grid(getattr(self, name), name))
        object.__setattr__(self, "motor_bandwidth",
                           _set_values(self.motor_bandwidth, "motor_bandwidth"))
        for v in self.v:
            for n0 in self.N0:
                for bm in self.b_M:
                    OperatingPoint(1e-3, v, n0, bm)

    point_dims = MapStudy.point_dims
    point_shape = MapStudy.point_shape
    chunks = MapStudy.chunks

    @property
    def shape(self) -> tuple[int, ...]:
        return self.point_shape

    def arguments(self) -> dict:
        return {"kind": self.kind, "v": list(self.v), "N0": list(self.N0), "b_M": list(self.b_M),
                "xtol": self.xtol,
                **{name: list(getattr(self, name)) for name in SET_VALUES if getattr(self, name)}}

    def run_chunk(self, parameters: Parameters, key: tuple[int, ...]) -> dict:
        """s0* at one (v, N0, b_M[, f_c]) (nan when there is none in the searched range)."""
        i, j, k = key[:3]
        model = cached_model(_chunk_parameters(self, parameters, key[3] if len(key) > 3 else None))
        try:
            limit = stability_limit(model, self.v[i], self.N0[j], self.b_M[k],
                                    xtol=self.xtol)
            return {"s0_limit": limit.s0_limit, "evaluations": limit.evaluations}
        except NoStabilityLimit:
            return {"s0_limit": float("nan"), "evaluations": 0}


def run_chunk(study, parameters: Parameters, key) -> dict:
    """Module-level entry of a chunk (what an executor ships to a worker)."""
    return study.run_chunk(parameters, key)


def run_serial(study, parameters: Parameters) -> dict:
    """All chunks in this process, in order: {key: chunk result} (the reference of the engine)."""
    return {key: run_chunk(study, parameters, key) for key in study.chunks()}


def chunk_function(study, parameters: Parameters):
    """``key -> chunk result`` for ``map``-like executors."""
    return partial(run_chunk, study, parameters)


def study_fingerprint(study, parameters: Parameters) -> str:
    """Short hash of the study's arguments and the parameter set (names a store's contents)."""
    text = json.dumps({"arguments": study.arguments(), "parameters": parameter_hash(parameters)},
                      sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]
