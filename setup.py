"""Package discovery for mcengine (metadata lives in pyproject.toml).

The folder ``addon/`` is installed as the package ``mcengine_blender``, with
its subpackages renamed to match (``addon/export`` -> ``mcengine_blender.export``).
setuptools' declarative ``packages.find`` cannot rename a folder, so the list is
computed here; new subpackages are picked up without editing any config.
"""
from setuptools import find_packages, setup

ADDON_PACKAGE = "mcengine_blender"
ADDON_FOLDER = "addon"

setup(
    packages=(
        find_packages(include=["mcengine", "mcengine.*"])
        + [ADDON_PACKAGE]
        + [f"{ADDON_PACKAGE}.{name}" for name in find_packages(ADDON_FOLDER)]
    ),
    package_dir={ADDON_PACKAGE: ADDON_FOLDER},
    # The closures' tables (energy compensation, albedo estimates, sheen) are data the
    # kernels freeze into their compiled code; wheels and the extension must carry them.
    package_data={"mcengine.kernels.closures": ["data/*.npy"]},
)
