"""Results of a study as an xarray Dataset in a Zarr store (format 3, no consolidated metadata).

Layout of a map store (``MapStudy``)::

    largest_real_part (s0, v, N0, b_M) float64 [1/s]   chunk (all s0, 1, 1, 1): one s0-line
    stable            (s0, v, N0, b_M) bool
    flutter_pairs     (s0, v, N0, b_M) int16  [-]
    divergent_real    (s0, v, N0, b_M) int16  [-]
    dense_points      (s0, v, N0, b_M) bool   (solved by a full eigen-analysis)
    s0_limit          (v, N0, b_M)     float64 [-]  (nan: no limit inside the s0 range)
    outside_max_real_part (v, N0, b_M) float64 [1/s]
    chunk_done        (v, N0, b_M)     int8   completion marker, chunk (1, 1, 1)

A limit store (``LimitStudy``) holds ``s0_limit`` and ``evaluations`` over (v, N0, b_M).
Coordinates: ``s0`` [-], ``v`` [m/s] (and ``v_kmh``), ``N0`` [N], ``b_M`` [N m s/rad].

Each finished chunk is written into its own Zarr chunks (one file per variable, written
atomically by Zarr's local store: temporary file, then rename), and *then* its ``chunk_done``
entry (its own one-element chunk, also atomic).  A chunk is finished if and only if its marker
is set, so an interrupted or killed study leaves only whole chunks behind; a resume recomputes
exactly the chunks without a marker.  The attributes hold the parameter set's hash, the code
version, the study's arguments and the units; a resume with another parameter set or other
arguments is refused (:class:`StoreMismatch`).

Written with zarr-python directly (region writes of a pre-created store) and read with xarray
(``consolidated=False``: Zarr format 3 has no consolidated metadata in its specification, and
xarray's default would warn).
"""

from __future__ import annotations

import json
import subprocess
import time
from collections.abc import Callable
from dataclasses import dataclass
from importlib import metadata
from pathlib import Path

import numpy as np

from model.mechanics.operating_point import KMH
from model.mechanics.parameters import Parameters, parameter_hash

UNITS = {"largest_real_part": "1/s", "stable": "-", "flutter_pairs": "-", "divergent_real": "-",
         "dense_points": "-", "s0_limit": "-", "outside_max_real_part": "1/s",
         "evaluations": "-", "chunk_done": "-", "s0": "-", "v": "m/s", "v_kmh": "km/h", "N0": "N",
         "b_M": "N m s/rad"}
DESCRIPTIONS = {
    "largest_real_part": "largest real part of all non-rigid eigenvalues",
    "stable": "all non-rigid eigenvalues in the closed left half-plane",
    "flutter_pairs": "complex eigenvalue pairs with positive real part",
    "divergent_real": "positive real eigenvalues",
    "dense_points": "point solved by a full eigen-analysis (else the continuation or the "
                    "reduced model)",
    "s0_limit": "stability limit s0*: smallest creepage where the bogie turns unstable "
                "(nan: none in the searched range)",
    "outside_max_real_part": "method reduced: largest real part of the eigenvalues outside the "
                             "reduction basis at the anchors of the s0-line (its ends, the "
                             "steepest falling creep slope); nan for the continuation (no "
                             "eigenvalue is outside)",
    "evaluations": "eigen-analyses used by the limit search",
    "chunk_done": "1 when the chunk (s0-line or limit point) is completely written",
}
LINE_VARIABLES = {"largest_real_part": (np.float64, np.nan), "stable": (bool, False),
                  "flutter_pairs": (np.int16, -1), "divergent_real": (np.int16, -1),
                  "dense_points": (bool, False)}
POINT_VARIABLES = {"map": {"s0_limit": (np.float64, np.nan),
                           "outside_max_real_part": (np.float64, np.nan)},
                   "limit": {"s0_limit": (np.float64, np.nan), "evaluations": (np.int32, -1)}}
FORMAT = "bogie-study-1"


class StoreMismatch(ValueError):
    """A store that does not belong to this study (other parameters, arguments or kind)."""


def code_version() -> str:
    """The package version and, in a git checkout, the commit (``+dirty`` with local changes)."""
    version = metadata.version("bogie-drive-dynamics")
    root = Path(__file__).resolve().parents[2]  # the project (model/studies/store.py)
    try:
        commit = subprocess.run(["git", "-C", str(root), "describe", "--always", "--dirty"],
                                capture_output=True, text=True, timeout=5, check=True).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return version
    return f"{version}+{commit}" if commit else version


def _attributes(study, parameters: Parameters) -> dict:
    return {"format": FORMAT, "study": study.kind,
            "arguments": json.dumps(study.arguments(), sort_keys=True),
            "parameters_hash": parameter_hash(parameters),
            "parameters_source": parameters.source, "code_version": code_version()}


def _coordinates(study) -> dict:
    import xarray as xr

    coords = {"v": ("v", np.array(study.v)), "N0": ("N0", np.array(study.N0)),
              "b_M": ("b_M", np.array(study.b_M)), "v_kmh": ("v", np.array(study.v) / KMH)}
    if study.kind == "map":
        coords["s0"] = ("s0", np.array(study.s0))
    return {name: xr.Variable(dims, data, {"units": UNITS[name]}) for name, (dims, data)
            in coords.items()}


def create_store(path: str | Path, study, parameters: Parameters) -> None:
    """A new store for ``study`` at ``path`` (replaces what is there) with every chunk unfinished."""
    import xarray as xr

    point_dims = ("v", "N0", "b_M")
    shape = tuple(len(getattr(study, d)) for d in point_dims)
    variables = {}
    encoding = {}
    specs = dict(POINT_VARIABLES[study.kind])
    specs["chunk_done"] = (np.int8, 0)
    for name, (dtype, fill) in specs.items():
        variables[name] = xr.Variable(point_dims, np.full(shape, fill, dtype=dtype),
                                      {"units": UNITS[name], "description": DESCRIPTIONS[name]})
        encoding[name] = {"chunks": (1, 1, 1), "fill_value": fill}
    if study.kind == "map":
        for name, (dtype, fill) in LINE_VARIABLES.items():
            variables[name] = xr.Variable(("s0", *point_dims),
                                          np.full((len(study.s0), *shape), fill, dtype=dtype),
                                          {"units": UNITS[name], "description": DESCRIPTIONS[name]})
            encoding[name] = {"chunks": (len(study.s0), 1, 1, 1), "fill_value": fill}
    dataset = xr.Dataset(variables, coords=_coordinates(study), attrs=_attributes(study, parameters))
    dataset.to_zarr(str(path), mode="w", consolidated=False, zarr_format=3, encoding=encoding)


def check_store(path: str | Path, study, parameters: Parameters) -> None:
    """Raise :class:`StoreMismatch` unless the store at ``path`` was made for this study and
    this parameter set."""
    import zarr

    try:
        group = zarr.open_group(str(path), mode="r")
        attrs = dict(group.attrs)
    except (FileNotFoundError, ValueError, KeyError, OSError) as error:
        raise StoreMismatch(f"'{path}' is not a study store ({error})") from None
    if attrs.get("format") != FORMAT:
        raise StoreMismatch(f"'{path}' is not a study store of this program")
    if attrs.get("study") != study.kind:
        raise StoreMismatch(f"'{path}' holds a {attrs.get('study')} study, not a {study.kind} study")
    if attrs.get("parameters_hash") != parameter_hash(parameters):
        raise StoreMismatch(f"'{path}' was computed with another parameter set (hash "
                            f"{str(attrs.get('parameters_hash'))[:12]}…, this one "
                            f"{parameter_hash(parameters)[:12]}…)")
    if json.loads(attrs.get("arguments", "{}")) != json.loads(json.dumps(study.arguments())):
        raise StoreMismatch(f"'{path}' was computed with other study arguments: "
                            f"{attrs.get('arguments')}")


def finished_chunks(path: str | Path) -> set[tuple[int, int, int]]:
    """Keys of the chunks whose completion marker is set."""
    import zarr

    done = zarr.open_group(str(path), mode="r")["chunk_done"][...]
    return {tuple(int(i) for i in key) for key in np.argwhere(done == 1)}


class StoreWriter:
    """Writes finished chunks into a pre-created store (data first, then the marker)."""

    def __init__(self, path: str | Path, study):
        import zarr

        self.group = zarr.open_group(str(path), mode="r+")
        self.study = study

    def write(self, key: tuple[int, int, int], result: dict) -> None:
        i, j, k = key
        if self.study.kind == "map":
            for name in LINE_VARIABLES:
                self.group[name][:, i, j, k] = np.asarray(result[name])
        for name in POINT_VARIABLES[self.study.kind]:
            self.group[name][i, j, k] = result[name]
        self.group["chunk_done"][i, j, k] = 1


def open_study(path: str | Path):
    """The store as an :class:`xarray.Dataset` (loaded into memory)."""
    import xarray as xr

    with xr.open_zarr(str(path), consolidated=False) as dataset:
        return dataset.load()


# --- running a study into a store ------------------------------------------------------------

@dataclass(frozen=True)
class StudyRun:
    """What one run of a study did."""

    total: int  # chunks of the study
    skipped: int  # chunks found finished in the store (resume)
    computed: int  # chunks computed and written by this run
    seconds: float  # wall time of the computation [s]


def prepare_store(path: str | Path, study, parameters: Parameters, resume: bool) -> list:
    """The chunk keys still to compute; creates the store (``resume=False``; the path must not
    exist) or checks it (``resume=True``; raises :class:`StoreMismatch`)."""
    path = Path(path)
    if resume:
        if not path.exists():
            raise StoreMismatch(f"'{path}' does not exist: nothing to resume")
        check_store(path, study, parameters)
        done = finished_chunks(path)
    else:
        if path.exists():
            raise StoreMismatch(f"'{path}' exists: continue it with --resume, or remove it")
        if not path.parent.is_dir():
            raise StoreMismatch(f"directory '{path.parent}' does not exist")
        create_store(path, study, parameters)
        done = set()
    return [key for key in study.chunks() if key not in done]


def run_into_store(study, parameters: Parameters, path: str | Path, map_unordered,
                   resume: bool = False,
                   progress: Callable[[int, int, float], None] | None = None) -> StudyRun:
    """Compute the unfinished chunks of ``study`` with ``map_unordered(function, items)`` (an
    iterator of (index, result) as they finish: :meth:`model.studies.engine.StudyEngine.
    map_unordered` or :func:`model.studies.engine.serial_map_unordered`) and write each into the
    store at ``path`` as it arrives.  ``progress(finished, total, elapsed seconds)`` after each.
    An interruption (Ctrl-C, an error) leaves every chunk written so far finished."""
    from model.studies.maps import chunk_function

    todo = prepare_store(path, study, parameters, resume)
    total = len(study.chunks())
    skipped = total - len(todo)
    writer = StoreWriter(path, study)
    start = time.monotonic()
    computed = 0
    if progress is not None:
        progress(skipped, total, 0.0)
    for index, result in map_unordered(chunk_function(study, parameters), todo):
        writer.write(todo[index], result)
        computed += 1
        if progress is not None:
            progress(skipped + computed, total, time.monotonic() - start)
    return StudyRun(total, skipped, computed, time.monotonic() - start)
