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
Another study describes its own layout (:class:`StoreLayout`: dimensions, coordinates, variables
and the marker dimensions a chunk key indexes) with a ``store_layout()`` method, e.g. the design-
load envelope (:meth:`model.studies.envelope.EnvelopeStudy.store_layout`, docs/design-loads.md).

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
         "b_M": "N m s/rad", "motor_bandwidth": "Hz"}
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


@dataclass(frozen=True)
class StoreLayout:
    """What a study's store holds (plain data; the map and limit studies' layout is built here,
    other studies describe their own with a ``store_layout()`` method).  Every variable is
    chunked by one element along the marker dimensions (a chunk key indexes them) and whole
    along the others; ``chunk_done`` spans the marker dimensions."""

    sizes: dict[str, int]  # dimension -> length
    coords: dict[str, tuple[tuple[str, ...], np.ndarray, dict]]  # name -> (dims, values, attrs)
    # name -> (dims, dtype, fill value, attrs)
    variables: dict[str, tuple[tuple[str, ...], object, object, dict]]
    marker_dims: tuple[str, ...]  # dimensions indexed by a chunk key

    def region(self, name: str, key: tuple[int, ...]) -> tuple:
        """The index of chunk ``key`` in variable ``name`` (an int per marker dimension, a whole
        slice along the others)."""
        dims = self.variables[name][0]
        return tuple(key[self.marker_dims.index(d)] if d in self.marker_dims else slice(None)
                     for d in dims)


def store_layout(study) -> StoreLayout:
    """The layout of ``study``'s store (its own ``store_layout()`` if it has one)."""
    own = getattr(study, "store_layout", None)
    if own is not None:
        return own()
    point_dims = study.point_dims  # v, N0, b_M and each list of the set's values given
    coords = {name: (name, np.array(getattr(study, name))) for name in point_dims}
    coords["v_kmh"] = ("v", np.array(study.v) / KMH)
    if study.kind == "map":
        coords["s0"] = ("s0", np.array(study.s0))
    coords = {name: ((dims,), data, {"units": UNITS[name]}) for name, (dims, data)
              in coords.items()}
    sizes = {name: len(coords[name][1]) for name in (*point_dims, "s0") if name in coords}
    variables = {name: (point_dims, dtype, fill, {"units": UNITS[name],
                                                   "description": DESCRIPTIONS[name]})
                 for name, (dtype, fill) in POINT_VARIABLES[study.kind].items()}
    if study.kind == "map":
        for name, (dtype, fill) in LINE_VARIABLES.items():
            variables[name] = (("s0", *point_dims), dtype, fill,
                               {"units": UNITS[name], "description": DESCRIPTIONS[name]})
    return StoreLayout(sizes, coords, variables, point_dims)


def create_store(path: str | Path, study, parameters: Parameters) -> None:
    """A new store for ``study`` at ``path`` (replaces what is there) with every chunk unfinished."""
    import xarray as xr

    layout = store_layout(study)
    variables, encoding = {}, {}
    specs = dict(layout.variables)
    specs["chunk_done"] = (layout.marker_dims, np.int8, 0,
                           {"units": UNITS["chunk_done"], "description": DESCRIPTIONS["chunk_done"]})
    for name, (dims, dtype, fill, attrs) in specs.items():
        shape = tuple(layout.sizes[d] for d in dims)
        variables[name] = xr.Variable(dims, np.full(shape, fill, dtype=dtype), attrs)
        encoding[name] = {"chunks": tuple(1 if d in layout.marker_dims else layout.sizes[d]
                                          for d in dims), "fill_value": fill}
    coords = {name: xr.Variable(dims, data, attrs)
              for name, (dims, data, attrs) in layout.coords.items()}
    dataset = xr.Dataset(variables, coords=coords, attrs=_attributes(study, parameters))
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
        self.layout = store_layout(study)

    def write(self, key: tuple[int, ...], result: dict) -> None:
        for name in self.layout.variables:
            self.group[name][self.layout.region(name, key)] = np.asarray(result[name])
        self.group["chunk_done"][tuple(key)] = 1


class MemoryWriter:
    """The same as :class:`StoreWriter` into numpy arrays (``arrays``: name -> array over the
    variable's dimensions, its fill value where no chunk was written)."""

    def __init__(self, study):
        self.layout = layout = store_layout(study)
        self.arrays = {name: np.full(tuple(layout.sizes[d] for d in dims), fill, dtype=dtype)
                       for name, (dims, dtype, fill, _) in layout.variables.items()}

    def write(self, key: tuple[int, ...], result: dict) -> None:
        for name, array in self.arrays.items():
            array[self.layout.region(name, key)] = np.asarray(result[name])


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


def run_in_memory(study, parameters: Parameters, map_unordered,
                  progress: Callable[[int, int, float], None] | None = None) -> dict:
    """Every chunk of ``study`` computed as :func:`run_into_store` does, into numpy arrays
    (:class:`MemoryWriter`) instead of a store: name -> array."""
    from model.studies.maps import chunk_function

    todo = study.chunks()
    writer = MemoryWriter(study)
    start = time.monotonic()
    if progress is not None:
        progress(0, len(todo), 0.0)
    for done, (index, result) in enumerate(map_unordered(chunk_function(study, parameters), todo),
                                           start=1):
        writer.write(todo[index], result)
        if progress is not None:
            progress(done, len(todo), time.monotonic() - start)
    return writer.arrays
