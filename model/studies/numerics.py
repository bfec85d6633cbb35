"""The numerical environment in which a calibration writes the same bytes on every machine.

A least squares of many phases amplifies the last bits of its arithmetic: the same command moves
the calibrated values by up to about 1e-5 relative between two x86-64 processors, because the
libraries choose their kernels by the processor they find.

* OpenBLAS (NumPy's and SciPy's) picks its kernels by the processor; ``OPENBLAS_CORETYPE``
  fixes them (Haswell's: AVX2 and FMA, which the server and desktop x86-64 processors of the last
  decade have; :func:`pinnable` checks), and one BLAS thread fixes the split of its sums.
* NumPy dispatches its loops (``exp``, ``sin``, reductions …) to AVX-512 versions where the
  processor has them; ``NPY_DISABLE_CPU_FEATURES`` keeps them at the AVX2 level.

:func:`reproducible_environment` gives the environment with these pins, to be set before NumPy
is imported (``bogie calibrate`` runs itself again in it).  The bytes also depend on the
releases of NumPy and SciPy (and their OpenBLAS): the same releases, the same bytes.
"""

from __future__ import annotations

import platform
from collections.abc import Mapping

BLAS_KERNELS = "Haswell"  # OpenBLAS's AVX2 + FMA kernels
MARKER = "BOGIE_PINNED_NUMERICS"  # set in the pinned environment: what it was pinned for


def _numpy_cpu() -> tuple[dict[str, bool], list[str]]:
    """NumPy's processor features (name → present) and the targets it dispatches to."""
    try:
        from numpy._core import _multiarray_umath as umath
    except ImportError:  # NumPy 1.x
        from numpy.core import _multiarray_umath as umath
    return dict(umath.__cpu_features__), list(umath.__cpu_dispatch__)


def pinnable(features: Mapping[str, bool] | None = None, machine: str | None = None) -> bool:
    """Whether this processor can run the pinned kernels: x86-64 with AVX2 and FMA."""
    machine = (machine or platform.machine()).lower()
    features = _numpy_cpu()[0] if features is None else features
    return (machine in ("x86_64", "amd64") and bool(features.get("AVX2"))
            and bool(features.get("FMA3")))


def disabled_numpy_targets(dispatch: list[str] | None = None) -> list[str]:
    """NumPy's dispatch targets above AVX2 (the AVX-512 family), to be disabled."""
    dispatch = _numpy_cpu()[1] if dispatch is None else dispatch
    return [name for name in dispatch if name.startswith("AVX512") or name == "X86_V4"]


def pinned_values(dispatch: list[str] | None = None) -> dict[str, str]:
    """The environment variables that pin the numerics (one BLAS thread, OpenBLAS's Haswell
    kernels, NumPy's loops at most AVX2)."""
    values = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1",
              "OPENBLAS_CORETYPE": BLAS_KERNELS}
    disabled = disabled_numpy_targets(dispatch)
    if disabled:
        values["NPY_DISABLE_CPU_FEATURES"] = " ".join(disabled)
    values[MARKER] = "calibration"
    return values


def reproducible_environment(environ: Mapping[str, str]) -> dict[str, str] | None:
    """``environ`` with the pins of :func:`pinned_values`; ``None`` where the processor cannot
    take them (not x86-64 with AVX2 and FMA: its bytes are its own)."""
    if not pinnable():
        return None
    return {**environ, **pinned_values()}


def is_pinned(environ: Mapping[str, str]) -> bool:
    """Whether ``environ`` already holds every pin (no second run needed)."""
    return all(environ.get(name) == value for name, value in pinned_values().items())


def description() -> str:
    """The pins in words (for the command's progress line)."""
    disabled = disabled_numpy_targets()
    return (f"OpenBLAS's {BLAS_KERNELS} kernels on one thread, NumPy's loops without "
            f"{', '.join(disabled) if disabled else 'AVX-512'}")


def in_effect() -> dict:
    """The numerics of this process: each OpenBLAS library's kernels and threads (NumPy's and
    SciPy's), and NumPy's dispatch targets that this process uses."""
    import scipy.linalg  # noqa: F401 - load SciPy's BLAS too
    from threadpoolctl import threadpool_info

    features, dispatch = _numpy_cpu()
    return {"blas": [{"library": info.get("prefix", info.get("internal_api", "")),
                      "kernels": info.get("architecture"), "threads": info.get("num_threads")}
                     for info in threadpool_info() if info.get("user_api") == "blas"],
            "numpy_targets": [name for name in dispatch if features.get(name)]}
