"""The package's build backend: maturin's (PEP 517), with the photo stages
(init, track, run) only when the system OpenCV is there.

`pip install ./python` calls it. It asks pkg-config for OpenCV 4 (what the
opencv crate itself probes) and, when it is missing, builds the package
without its `opencv` feature and says so, instead of failing in the opencv
crate's build script: `import bulge` then warns that the photo stages are
missing. Arguments given through MATURIN_PEP517_ARGS or config settings are
kept.
"""

import os
import shutil
import subprocess
import sys

import maturin
from maturin import (  # noqa: F401  (the hooks this backend passes through)
    build_sdist,
    get_requires_for_build_editable,
    get_requires_for_build_sdist,
    get_requires_for_build_wheel,
)


def _has_opencv() -> bool:
    pkg_config = shutil.which("pkg-config")
    if pkg_config is None:
        return False
    return subprocess.run([pkg_config, "--exists", "opencv4"]).returncode == 0


def _without_opencv_if_missing() -> None:
    args = os.environ.get("MATURIN_PEP517_ARGS", "")
    if "--no-default-features" in args or _has_opencv():
        return
    print(
        "bulge: no system OpenCV (pkg-config finds no opencv4): building without the photo "
        "stages (init, track, run); install it (apt-get install libopencv-dev clang "
        "libclang-dev) and reinstall to have them",
        file=sys.stderr,
    )
    os.environ["MATURIN_PEP517_ARGS"] = f"{args} --no-default-features".strip()


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    _without_opencv_if_missing()
    return maturin.build_wheel(wheel_directory, config_settings, metadata_directory)


def build_editable(wheel_directory, config_settings=None, metadata_directory=None):
    _without_opencv_if_missing()
    return maturin.build_editable(wheel_directory, config_settings, metadata_directory)


def prepare_metadata_for_build_wheel(metadata_directory, config_settings=None):
    _without_opencv_if_missing()
    return maturin.prepare_metadata_for_build_wheel(metadata_directory, config_settings)


def prepare_metadata_for_build_editable(metadata_directory, config_settings=None):
    _without_opencv_if_missing()
    return maturin.prepare_metadata_for_build_editable(metadata_directory, config_settings)
