"""Typed stubs of the bulge package (see bulge/__init__.py)."""

from os import PathLike
from typing import Callable, Dict, List, Optional, Tuple, Union

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

_Table = Union[pd.DataFrame, str, PathLike[str]]
_Path = Union[str, PathLike[str]]

class StressOutput:
    stress_strain: pd.DataFrame
    sources: Optional[pd.DataFrame]
    warnings: List[str]

def stress(
    heights: _Table,
    experiment: Optional[_Path] = None,
    *,
    radius_m: Optional[float] = None,
    thickness_m: Optional[float] = None,
    poisson: Optional[float] = None,
    prebulge_height_m: Optional[float] = None,
    strain: str = "engineering",
    true_stress: str = "paper",
    modulus: str = "biaxial",
    modulus_stress: str = "nominal",
    height_std_m: Optional[float] = None,
) -> StressOutput: ...

class FitOutput:
    material: dict
    material_toml: str
    curve: pd.DataFrame
    residuals: pd.DataFrame
    models: Optional[pd.DataFrame]
    files: Dict[str, bytes]
    summary: str
    warnings: List[str]

def fit(
    stress_strain: _Table,
    *,
    model: str = "quartic",
    degree: int = 4,
    ogden_terms: int = 3,
    poisson: float = 0.45,
    modulus: str = "biaxial",
    weighted: bool = False,
    samples: int = 200,
    stress_measure: Optional[str] = None,
    strain_measure: Optional[str] = None,
    to_heights: Optional[_Path] = None,
    plot: bool = True,
) -> FitOutput: ...

class TrackOutput:
    heights: pd.DataFrame
    skipped: List[Tuple[int, str, float, str]]
    warnings: List[str]
    note: Optional[str]

def track(
    experiment: _Path,
    *,
    min_score: float = 0.5,
    skip_bad_frames: bool = False,
    refine: str = "edge",
    search_margin_px: int = 8,
    edge_span_px: Optional[int] = None,
    edge_window_px: int = 3,
    progress: Optional[Callable[[int, int], object]] = None,
) -> TrackOutput: ...
