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
import os
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

__all__ = [
    "BadInput",
    "Failure",
    "FitOutput",
    "InitOutput",
    "RunOutput",
    "SimulateOutput",
    "StressOutput",
    "StudyOutput",
    "TrackOutput",
    "fit",
    "init",
    "run",
    "simulate",
    "stress",
    "study",
    "track",
    "HAS_OPENCV",
    "__version__",
]

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


def _csv_in(table, name: str) -> "Tuple[bytes | None, str]":
    """A table given as a DataFrame or as a CSV file's path: the DataFrame's
    CSV bytes and the name messages use (``<name DataFrame>``, whose line
    ``n`` is row ``n - 2``: the header is line 1), or no bytes and the path,
    which the library reads as the command line does."""
    if isinstance(table, pd.DataFrame):
        return table.to_csv(index=False).encode(), f"<{name} DataFrame>"
    return None, os.fspath(table)


def _path(p):
    return None if p is None else os.fspath(p)


@dataclass
class StressOutput:
    """What ``bulge stress`` writes, in memory.

    ``stress_strain`` is stress_strain.csv (the input's other columns first,
    then ``pressure_pa,height_m,radius_m,...,secant_modulus_pa`` and the
    ``*_std`` columns when the heights have standard deviations);
    ``sources`` how every point moves for each input's stated error (when
    the experiment states errors besides the heights'); ``warnings`` what
    the command line prints as warnings.
    """

    stress_strain: pd.DataFrame
    sources: "pd.DataFrame | None" = None
    warnings: List[str] = field(default_factory=list)


def stress(
    heights,
    experiment=None,
    *,
    radius_m: "float | None" = None,
    thickness_m: "float | None" = None,
    poisson: "float | None" = None,
    prebulge_height_m: "float | None" = None,
    strain: str = "engineering",
    true_stress: str = "paper",
    modulus: str = "biaxial",
    modulus_stress: str = "nominal",
    height_std_m: "float | None" = None,
) -> StressOutput:
    """Heights -> stress and strain with the spherical-cap formulas, as
    ``bulge stress``: ``heights`` a DataFrame (or a CSV path) with
    ``pressure_pa`` and ``height_m`` (``height_std_m`` optional), the
    specimen from ``experiment`` (a TOML path) or from ``radius_m``,
    ``thickness_m``, ``poisson`` and ``prebulge_height_m``. The choices
    take the command line's names (``strain="log"``, ``modulus="uniaxial"``)."""
    data, label = _csv_in(heights, "heights")
    csv, sources, warnings = _native.stress(
        data,
        label,
        _path(experiment),
        radius_m,
        thickness_m,
        poisson,
        prebulge_height_m,
        strain,
        true_stress,
        modulus,
        modulus_stress,
        height_std_m,
    )
    return StressOutput(
        stress_strain=_table(bytes(csv)),
        sources=None if sources is None else _table(bytes(sources)),
        warnings=list(warnings),
    )


@dataclass
class FitOutput:
    """What ``bulge fit`` writes, in memory.

    ``material`` is material.toml as a dict (``material_toml`` its text,
    which ``bulge simulate --material`` reads); ``curve`` the fitted law on
    a grid, ``residuals`` data, law and residual at every point, ``models``
    the comparison of every law (``model="all"``); ``files`` every file by
    the command line's name for ``-o material.toml`` (the figure as SVG and
    PNG included unless ``plot=False``); ``summary`` what it prints;
    ``warnings`` its warnings.
    """

    material: dict
    material_toml: str
    curve: pd.DataFrame
    residuals: pd.DataFrame
    models: "pd.DataFrame | None" = None
    files: Dict[str, bytes] = field(default_factory=dict)
    summary: str = ""
    warnings: List[str] = field(default_factory=list)


def fit(
    stress_strain,
    *,
    model: str = "quartic",
    degree: int = 4,
    ogden_terms: int = 3,
    poisson: float = 0.45,
    modulus: str = "biaxial",
    weighted: bool = False,
    samples: int = 200,
    stress_measure: "str | None" = None,
    strain_measure: "str | None" = None,
    to_heights=None,
    plot: bool = True,
) -> FitOutput:
    """Stress/strain -> a material law with its uncertainty, as ``bulge
    fit``: ``stress_strain`` a DataFrame (or a CSV path) as ``stress``
    returns it (or raw ``strain`` and ``stress_pa`` columns); ``model`` one
    of the command line's (``quartic``, ``polynomial``, ``neo-hookean``,
    ``mooney-rivlin``, ``yeoh``, ``ogden``, ``gent``, ``all``);
    ``to_heights`` an experiment file on whose specimen the law is
    corrected to the table's heights (with their covariance). The GIL is
    released while it works."""
    data, label = _csv_in(stress_strain, "stress_strain")
    material, curve, residuals, models, figure, summary, warnings = _native.fit(
        data,
        label,
        model,
        degree,
        ogden_terms,
        poisson,
        modulus,
        weighted,
        samples,
        stress_measure,
        strain_measure,
        _path(to_heights),
        plot,
    )
    files = {
        "material.toml": material.encode(),
        "material_curve.csv": bytes(curve),
        "material_residuals.csv": bytes(residuals),
    }
    if models is not None:
        files["material_models.csv"] = bytes(models)
    if figure is not None:
        files["material_fit.svg"] = bytes(figure[0])
        files["material_fit.png"] = bytes(figure[1])
    return FitOutput(
        material=_toml.loads(material),
        material_toml=material,
        curve=_table(bytes(curve)),
        residuals=_table(bytes(residuals)),
        models=None if models is None else _table(bytes(models)),
        files=files,
        summary=summary,
        warnings=list(warnings),
    )


@dataclass
class SimulateOutput:
    """What ``bulge simulate`` writes and says, in memory.

    ``simulated`` is simulated.csv (``pressure_pa,height_m,model,solver,
    nodes,iterations,residual,wall_s``, a sphere segment adds its radii; a
    dynamic run adds ``peak_m,static_height_m,overshoot,settling_time_s,
    dt_s,substeps,dt_limit_s``); ``profile`` the axisymmetric meridian at
    the last pressure solved (``profile=True``); ``trace`` a dynamic run's
    time histories (``t_s,value_m,kinetic_j,pressure_pa,model,integrator``,
    as ``--trace`` writes them); ``notes`` the mesh used; ``warnings`` its warnings;
    ``failures`` each pressure without an equilibrium, with its model and
    solver (the command line then exits with status 1 after writing the
    rows solved, which are here too).
    """

    simulated: pd.DataFrame
    profile: "pd.DataFrame | None" = None
    trace: "pd.DataFrame | None" = None
    notes: List[str] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)
    failures: List[str] = field(default_factory=list)


def _names(v) -> List[str]:
    """``"tp,axisym"`` or ``["tp", "axisym"]`` as a list of names."""
    if isinstance(v, str):
        return [x.strip() for x in v.split(",") if x.strip()]
    return [str(x) for x in v]


def simulate(
    material=None,
    experiment=None,
    *,
    scene=None,
    pressures=None,
    model="tp",
    solver="newton",
    tolerance: float = 1e-8,
    max_iterations: "int | None" = None,
    edge_length: "float | None" = None,
    nodes: "int | None" = None,
    accuracy: "float | None" = None,
    max_nodes: "int | None" = None,
    full: bool = False,
    profile: bool = False,
    density: "float | None" = None,
    progress=None,
    dynamic: bool = False,
    integrator="verlet",
    dt: "float | None" = None,
    t_end: "float | None" = None,
    damping: float = 0.1,
    damping_law: str = "critical",
    step_policy: str = "substep",
    xpbd_iterations: int = 20,
) -> SimulateOutput:
    """A material on a membrane -> simulated apex heights, as ``bulge
    simulate`` (quasi-static): ``material`` a dict as material.toml reads
    (``bulge.fit(...).material``), a ``FitOutput`` or a material.toml path;
    the membrane the specimen of ``experiment`` (a TOML path) at
    ``pressures`` (Pa), or the scene file ``scene``; ``model`` one name or
    several (``"tp,axisym"`` or a list: tp, tp-paper, van-gelder, lloyd,
    membrane, axisym), ``solver`` newton or dr; the mesh by
    ``edge_length``, ``nodes`` or ``accuracy`` (the relative height error
    wanted). ``dynamic=True`` integrates in time instead (``bulge simulate
    --dynamic``, docs/dynamics.md): each pressure applied as a step at t = 0
    on the membrane at rest, with ``integrator`` (one or several of
    explicit-euler, symplectic-euler, verlet, implicit-euler, xpbd), ``dt``,
    ``t_end`` (required), ``damping``, ``damping_law``, ``step_policy``,
    ``xpbd_iterations``. ``progress(done, total)`` is called once per model
    and pressure (and integrator); the GIL is released while it works."""
    if isinstance(material, FitOutput):
        material = material.material
    table = material if isinstance(material, dict) else None
    path = None if material is None or table is not None else os.fspath(material)
    csv, prof, notes, warnings, failures = _native.simulate(
        path,
        table,
        _path(experiment),
        _path(scene),
        None if pressures is None else [float(p) for p in pressures],
        _names(model),
        _names(solver),
        tolerance,
        max_iterations,
        edge_length,
        nodes,
        accuracy,
        max_nodes,
        full,
        profile,
        density,
        progress,
        None
        if not dynamic
        else {
            "integrators": _names(integrator),
            "dt": dt,
            "t_end": t_end,
            "damping": float(damping),
            "damping_law": damping_law,
            "step_policy": step_policy,
            "xpbd_iterations": int(xpbd_iterations),
        },
    )
    second = None if prof is None else _table(bytes(prof))
    return SimulateOutput(
        simulated=_table(bytes(csv)),
        profile=None if dynamic else second,
        trace=second if dynamic else None,
        notes=list(notes),
        warnings=list(warnings),
        failures=list(failures),
    )


@dataclass
class InitOutput:
    """What ``bulge init`` writes and says, in memory.

    ``experiment`` is the experiment file as a dict, ``experiment_toml`` its
    text (its paths relative to ``base``: write it there, e.g.
    ``pathlib.Path(base, "experiment.toml").write_text(out.experiment_toml)``);
    ``picture`` init.png, what was found drawn on the last frame; ``summary``
    the line the command line prints; ``notes`` its notes.
    """

    experiment: dict
    experiment_toml: str
    picture: bytes
    summary: str
    notes: List[str] = field(default_factory=list)


def init(
    source,
    radius_m: float,
    thickness_m: float,
    poisson: float = 0.45,
    *,
    base=None,
    every: "int | None" = None,
    pressure=None,
    glob: "str | None" = None,
    metres_per_pixel: "float | None" = None,
    points_px=None,
    distance_m: "float | None" = None,
    elevation_deg: "float | None" = None,
    camera_distance_m: "float | None" = None,
    orthographic: bool = False,
    response: str = "srgb",
    camera=None,
    clamp_row_px: "float | None" = None,
    clamp_row_std_px: float = 0.0,
) -> InitOutput:
    """The experiment file from the photos alone, as ``bulge init``:
    ``source`` a folder of photos or a video, the opening's radius and the
    membrane's thickness (m); the clamp plane, the axis, the scale, the
    template and the region are found in the photos. ``base`` is the folder
    the experiment file is for (default: the current folder): its paths are
    written relative to it. The other keywords are the command line's flags
    (``camera_distance_m`` for a camera above the clamp plane, ``camera`` a
    ``bulge calibrate`` file, ``pressure`` the pressure file,
    ``clamp_row_px`` the clamp plane's row when init does not find it)."""
    _need_opencv("init")
    toml, picture, summary, notes = _native.init(
        os.fspath(source),
        radius_m,
        thickness_m,
        poisson,
        _path(base),
        every,
        _path(pressure),
        glob,
        metres_per_pixel,
        None if points_px is None else [float(x) for x in points_px],
        distance_m,
        elevation_deg,
        camera_distance_m,
        orthographic,
        response,
        _path(camera),
        clamp_row_px,
        clamp_row_std_px,
    )
    return InitOutput(
        experiment=_toml.loads(toml),
        experiment_toml=toml,
        picture=bytes(picture),
        summary=summary,
        notes=list(notes),
    )


@dataclass
class TrackOutput:
    """What ``bulge track`` writes and says, in memory.

    ``heights`` is heights.csv (``frame,file,pressure_pa,apex_x_px,
    apex_y_px,score,height_m,height_std_m``, ``time_s`` when the frames'
    times are known); ``skipped`` the frames left out as (frame, file,
    score, reason); ``warnings`` its warnings; ``note`` the note on an
    uncalibrated lens, if any.
    """

    heights: pd.DataFrame
    skipped: List[Tuple[int, str, float, str]] = field(default_factory=list)
    warnings: List[str] = field(default_factory=list)
    note: "str | None" = None


def track(
    experiment,
    *,
    min_score: float = 0.5,
    skip_bad_frames: bool = False,
    refine: str = "edge",
    search_margin_px: int = 8,
    edge_span_px: "int | None" = None,
    edge_window_px: int = 3,
    progress=None,
) -> TrackOutput:
    """An experiment file's photos (or video) -> apex height per photo, as
    ``bulge track`` with the same keywords as its flags. ``progress``, when
    given, is called as ``progress(done, total)`` after each frame (e.g. a
    tqdm bar's ``update``); the GIL is released between the calls."""
    _need_opencv("track")
    csv, warnings, skipped, note = _native.track(
        os.fspath(experiment),
        min_score,
        skip_bad_frames,
        refine,
        search_margin_px,
        edge_span_px,
        edge_window_px,
        progress,
    )
    return TrackOutput(
        heights=_table(bytes(csv)),
        skipped=[tuple(s) for s in skipped],
        warnings=list(warnings),
        note=note,
    )


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


def run(experiment, *, progress=None, **settings) -> RunOutput:
    """The whole pipeline on an experiment file, as ``bulge run`` (the GIL is
    released while it works). ``settings`` are keys of the ``[run]`` table
    (``fit="mooney-rivlin"``, ``models=["tp"]``, ``pressures_pa=[...]``,
    ``accuracy=0.005``; docs/run.md lists them): like the command line's
    flags they win over the file's own ``[run]`` and ``[simulate]`` tables,
    which give the rest. ``progress(stage, done, total)``, when given, is
    called as each stage (track, stress, fit, simulate) starts and steps."""
    _need_opencv("run")
    files, notes, warnings, unsolved = _native.run(os.fspath(experiment), settings or None, progress)
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


@dataclass
class StudyOutput:
    """What ``bulge study`` writes into its folder and says.

    ``study`` is study.csv (one row per specimen, then mean, std, cv,
    ci95_low, ci95_high, pooled, joint); ``files`` the study's files by name
    (study.csv, the figures, study.html: each specimen's run is in the
    folder's ``specimens/<name>/``); ``summary`` the table the command line
    prints; ``log`` its lines (reused, done, failed); ``failed`` the
    specimens left out, with why (the command line then exits with status 1
    after writing the study of the others).
    """

    study: pd.DataFrame
    files: Dict[str, bytes] = field(default_factory=dict)
    summary: str = ""
    log: List[str] = field(default_factory=list)
    failed: List[Tuple[str, str]] = field(default_factory=list)


def study(inputs, out, *, redo: bool = False, progress=None, **settings) -> StudyOutput:
    """One material across several specimens, as ``bulge study``: ``inputs``
    a study file or a list of two or more experiment files, ``out`` the
    folder it writes (each specimen's run under ``specimens/<name>/``; a
    specimen whose inputs and settings did not change since the last study
    into it is read back, unless ``redo``). ``settings`` are keys of the
    ``[run]`` table shared by every specimen (``fit="mooney-rivlin"``);
    ``progress(done, total)`` is called as each specimen ends."""
    _need_opencv("study")
    if isinstance(inputs, (str, os.PathLike)):
        inputs = [inputs]
    files, summary, log, failed = _native.study(
        [os.fspath(p) for p in inputs], os.fspath(out), redo, settings or None, progress
    )
    by_name = {name: bytes(data) for name, data in files}
    return StudyOutput(
        study=_table(by_name["study.csv"]),
        files=by_name,
        summary=summary,
        log=list(log),
        failed=[tuple(f) for f in failed],
    )
