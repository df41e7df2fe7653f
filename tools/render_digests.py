"""Render fixed scenes with fixed seeds and compare the images bit for bit.

A refactoring must not change what the renderer computes.  This script renders
a few scenes of ``blend_scenes/`` through the public command line (so it works
whatever the module layout) and either records the SHA-256 of each image's
pixels or checks them against a record made earlier::

    python -m tools.render_digests --record out/digests.json     # before the change
    python -m tools.render_digests --check out/digests.json      # after it

``--check`` exits 0 when every image is bit-identical, 1 otherwise, and prints
the largest relative difference of each image that changed (the EXR files of
the recording run are kept next to the record for that).
"""
from __future__ import annotations

import argparse
import hashlib
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SCENES = ("cornell_box", "glass_mirror", "light_spot_shapes", "light_area_spread", "transforms")
RENDER_ARGS = ("--samples", "16", "--resolution", "64x64", "--seed", "3", "--threads", "2")


def _read_exr(path: Path) -> np.ndarray:
    from mcengine.imageio import read_exr
    return read_exr(path)


def render(scene: str, out: Path) -> Path:
    target = out / f"{scene}.exr"
    command = [str(Path(sys.executable).parent / "mcengine"), "render",
               str(REPO / "blend_scenes" / f"{scene}.blend"), *RENDER_ARGS, "-o", str(target)]
    done = subprocess.run(command, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"rendering {scene} failed:\n{done.stderr}")
    return target


def digest(image: np.ndarray) -> str:
    return hashlib.sha256(np.ascontiguousarray(image, np.float32).tobytes()).hexdigest()


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    mode = parser.add_mutually_exclusive_group(required=True)
    mode.add_argument("--record", type=Path, help="write the digests to this JSON file")
    mode.add_argument("--check", type=Path, help="compare with the digests in this JSON file")
    args = parser.parse_args(argv)
    record = args.record or args.check
    images = record.parent / (record.stem + ("_images" if args.record else "_check"))
    images.mkdir(parents=True, exist_ok=True)
    digests = {}
    for scene in SCENES:
        digests[scene] = digest(_read_exr(render(scene, images)))
        print(f"{scene}: {digests[scene][:16]}")
    if args.record:
        record.write_text(json.dumps({"args": RENDER_ARGS, "digests": digests}, indent=1))
        return 0
    before = json.loads(record.read_text())["digests"]
    same = True
    for scene, d in digests.items():
        if d == before[scene]:
            print(f"{scene}: identical")
            continue
        same = False
        old = _read_exr(record.parent / (record.stem + "_images") / f"{scene}.exr")
        new = _read_exr(images / f"{scene}.exr")
        rel = np.abs(new - old) / np.maximum(np.abs(old), 1e-12)
        print(f"{scene}: DIFFERENT, largest relative difference {rel.max():.3g}")
    return 0 if same else 1


if __name__ == "__main__":
    sys.exit(main())
