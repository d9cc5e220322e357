"""bulge from Python: the pipeline's stages over in-memory data.

Each function calls the bulge library (the same Rust crate as the ``bulge``
command line, built into ``bulge._native``) and returns what the command
line would write, in memory: CSV files as pandas DataFrames with the same
column names and units, TOML files as dicts. Figures are left to the user's
matplotlib; the SVG/PNG figures the command line draws are in ``files``.

Errors: ``BadInput`` (a ``ValueError``) when an input is refused, the command
line's exit status 2; ``Failure`` (a ``RuntimeError``) when the work failed,
exit status 1. Both carry the command line's message.
"""

from __future__ import annotations

import io
import sys
from dataclasses import dataclass, field
from typing import Dict, List, Tuple

import pandas as pd

from . import _native
from ._native import BadInput, Failure

if sys.version_info >= (3, 11):
    import tomllib as _toml
else:  # pragma: no cover
    import tomli as _toml

__all__ = ["BadInput", "Failure", "RunOutput", "run", "HAS_OPENCV", "__version__"]

__version__ = _native.version()

#: True when this build has the photo stages (track, run, study): they need
#: the system OpenCV when the package is built.
HAS_OPENCV: bool = _native.has_opencv()

if not HAS_OPENCV:
    import warnings as _warnings

    _warnings.warn(
        "bulge was built without OpenCV: run, track, init and study are not available "
        "(install the system OpenCV, e.g. apt-get install libopencv-dev clang libclang-dev, "
        "and reinstall with pip install ./python)",
        stacklevel=2,
    )


def _table(data: bytes) -> pd.DataFrame:
    """A CSV file of the command line as a DataFrame (its header as columns)."""
    return pd.read_csv(io.BytesIO(data))


@dataclass
class RunOutput:
    """Everything ``bulge run`` writes, in memory.

    ``heights``, ``stress_strain``, ``simulated`` (and ``laws`` when the
    law was chosen among several) are the CSV files as DataFrames;
    ``material`` is material.toml as a dict; ``files`` maps every file name
    to its bytes (figures included); ``notes`` are (stage, text) pairs;
    ``warnings`` the fit's warnings; ``unsolved`` the pressures (Pa) at
    which a model gave no height.
    """

    heights: pd.DataFrame
    stress_strain: pd.DataFrame
    material: dict
    simulated: pd.DataFrame
    laws: "pd.DataFrame | None" = None
    stress_strain_sources: "pd.DataFrame | None" = None
    files: Dict[str, bytes] = field(default_factory=dict)
    notes: List[Tuple[str, str]] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)
    unsolved: List[float] = field(default_factory=list)


def _need_opencv(name: str) -> None:
    if not HAS_OPENCV:
        raise Failure(
            f"bulge.{name} needs the photo stages, and this build has no OpenCV: install the "
            "system OpenCV (apt-get install libopencv-dev clang libclang-dev) and reinstall "
            "with pip install ./python"
        )


def run(experiment) -> RunOutput:
    """The whole pipeline on an experiment file, as ``bulge run`` (the GIL is
    released while it works). Settings come from the file's ``[run]`` and
    ``[simulate]`` tables, as on the command line without flags."""
    _need_opencv("run")
    files, notes, warnings, unsolved = _native.run(str(experiment))
    by_name = {name: bytes(data) for name, _stage, data in files}

    def csv(name):
        return _table(by_name[name]) if name in by_name else None

    return RunOutput(
        heights=csv("heights.csv"),
        stress_strain=csv("stress_strain.csv"),
        material=_toml.loads(by_name["material.toml"].decode()),
        simulated=csv("simulated.csv"),
        laws=csv("laws.csv"),
        stress_strain_sources=csv("stress_strain_sources.csv"),
        files=by_name,
        notes=[tuple(n) for n in notes],
        warnings=list(warnings),
        unsolved=list(unsolved),
    )
