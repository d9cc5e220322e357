"""Typed stubs of the bulge package (see bulge/__init__.py)."""

from os import PathLike
from typing import Callable, Dict, List, Optional, Sequence, Tuple, Union

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

def run(
    experiment: Union[str, PathLike[str]],
    *,
    progress: Optional[Callable[[str, int, int], object]] = None,
    **settings: object,
) -> RunOutput: ...

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

class SimulateOutput:
    simulated: pd.DataFrame
    profile: Optional[pd.DataFrame]
    trace: Optional[pd.DataFrame]
    notes: List[str]
    warnings: List[str]
    failures: List[str]

def simulate(
    material: Union[dict, FitOutput, _Path, None] = None,
    experiment: Optional[_Path] = None,
    *,
    scene: Optional[_Path] = None,
    pressures: Optional[Sequence[float]] = None,
    model: Union[str, Sequence[str]] = "tp",
    solver: Union[str, Sequence[str]] = "newton",
    tolerance: float = 1e-8,
    max_iterations: Optional[int] = None,
    edge_length: Optional[float] = None,
    nodes: Optional[int] = None,
    accuracy: Optional[float] = None,
    max_nodes: Optional[int] = None,
    full: bool = False,
    profile: bool = False,
    density: Optional[float] = None,
    progress: Optional[Callable[[int, int], object]] = None,
    dynamic: bool = False,
    integrator: Union[str, Sequence[str]] = "verlet",
    dt: Optional[float] = None,
    t_end: Optional[float] = None,
    damping: float = 0.1,
    damping_law: str = "critical",
    step_policy: str = "substep",
    xpbd_iterations: int = 20,
) -> SimulateOutput: ...

class InitOutput:
    experiment: dict
    experiment_toml: str
    picture: bytes
    summary: str
    notes: List[str]

def init(
    source: _Path,
    radius_m: float,
    thickness_m: float,
    poisson: float = 0.45,
    *,
    base: Optional[_Path] = None,
    every: Optional[int] = None,
    pressure: Optional[_Path] = None,
    glob: Optional[str] = None,
    metres_per_pixel: Optional[float] = None,
    points_px: Optional[Sequence[float]] = None,
    distance_m: Optional[float] = None,
    elevation_deg: Optional[float] = None,
    camera_distance_m: Optional[float] = None,
    orthographic: bool = False,
    response: str = "srgb",
    camera: Optional[_Path] = None,
    clamp_row_px: Optional[float] = None,
    clamp_row_std_px: float = 0.0,
) -> InitOutput: ...

class StudyOutput:
    study: pd.DataFrame
    files: Dict[str, bytes]
    summary: str
    log: List[str]
    failed: List[Tuple[str, str]]

def study(
    inputs: Union[_Path, Sequence[_Path]],
    out: _Path,
    *,
    redo: bool = False,
    progress: Optional[Callable[[int, int], object]] = None,
    **settings: object,
) -> StudyOutput: ...
