"""Build the MC Engine add-on as a Blender 5.0 extension zip.

Usage, from the repository root with the project's environment (or through
``python3.11 tasks.py extension``, which sets it up)::

    python -m tools.build_extension [--out DIR] [--wheel-cache DIR]

writes ``DIR/mcengine-<version>.zip`` (default ``dist/extension/``) and prints
its path.  Install it in Blender 5.0 with Preferences > Get Extensions >
Install from Disk, or ``blender --command extension install-file -r user_default -e ZIP``.

What goes in the zip
--------------------
* the add-on package: the files of ``addon/`` at the zip root, with
  ``blender_manifest.toml`` (its ``[build]`` excludes drop caches and the
  command-line module, which only runs outside Blender);
* ``wheels/``: exactly the wheels the manifest lists.  Third-party wheels are
  downloaded unmodified from PyPI with ``pip download --no-deps --only-binary``
  for CPython 3.11 on manylinux_2_28 x86-64 (what Blender 5.0 runs), and the
  build fails if PyPI does not serve the exact file named in the manifest;
* the renderer core as its own pure-Python wheel ``mcengine-<version>-py3-none-any``
  built here from ``mcengine/``.  Blender unpacks extension wheels into its
  extensions ``site-packages``, which it puts on ``sys.path``, so the core stays
  the top-level package ``mcengine`` exactly as under pip: the add-on imports it
  with the same absolute import in both settings, nothing edits ``sys.path``,
  and Blender removes it with the extension.  Vendoring it inside the add-on
  would instead make it ``bl_ext.<repo>.mcengine.mcengine``.

The zip itself is made and then checked by Blender's own extension tool
(``blender_ext.py build`` and ``validate``, shipped inside the bpy module: the
code behind ``blender --command extension build/validate``).
"""
from __future__ import annotations

import argparse
import ast
import base64
import csv
import hashlib
import importlib.util
import io
import shutil
import subprocess
import sys
import tempfile
import tomllib
import zipfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ADDON_DIR = REPO / "addon"
CORE_DIR = REPO / "mcengine"
MANIFEST_NAME = "blender_manifest.toml"
DEFAULT_OUT = REPO / "dist" / "extension"
DEFAULT_WHEEL_CACHE = REPO / "build" / "wheels"

CORE_DISTRIBUTION = "mcengine"
# Blender 5.0 for Linux x86-64 runs CPython 3.11 on glibc 2.28 (manylinux_2_28), which also
# runs wheels built for older glibc (manylinux2014 = manylinux_2_17: cffi, pyoidn).
PIP_TARGET = ["--python-version", "3.11", "--implementation", "cp", "--abi", "cp311",
              "--platform", "manylinux_2_28_x86_64", "--platform", "manylinux2014_x86_64"]
# Wheels are zip files; a fixed timestamp makes the core wheel byte-for-byte reproducible.
ZIP_EPOCH = (1980, 1, 1, 0, 0, 0)
SKIPPED_DIRS = {"__pycache__"}
SKIPPED_SUFFIXES = {".pyc", ".pyo"}


class BuildError(Exception):
    """A build failure, reported as one line."""


def read_manifest(addon_dir: Path = ADDON_DIR) -> dict:
    """The parsed ``blender_manifest.toml`` of the add-on."""
    with open(addon_dir / MANIFEST_NAME, "rb") as handle:
        return tomllib.load(handle)


def core_version(core_dir: Path = CORE_DIR) -> str:
    """``__version__`` of the core package, read without importing it."""
    tree = ast.parse((core_dir / "__init__.py").read_text(encoding="utf-8"))
    for node in tree.body:
        if isinstance(node, ast.Assign) and any(
                isinstance(target, ast.Name) and target.id == "__version__" for target in node.targets):
            return ast.literal_eval(node.value)
    raise BuildError(f"no __version__ in {core_dir / '__init__.py'}")


def wheel_name_version(filename: str) -> tuple[str, str]:
    """Distribution name and version from a wheel file name (PEP 427)."""
    parts = filename[:-len(".whl")].split("-")
    if not filename.endswith(".whl") or len(parts) not in (5, 6):
        raise BuildError(f"not a wheel file name: {filename}")
    return parts[0], parts[1]


def fetch_wheel(filename: str, cache: Path) -> Path:
    """Download the PyPI wheel ``filename`` into ``cache`` (kept between builds)."""
    cached = cache / filename
    if cached.is_file():
        return cached
    name, version = wheel_name_version(filename)
    cache.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(dir=cache) as download_dir:
        command = [sys.executable, "-m", "pip", "download", "--quiet", "--no-deps",
                   "--only-binary=:all:", *PIP_TARGET, "--dest", download_dir, f"{name}=={version}"]
        done = subprocess.run(command, capture_output=True, text=True)
        if done.returncode != 0:
            last = (done.stderr.strip().splitlines() or ["pip failed"])[-1]
            raise BuildError(f"cannot download {name}=={version}: {last}")
        got = sorted(path.name for path in Path(download_dir).glob("*.whl"))
        if got != [filename]:
            raise BuildError(f"PyPI served {got} for {name}=={version}, but the manifest lists "
                             f"{filename}; update {MANIFEST_NAME}")
        shutil.move(Path(download_dir) / filename, cached)
    return cached


def _record_hash(data: bytes) -> str:
    digest = base64.urlsafe_b64encode(hashlib.sha256(data).digest()).rstrip(b"=")
    return "sha256=" + digest.decode("ascii")


def _package_files(package_dir: Path) -> list[Path]:
    """Files of a package tree, sorted, without bytecode caches."""
    return sorted(
        path for path in package_dir.rglob("*")
        if path.is_file() and path.suffix not in SKIPPED_SUFFIXES
        and not SKIPPED_DIRS.intersection(path.relative_to(package_dir).parts))


def build_core_wheel(dest: Path, version: str, core_dir: Path = CORE_DIR) -> Path:
    """Write ``mcengine-<version>-py3-none-any.whl`` holding only the core package.

    Returns
    -------
    Path of the wheel in ``dest``.
    """
    dist_info = f"{CORE_DISTRIBUTION}-{version}.dist-info"
    metadata = "\n".join([
        "Metadata-Version: 2.1",
        f"Name: {CORE_DISTRIBUTION}",
        f"Version: {version}",
        "Summary: mcengine renderer core (bundled by the MC Engine Blender extension)",
        "License: GPL-3.0-or-later",
        "Requires-Python: ==3.11.*",
        "Requires-Dist: numpy>=1.26,<2.0",
        "Requires-Dist: embreex>=4.4",
        "Requires-Dist: numba>=0.60",
        "Requires-Dist: OpenEXR>=3.3",
        "Requires-Dist: pyoidn>=2.5",
        "", ""])
    wheel_info = "\n".join([
        "Wheel-Version: 1.0",
        "Generator: mcengine tools.build_extension",
        "Root-Is-Purelib: true",
        "Tag: py3-none-any",
        "", ""])
    entries = [(f"{core_dir.name}/{path.relative_to(core_dir).as_posix()}", path.read_bytes())
               for path in _package_files(core_dir)]
    entries += [(f"{dist_info}/METADATA", metadata.encode()), (f"{dist_info}/WHEEL", wheel_info.encode())]
    record = io.StringIO()
    writer = csv.writer(record, lineterminator="\n")
    for arcname, data in entries:
        writer.writerow([arcname, _record_hash(data), len(data)])
    writer.writerow([f"{dist_info}/RECORD", "", ""])
    entries.append((f"{dist_info}/RECORD", record.getvalue().encode()))

    wheel = dest / f"{CORE_DISTRIBUTION}-{version}-py3-none-any.whl"
    with zipfile.ZipFile(wheel, "w", zipfile.ZIP_DEFLATED) as archive:
        for arcname, data in entries:
            info = zipfile.ZipInfo(arcname, ZIP_EPOCH)
            info.compress_type = zipfile.ZIP_DEFLATED
            info.external_attr = 0o644 << 16
            archive.writestr(info, data)
    return wheel


def blender_ext_script() -> Path:
    """Blender's extension command-line tool inside the installed bpy module."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise BuildError("the bpy module (Blender 5.0) is not installed in this Python")
    for location in spec.submodule_search_locations:
        found = sorted(Path(location).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
        if found:
            return found[-1]
    raise BuildError("Blender's extension tool (bl_pkg/cli/blender_ext.py) is missing from bpy")


def _run_blender_ext(*args: str) -> str:
    done = subprocess.run([sys.executable, str(blender_ext_script()), *args],
                          capture_output=True, text=True)
    output = (done.stdout + done.stderr).strip()
    if done.returncode != 0:
        raise BuildError(f"blender_ext {args[0]} failed: {' '.join(output.splitlines()[-3:])}")
    return output


def build(out_dir: Path = DEFAULT_OUT, wheel_cache: Path = DEFAULT_WHEEL_CACHE,
          addon_dir: Path = ADDON_DIR, core_dir: Path = CORE_DIR) -> Path:
    """Assemble, zip and validate the extension; returns the zip's path."""
    manifest = read_manifest(addon_dir)
    version = core_version(core_dir)
    if manifest.get("version") != version:
        raise BuildError(f"{MANIFEST_NAME} has version {manifest.get('version')!r} but "
                         f"mcengine.__version__ is {version!r}; make them equal")
    wheel_paths = manifest.get("wheels", [])
    core_wheel_name = f"{CORE_DISTRIBUTION}-{version}-py3-none-any.whl"
    if f"./wheels/{core_wheel_name}" not in wheel_paths:
        raise BuildError(f"{MANIFEST_NAME} must list ./wheels/{core_wheel_name}")

    out_dir.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        staging = Path(tmp) / manifest["id"]
        shutil.copytree(addon_dir, staging, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        wheels_dir = staging / "wheels"
        wheels_dir.mkdir(exist_ok=True)
        for wheel_path in wheel_paths:
            filename = Path(wheel_path).name
            if filename == core_wheel_name:
                build_core_wheel(wheels_dir, version, core_dir)
            else:
                shutil.copy2(fetch_wheel(filename, wheel_cache), wheels_dir / filename)
        zip_path = out_dir / f"{manifest['id']}-{version}.zip"
        zip_path.unlink(missing_ok=True)
        _run_blender_ext("build", "--source-dir", str(staging), "--output-filepath", str(zip_path))
    _run_blender_ext("validate", str(zip_path))
    return zip_path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m tools.build_extension", description=__doc__.split("\n")[0])
    parser.add_argument("--out", type=Path, default=DEFAULT_OUT,
                        help=f"output folder (default: {DEFAULT_OUT.relative_to(REPO)})")
    parser.add_argument("--wheel-cache", type=Path, default=DEFAULT_WHEEL_CACHE,
                        help=f"where downloaded wheels are kept (default: {DEFAULT_WHEEL_CACHE.relative_to(REPO)})")
    args = parser.parse_args(argv)
    try:
        zip_path = build(args.out.absolute(), args.wheel_cache.absolute())
    except (BuildError, OSError, tomllib.TOMLDecodeError) as exc:
        print(f"build_extension: error: {exc}", file=sys.stderr)
        return 1
    print(zip_path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
