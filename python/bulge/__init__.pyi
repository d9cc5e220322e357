"""Typed stubs of the bulge package (see bulge/__init__.py)."""

from os import PathLike
from typing import Dict, List, Optional, Tuple, Union

import pandas as pd

__version__: str
HAS_OPENCV: bool

class BadInput(ValueError):
    """The input was refused (the command line's exit status 2)."""

class Failure(RuntimeError):
    """The work failed (the command line's exit status 1)."""

class RunOutput:
    heights: pd.DataFrame
    stress_strain: pd.DataFrame
    material: dict
    simulated: pd.DataFrame
    laws: Optional[pd.DataFrame]
    stress_strain_sources: Optional[pd.DataFrame]
    files: Dict[str, bytes]
    notes: List[Tuple[str, str]]
    warnings: List[str]
    unsolved: List[float]

def run(experiment: Union[str, PathLike[str]]) -> RunOutput: ...
