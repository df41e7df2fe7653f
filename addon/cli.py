"""Command line: render a .blend file headless with MC Engine or Cycles, compare the two,
or study what accuracy costs in time.

Two spellings take the same options::

    mcengine render SCENE.blend [--engine mcengine|cycles] [--samples N] [--resolution WxH]
                                [--seed S] [--frame F] [-o OUT.exr|OUT.png ...] [-F FORMAT]
                                [--integrator path|raycast|whitted|distribution]
                                [--depth R] [--branching B]
    mcengine -b SCENE.blend -E MCENGINE -o /tmp/out_#### -F OPEN_EXR -f 1

The second one is Blender's own background-render syntax (``-b -E -o -f -F -S -t``
and their long forms), so ``blender -b`` scripts carry over unchanged.

``compare`` renders a scene with both engines and tests whether they agree
(see ``mcengine_blender.comparison`` and ``mcengine.report``)::

    mcengine compare SCENE.blend [--samples N] [--resolution WxH|P%] [--seeds K] [--out DIR]
    mcengine compare --suite FOLDER [same options]      # every .blend in FOLDER, one summary

``study`` renders a ladder of sample counts with each integrator (and Cycles)
and reports error against time (see ``mcengine_blender.study`` and
``mcengine.study``)::

    mcengine study SCENE.blend [--out DIR] [--max-samples N] [--integrators path,raycast,...]
                               [--with-cycles] [--seeds K] [--resolution WxH]
                               [--depth R] [--branching B] [--target RELMSE]

Conventions
-----------
* Every argument, the input file (its magic bytes) and the output folders are
  checked before ``bpy`` is imported, so bad input fails in well under a second.
* Failures are one line on stderr, ``mcengine: error: ...``, never a traceback.
  Exit status: 0 rendered, 1 the render (or file loading) failed, 2 bad input;
  ``compare`` exits 0 when the engines agree and 3 when they differ (1 and 2 as
  above; in a suite, any failed scene gives 1, else any difference 3).
* Output paths follow Blender: ``//`` is the .blend file's folder, the last run
  of ``#`` in the file name becomes the zero-padded frame number, and the
  format's extension is appended when the name has none.  ``-o`` may be given
  several times to save the same render in several formats.
* Overrides change this render only, never the file.  Samples go to
  ``scene.cycles.samples`` and the seed to ``scene.cycles.seed`` (MC Engine reads
  Cycles' sampling settings); ``--resolution`` sets x, y and 100 %.
* EXR output is OPEN_EXR, 32-bit float RGBA, scene-linear, with the file's EXR
  codec; PNG output is 8-bit RGBA through the file's view transform.
* Blender's own log is captured: shown with ``--verbose`` or when a render fails,
  otherwise only its ``Warning:`` lines are passed on.
* Progress goes to stderr: a bar redrawn in place on a terminal, one line per
  10 % otherwise.  It parses ``Sample N/M`` from the render statistics
  (``bpy.app.handlers.render_stats``), which Cycles reports and which a Python
  engine reports through ``RenderEngine.update_stats``; ``update_progress`` does
  not reach Python handlers in Blender 5.0.
* After an MC Engine render one line of ray accounting goes to stderr: rays
  per pixel by kind, Mrays/s and the time of each phase.
* The only thing written to stdout is the path of each saved image (``compare``:
  the path of each ``report.json``, or of ``summary.json`` for a suite;
  ``study``: the path of ``study.html``).
"""
from __future__ import annotations

import argparse
import contextlib
import ctypes
import gzip
import math
import os
import re
import sys
import tempfile
import time
import traceback
from dataclasses import dataclass
from pathlib import Path

PROG = "mcengine"

EXIT_OK = 0
EXIT_RENDER_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_DIFFER = 3
EXIT_INTERRUPTED = 130

# User-facing engine names -> RenderEngine bl_idname.
ENGINES = {"mcengine": "MCENGINE", "cycles": "CYCLES"}
DEFAULT_ENGINE = "MCENGINE"

# Blender image format -> file extension.  Only the two formats whose pixel
# meaning is unambiguous are offered: linear float EXR and display-referred PNG.
FORMATS = {"OPEN_EXR": ".exr", "PNG": ".png"}
DEFAULT_FORMAT = "OPEN_EXR"
# Extensions of other image formats: a name ending in one of these is a mistake,
# not a name to which ".exr" should be appended.
OTHER_IMAGE_EXTENSIONS = {".jpg", ".jpeg", ".tif", ".tiff", ".hdr", ".bmp", ".tga",
                          ".webp", ".jp2", ".dpx", ".cin", ".rgb", ".sgi", ".mp4", ".mkv"}

# Blender's hard limits (RNA ranges of RenderSettings, CyclesRenderSettings, Scene).
MIN_RESOLUTION, MAX_RESOLUTION = 4, 65536
MAX_SAMPLES = 16_777_216
MAX_SEED = 2_147_483_647
MAX_FRAME = 1_048_574
MAX_THREADS = 1024
# compare: renders per engine.  Two is the minimum that estimates the noise;
# more than this is never needed (the test pools every pixel's variance).
DEFAULT_SEEDS, MAX_SEEDS = 2, 64
MAX_PERCENTAGE = 1000
DEFAULT_ALPHA = 1e-3
# The comparison tests an 8x8 grid of blocks, so each side needs 8 pixels.
MIN_COMPARE_SIZE = 8
# MC Engine's integrators (scene.mcengine.integrator, lower case) and the
# ranges of its depth and branching properties (addon/properties.py).
INTEGRATORS = ("path", "raycast", "whitted", "distribution")
MAX_DEPTH = 16
MAX_BRANCHING = 64
# study: the ladder's largest sample count (25 rungs at most, see mcengine.study).
MAX_STUDY_SAMPLES = 1 << 24

# A .blend starts with "BLENDER"; Blender 3.0+ may zstd-compress the whole file,
# older versions gzip it.
BLEND_MAGIC = b"BLENDER"
ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"
GZIP_MAGIC = b"\x1f\x8b"

SAMPLE_STATS = re.compile(r"Sample (\d+)/(\d+)")
# Non-TTY progress prints one line each time this fraction is crossed.
PROGRESS_LINE_STEP = 0.1
PROGRESS_BAR_WIDTH = 30


class CliError(Exception):
    """An error reported as one line; ``exit_code`` is the process exit status."""

    def __init__(self, message: str, exit_code: int = EXIT_BAD_INPUT):
        super().__init__(message)
        self.exit_code = exit_code


# ---------------------------------------------------------------------------
# Argument parsing and validation (no bpy)
# ---------------------------------------------------------------------------

class _Parser(argparse.ArgumentParser):
    """argparse that raises instead of printing usage and exiting."""

    def error(self, message):
        raise CliError(message)


def _positive_int(text: str, what: str, maximum: int) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} must be a whole number, got {text!r}") from None
    if not 1 <= value <= maximum:
        raise argparse.ArgumentTypeError(f"{what} must be between 1 and {maximum}, got {value}")
    return value


def _samples(text: str) -> int:
    return _positive_int(text, "sample count", MAX_SAMPLES)


def _seed(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"seed must be a whole number, got {text!r}") from None
    if not 0 <= value <= MAX_SEED:
        raise argparse.ArgumentTypeError(f"seed must be between 0 and {MAX_SEED}, got {value}")
    return value


def _frame(text: str) -> int:
    if text[:1] in "+-" or not text.isdigit():
        raise argparse.ArgumentTypeError(
            f"frame must be one absolute frame number, got {text!r} "
            "(relative frames and ranges are not supported)")
    value = int(text)
    if value > MAX_FRAME:
        raise argparse.ArgumentTypeError(f"frame must be at most {MAX_FRAME}, got {value}")
    return value


def _threads(text: str) -> int:
    if text == "0":
        return 0
    return _positive_int(text, "thread count", MAX_THREADS)


def _resolution(text: str) -> tuple[int, int]:
    match = re.fullmatch(r"\s*(\d+)\s*[xX]\s*(\d+)\s*", text)
    if not match:
        raise argparse.ArgumentTypeError(f"resolution must look like 640x480, got {text!r}")
    width, height = int(match[1]), int(match[2])
    for size in (width, height):
        if not MIN_RESOLUTION <= size <= MAX_RESOLUTION:
            raise argparse.ArgumentTypeError(
                f"resolution {width}x{height} is outside Blender's range "
                f"{MIN_RESOLUTION}..{MAX_RESOLUTION} per side")
    return width, height


def _engine(text: str) -> str:
    idname = ENGINES.get(text.lower())
    if idname is None:
        raise argparse.ArgumentTypeError(
            f"unknown engine {text!r} (choose from {', '.join(ENGINES)})")
    return idname


def _integrator(text: str) -> str:
    name = text.lower()
    if name not in INTEGRATORS:
        raise argparse.ArgumentTypeError(
            f"unknown integrator {text!r} (choose from {', '.join(INTEGRATORS)})")
    return name


def _integrator_list(text: str) -> tuple[str, ...]:
    names = tuple(_integrator(part.strip()) for part in text.split(",") if part.strip())
    if not names:
        raise argparse.ArgumentTypeError("--integrators needs at least one name, e.g. path,raycast")
    if len(set(names)) != len(names):
        raise argparse.ArgumentTypeError(f"an integrator is listed twice in {text!r}")
    return names


def _depth(text: str) -> int:
    return _positive_int(text, "depth", MAX_DEPTH)


def _branching(text: str) -> int:
    return _positive_int(text, "branching", MAX_BRANCHING)


def _add_integrator_options(parser, for_study: bool = False) -> None:
    """--depth and --branching (and --integrator for a render)."""
    if not for_study:
        parser.add_argument("--integrator", type=_integrator, default=None,
                            help="MC Engine's algorithm: path (default), raycast, whitted or "
                                 "distribution (default: the file's setting)")
    parser.add_argument("--depth", type=_depth, default=None, metavar="R",
                        help=f"ray levels of whitted and distribution, 1..{MAX_DEPTH} "
                             "(the camera ray is level 1)")
    parser.add_argument("--branching", type=_branching, default=None, metavar="B",
                        help=f"rays per hit of distribution, 1..{MAX_BRANCHING}")


def _check_integrator_options(integrators, depth, branching, engine=None) -> None:
    """One-line errors for options that the chosen integrators would ignore."""
    if engine == "CYCLES" and (integrators or depth or branching):
        raise CliError("--integrator, --depth and --branching choose MC Engine's algorithm; "
                       "they do not apply to --engine cycles")
    if not integrators:
        return
    if depth is not None and not {"whitted", "distribution"} & set(integrators):
        raise CliError("--depth applies to the whitted and distribution integrators only")
    if branching is not None and "distribution" not in integrators:
        raise CliError("--branching applies to the distribution integrator only")


def _format(text: str) -> str:
    name = text.upper()
    if name not in FORMATS:
        raise argparse.ArgumentTypeError(
            f"unsupported format {text!r} (choose from {', '.join(FORMATS)})")
    return name


def build_parser() -> argparse.ArgumentParser:
    """The ``mcengine`` parser with its ``render`` subcommand."""
    parser = _Parser(
        prog=PROG,
        description="Render .blend files with MC Engine (or Cycles) from the command line. "
                    f"Blender's syntax also works: {PROG} -b SCENE.blend -E MCENGINE -o OUT -f 1",
    )
    parser.add_argument("--version", action="version", version=f"%(prog)s {_version()}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")
    render = commands.add_parser(
        "render", help="render one frame of a .blend file",
        description="Render one frame of a .blend file and save it as EXR and/or PNG.")
    render.add_argument("blendfile", metavar="SCENE.blend", help="the file to render")
    render.add_argument("-E", "--engine", type=_engine, default=None,
                        help="mcengine (default) or cycles; Blender's MCENGINE/CYCLES also work")
    render.add_argument("--samples", type=_samples, default=None,
                        help="samples per pixel (default: the file's Cycles samples)")
    render.add_argument("--resolution", type=_resolution, default=None, metavar="WxH",
                        help="image size in pixels, at 100%% (default: the file's)")
    render.add_argument("--seed", type=_seed, default=None,
                        help="sampling seed (default: the file's Cycles seed)")
    render.add_argument("-f", "--frame", "--render-frame", dest="frame", type=_frame,
                        default=None, metavar="F", help="frame to render (default: the file's current frame)")
    render.add_argument("-o", "--output", "--render-output", dest="outputs", action="append",
                        default=None, metavar="PATH",
                        help="output image; .exr or .png, '//' = folder of the .blend, "
                             "'#' = frame digits; repeat to save several formats "
                             "(default: ./SCENE.exr)")
    render.add_argument("-F", "--render-format", dest="format", type=_format, default=None,
                        metavar="FORMAT", help="OPEN_EXR or PNG (default: from the extension, else OPEN_EXR)")
    render.add_argument("-S", "--scene", default=None, help="scene to render (default: the file's active scene)")
    render.add_argument("-t", "--threads", type=_threads, default=None,
                        help="CPU threads, 0 = all (default: the file's setting)")
    _add_integrator_options(render)
    render.add_argument("--verbose", action="store_true",
                        help="show Blender's own log and tracebacks")
    _add_compare_parser(commands)
    _add_study_parser(commands)
    return parser


def _add_compare_parser(commands) -> None:
    compare = commands.add_parser(
        "compare", help="render with MC Engine and Cycles and test whether they agree",
        description="Render a scene with MC Engine and with Cycles under matched, unbiased "
                    "settings, K seeds each, and test whether the two agree within their noise. "
                    "Writes mcengine.exr, cycles.exr, side_by_side.png, report.json and report.md. "
                    "Exit status 0: agree, 3: differ.")
    compare.add_argument("blendfile", metavar="SCENE.blend", nargs="?", default=None,
                         help="the file to compare (or use --suite)")
    compare.add_argument("--suite", metavar="FOLDER", default=None,
                         help="compare every .blend in FOLDER and write summary.md/.html/.json")
    compare.add_argument("--samples", type=_samples, default=None,
                         help="samples per pixel and render (default: the file's Cycles samples)")
    compare.add_argument("--resolution", type=_compare_resolution, default=None, metavar="WxH|P%",
                         help="image size in pixels, or a percentage of the file's size "
                              "(default: the file's size and percentage)")
    compare.add_argument("--seeds", type=_seeds, default=DEFAULT_SEEDS, metavar="K",
                         help=f"renders per engine, {2}..{MAX_SEEDS} (default {DEFAULT_SEEDS})")
    compare.add_argument("--alpha", type=_alpha, default=DEFAULT_ALPHA,
                         help=f"false-alarm rate of the verdict over all its tests "
                              f"(default {DEFAULT_ALPHA:g})")
    compare.add_argument("--out", metavar="DIR", default=None,
                         help="output folder, created if missing "
                              "(default: ./compare-SCENE, or ./compare-suite)")
    compare.add_argument("-S", "--scene", default=None,
                         help="scene to compare (default: the file's active scene)")
    compare.add_argument("-t", "--threads", type=_threads, default=None,
                         help="CPU threads, 0 = all (default: the file's setting)")
    compare.add_argument("--verbose", action="store_true",
                         help="show Blender's own log and tracebacks")


def _add_study_parser(commands) -> None:
    from mcengine.study import DEFAULT_MAX_SAMPLES, DEFAULT_SEEDS, DEFAULT_TARGET_RELMSE

    study = commands.add_parser(
        "study", help="measure what accuracy costs in time, per integrator and for Cycles",
        description="Render the scene at 1, 2, 4, ... N samples per pixel with each integrator "
                    "(and Cycles), several seeds each, time every render and measure its error "
                    "against a converged reference. Writes study.csv, error_vs_time.png, "
                    "error_vs_samples.png, equal_time.png, study.html, study.md and study.json.")
    study.add_argument("blendfile", metavar="SCENE.blend", help="the file to study")
    study.add_argument("--out", metavar="DIR", default=None,
                       help="output folder, created if missing (default: ./study-SCENE)")
    study.add_argument("--max-samples", type=_study_samples, default=DEFAULT_MAX_SAMPLES,
                       metavar="N", help=f"largest sample count of the ladder "
                                         f"(default {DEFAULT_MAX_SAMPLES})")
    study.add_argument("--integrators", type=_integrator_list, default=INTEGRATORS,
                       metavar="LIST", help="comma-separated, from " + ",".join(INTEGRATORS)
                                            + " (default: all)")
    study.add_argument("--with-cycles", action="store_true",
                       help="also study Cycles, against its own reference")
    study.add_argument("--seeds", type=_seeds, default=DEFAULT_SEEDS, metavar="K",
                       help=f"renders per sample count, 2..{MAX_SEEDS} (default {DEFAULT_SEEDS})")
    study.add_argument("--resolution", type=_resolution, default=None, metavar="WxH",
                       help="image size in pixels (default: the file's size and percentage)")
    study.add_argument("--target", type=_target, default=DEFAULT_TARGET_RELMSE,
                       metavar="RELMSE", help=f"relMSE whose time to reach is reported "
                                              f"(default {DEFAULT_TARGET_RELMSE:g})")
    study.add_argument("--reference-samples", type=_samples, default=None, metavar="M",
                       help="samples per pixel of each reference (default: 16 x N)")
    _add_integrator_options(study, for_study=True)
    study.add_argument("-S", "--scene", default=None,
                       help="scene to study (default: the file's active scene)")
    study.add_argument("-t", "--threads", type=_threads, default=None,
                       help="CPU threads, 0 = all (default: the file's setting)")
    study.add_argument("--verbose", action="store_true",
                       help="show Blender's own log and tracebacks")


def _study_samples(text: str) -> int:
    return _positive_int(text, "largest sample count", MAX_STUDY_SAMPLES)


def _target(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"target must be a number, got {text!r}") from None
    if not 0.0 < value < math.inf:
        raise argparse.ArgumentTypeError(f"target relMSE must be positive, got {value:g}")
    return value


def _compare_resolution(text: str):
    """``WxH`` -> ("size", (w, h)); ``P%`` -> ("percent", P)."""
    match = re.fullmatch(r"\s*(\d+)\s*%\s*", text)
    if match is None:
        return "size", _resolution(text)
    percent = int(match[1])
    if not 1 <= percent <= MAX_PERCENTAGE:
        raise argparse.ArgumentTypeError(
            f"resolution percentage must be between 1 and {MAX_PERCENTAGE}, got {percent}")
    return "percent", percent


def _seeds(text: str) -> int:
    value = _positive_int(text, "seed count", MAX_SEEDS)
    if value < 2:
        raise argparse.ArgumentTypeError("at least 2 seeds are needed to estimate the noise, got 1")
    return value


def _alpha(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"alpha must be a number, got {text!r}") from None
    if not 0.0 < value < 1.0:
        raise argparse.ArgumentTypeError(f"alpha must lie strictly between 0 and 1, got {value:g}")
    return value


def _version() -> str:
    from importlib.metadata import PackageNotFoundError, version
    try:
        return version("mcengine")
    except PackageNotFoundError:
        return "(not installed)"


def _blender_style(argv: list[str]) -> list[str]:
    """Rewrite Blender's ``-b FILE ...`` syntax to ``render FILE ...``.

    ``-b`` takes no value in Blender (the file is a separate argument), so it is
    simply dropped; ``-a`` (animation) and the frame-range flags are refused
    because this command renders one frame.
    """
    unsupported = {"-a", "--render-anim", "-s", "--frame-start", "-e", "--frame-end",
                   "-j", "--frame-jump", "-P", "--python", "--python-expr", "-x", "--use-extension"}
    for arg in argv:
        if arg in unsupported:
            raise CliError(f"Blender option {arg} is not supported (renders one frame; see {PROG} render --help)")
    return ["render"] + [arg for arg in argv if arg not in ("-b", "--background")]


@dataclass(frozen=True)
class Output:
    """One image to save: ``pattern`` is the absolute path before frame substitution."""

    pattern: Path
    file_format: str


@dataclass(frozen=True)
class RenderRequest:
    """A validated ``render`` command line."""

    blendfile: Path
    engine: str
    outputs: tuple[Output, ...]
    samples: int | None
    resolution: tuple[int, int] | None
    seed: int | None
    frame: int | None
    scene: str | None
    threads: int | None
    verbose: bool
    integrator: str | None = None
    depth: int | None = None
    branching: int | None = None


def check_blend_file(path: Path) -> None:
    """Raise CliError unless ``path`` is a readable .blend (plain, zstd or gzip)."""
    if not path.exists():
        raise CliError(f"file not found: {path}")
    if not path.is_file():
        raise CliError(f"not a file: {path}")
    try:
        with open(path, "rb") as handle:
            head = handle.read(len(BLEND_MAGIC))
            handle.seek(0)
            if head.startswith(ZSTD_MAGIC):
                head = _zstd_head(handle, len(BLEND_MAGIC))
            elif head.startswith(GZIP_MAGIC):
                with gzip.GzipFile(fileobj=handle) as unzipped:
                    head = unzipped.read(len(BLEND_MAGIC))
    except (OSError, EOFError) as exc:
        raise CliError(f"cannot read {path}: {_os_reason(exc)}") from None
    if head != BLEND_MAGIC:
        raise CliError(f"not a .blend file: {path}")


def _zstd_head(handle, count: int) -> bytes:
    """First ``count`` decompressed bytes of a zstd stream (b"" if undecodable)."""
    try:
        import zstandard  # a dependency of bpy
    except ImportError:
        return BLEND_MAGIC  # cannot look inside; let Blender judge the contents
    try:
        return zstandard.ZstdDecompressor().stream_reader(handle).read(count)
    except zstandard.ZstdError:
        return b""


def _os_reason(exc: OSError) -> str:
    return exc.strerror or str(exc)


def _output_for(raw: str, forced_format: str | None, blend_dir: Path) -> Output:
    """Resolve ``//`` and the format of one ``-o`` value (frame digits come later)."""
    text = raw
    if text.startswith("//"):
        text = str(blend_dir / text[2:])
    if text.endswith(("/", os.sep)) or text == "":
        text += "####"  # Blender names a bare folder's image by its frame number
    pattern = Path(text).absolute()
    suffix = pattern.suffix.lower()
    by_extension = next((fmt for fmt, ext in FORMATS.items() if ext == suffix), None)
    if suffix in OTHER_IMAGE_EXTENSIONS:
        raise CliError(f"unsupported output type {suffix!r} in {raw} (use .exr or .png)")
    if forced_format and by_extension and by_extension != forced_format:
        raise CliError(f"output {raw} has extension {suffix} but the format is {forced_format}")
    file_format = forced_format or by_extension or DEFAULT_FORMAT
    if by_extension is None:
        pattern = pattern.with_name(pattern.name + FORMATS[file_format])
    return Output(pattern, file_format)


def check_output_folder(path: Path) -> None:
    """Raise CliError unless an image can be created at ``path`` (tested by writing)."""
    folder = path.parent
    if not folder.exists():
        raise CliError(f"output folder does not exist: {folder}")
    if not folder.is_dir():
        raise CliError(f"output folder is not a folder: {folder}")
    if path.is_dir():
        raise CliError(f"output path is a folder: {path}")
    try:
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise CliError(f"cannot write to output folder {folder}: {_os_reason(exc)}") from None


@dataclass(frozen=True)
class CompareRequest:
    """A validated ``compare`` command line: ``blendfile`` or ``suite`` is set."""

    blendfile: Path | None
    suite: Path | None
    out: Path
    samples: int | None
    resolution: tuple[int, int] | None
    percentage: int | None
    seeds: int
    alpha: float
    scene: str | None
    threads: int | None
    verbose: bool


def prepare_output_folder(folder: Path) -> None:
    """Create ``folder`` (and its parents) if needed; raise CliError unless it is writable."""
    if folder.exists() and not folder.is_dir():
        raise CliError(f"output path is not a folder: {folder}")
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError as exc:
        raise CliError(f"cannot write to output folder {folder}: {_os_reason(exc)}") from None


def _compare_request(args) -> CompareRequest:
    if (args.blendfile is None) == (args.suite is None):
        raise CliError("give either SCENE.blend or --suite FOLDER "
                       f"(try '{PROG} compare SCENE.blend' or '{PROG} compare --suite blend_scenes/')")
    blendfile = suite = None
    if args.suite is not None:
        suite = Path(args.suite).absolute()
        if not suite.is_dir():
            raise CliError(f"suite folder not found: {suite}" if not suite.exists()
                           else f"--suite needs a folder, not a file: {suite}")
        files = sorted(suite.glob("*.blend"))
        if not files:
            raise CliError(f"no .blend files in {suite}")
        for path in files:
            check_blend_file(path)
        if args.scene is not None:
            raise CliError("-S/--scene names one scene of one file; it cannot be used with --suite")
        default_out = "compare-suite"
    else:
        blendfile = Path(args.blendfile).absolute()
        check_blend_file(blendfile)
        default_out = f"compare-{blendfile.stem}"
    out = Path(args.out if args.out is not None else default_out).absolute()
    prepare_output_folder(out)
    kind, value = args.resolution if args.resolution is not None else (None, None)
    if kind == "size" and min(value) < MIN_COMPARE_SIZE:
        raise CliError(f"resolution {value[0]}x{value[1]} is too small for the comparison's "
                       f"{MIN_COMPARE_SIZE}x{MIN_COMPARE_SIZE} block grid")
    return CompareRequest(
        blendfile=blendfile, suite=suite, out=out, samples=args.samples,
        resolution=value if kind == "size" else None,
        percentage=value if kind == "percent" else None, seeds=args.seeds, alpha=args.alpha,
        scene=args.scene, threads=args.threads, verbose=args.verbose)


@dataclass(frozen=True)
class StudyRequest:
    """A validated ``study`` command line."""

    blendfile: Path
    out: Path
    max_samples: int
    integrators: tuple
    with_cycles: bool
    seeds: int
    resolution: tuple[int, int] | None
    target: float
    reference_samples: int | None
    depth: int | None
    branching: int | None
    scene: str | None
    threads: int | None
    verbose: bool


def _study_request(args) -> StudyRequest:
    from mcengine.study import REFERENCE_RENDERS
    blendfile = Path(args.blendfile).absolute()
    check_blend_file(blendfile)
    _check_integrator_options(args.integrators, args.depth, args.branching)
    if args.reference_samples is not None and args.reference_samples < max(
            2 * args.max_samples, REFERENCE_RENDERS):
        raise CliError(f"--reference-samples {args.reference_samples} is too few to measure "
                       f"errors against: use at least {max(2 * args.max_samples, REFERENCE_RENDERS)} "
                       f"(twice --max-samples), ideally 16 times")
    out = Path(args.out if args.out is not None else f"study-{blendfile.stem}").absolute()
    prepare_output_folder(out)
    return StudyRequest(
        blendfile=blendfile, out=out, max_samples=args.max_samples,
        integrators=args.integrators, with_cycles=args.with_cycles, seeds=args.seeds,
        resolution=args.resolution, target=args.target,
        reference_samples=args.reference_samples, depth=args.depth, branching=args.branching,
        scene=args.scene, threads=args.threads, verbose=args.verbose)


def parse_args(argv: list[str]) -> RenderRequest | CompareRequest | StudyRequest | None:
    """Validate the command line; None means help/version was printed."""
    if any(arg in ("-b", "--background") for arg in argv):
        argv = _blender_style(argv)
    parser = build_parser()
    if not argv:
        raise CliError(f"no command given (try '{PROG} render SCENE.blend' or '{PROG} --help')")
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # --help / --version
        if exc.code:
            raise
        return None
    if args.command == "compare":
        return _compare_request(args)
    if args.command == "study":
        return _study_request(args)
    engine = args.engine or DEFAULT_ENGINE
    _check_integrator_options((args.integrator,) if args.integrator else (), args.depth,
                              args.branching, engine)
    blendfile = Path(args.blendfile).absolute()
    check_blend_file(blendfile)
    raw_outputs = args.outputs or [f"{blendfile.stem}{FORMATS[args.format or DEFAULT_FORMAT]}"]
    outputs = tuple(_output_for(raw, args.format, blendfile.parent) for raw in raw_outputs)
    for output in outputs:
        check_output_folder(output.pattern)
    return RenderRequest(
        blendfile=blendfile, engine=engine, outputs=outputs,
        samples=args.samples, resolution=args.resolution, seed=args.seed, frame=args.frame,
        scene=args.scene, threads=args.threads, verbose=args.verbose,
        integrator=args.integrator, depth=args.depth, branching=args.branching)


def frame_path(pattern: Path, frame: int) -> Path:
    """Replace the last run of ``#`` in the file name with the zero-padded frame."""
    runs = list(re.finditer(r"#+", pattern.name))
    if not runs:
        return pattern
    last = runs[-1]
    name = pattern.name[:last.start()] + str(frame).zfill(len(last[0])) + pattern.name[last.end():]
    return pattern.with_name(name)


# ---------------------------------------------------------------------------
# Blender's log and the progress display
# ---------------------------------------------------------------------------

class BlenderLog:
    """Captures everything written to fds 1 and 2 (C and Python) into a file.

    Blender writes its log from C with buffered stdio, so the C buffers are
    flushed before the descriptors are restored.  ``console`` is a duplicate of
    the real stderr for the progress display, which must not be captured.
    """

    def __init__(self, passthrough: bool):
        self.passthrough = passthrough
        self.console = os.fdopen(os.dup(2), "w", buffering=1)
        self._file = tempfile.TemporaryFile(mode="w+b")

    @contextlib.contextmanager
    def capture(self):
        if self.passthrough:
            yield
            return
        _flush_all()
        saved = os.dup(1), os.dup(2)
        os.dup2(self._file.fileno(), 1)
        os.dup2(self._file.fileno(), 2)
        try:
            yield
        finally:
            _flush_all()
            os.dup2(saved[0], 1)
            os.dup2(saved[1], 2)
            os.close(saved[0])
            os.close(saved[1])

    def mark(self) -> int:
        """Current end of the log, for ``text(since=...)``."""
        self._file.seek(0, os.SEEK_END)
        return self._file.tell()

    def text(self, since: int = 0) -> str:
        """The log captured so far, from byte offset ``since``."""
        self._file.seek(since)
        return self._file.read().decode("utf-8", "replace")


def _flush_all() -> None:
    sys.stdout.flush()
    sys.stderr.flush()
    with contextlib.suppress(Exception):
        ctypes.CDLL(None).fflush(None)


def engine_traceback(log: str) -> str | None:
    """The exception line of a Python traceback in Blender's log, if any.

    Blender catches exceptions raised inside ``RenderEngine.render``, prints the
    traceback and still saves the (incomplete) image, so the log is the only
    place a crash shows up.
    """
    lines = log.splitlines()
    starts = [i for i, line in enumerate(lines) if line.startswith("Traceback (most recent call last)")]
    if not starts:
        return None
    for line in lines[starts[-1] + 1:]:
        if line and not line[0].isspace():
            return line.strip()
    return "the render engine raised an exception"


def warning_lines(log: str) -> list[str]:
    """``Warning: ...`` lines (engine reports) from Blender's log, without the prefix."""
    return [line.split(":", 1)[1].strip() for line in log.splitlines() if line.startswith("Warning:")]


def error_message(exc: Exception) -> str:
    """One line from a bpy operator's RuntimeError (``Error: ...`` lines joined)."""
    lines = [line.strip() for line in str(exc).splitlines() if line.strip()]
    lines = [line[len("Error:"):].strip() if line.startswith("Error:") else line for line in lines]
    unique = list(dict.fromkeys(lines))
    return "; ".join(unique) or type(exc).__name__


class Progress:
    """Render progress on stderr from Blender's render statistics strings."""

    def __init__(self, stream, label: str):
        self.stream = stream
        self.label = label
        self.is_tty = stream.isatty()
        self.start = time.monotonic()
        self._lines_printed = 0  # non-TTY: number of PROGRESS_LINE_STEP steps reported
        self._drawn = False

    def on_stats(self, stats, *_unused) -> None:
        """``bpy.app.handlers.render_stats`` callback; never raises."""
        with contextlib.suppress(Exception):
            self.update(str(stats))

    def update(self, stats: str) -> None:
        match = SAMPLE_STATS.search(stats)
        if match is None:
            if self.is_tty and not self._drawn:
                phase = stats.split("|")[-1].strip()
                self._draw(f"{self.label}: {phase}")
            return
        done, total = int(match[1]), int(match[2])
        fraction = min(done / total, 1.0) if total else 0.0
        if self.is_tty:
            filled = round(fraction * PROGRESS_BAR_WIDTH)
            bar = "#" * filled + "." * (PROGRESS_BAR_WIDTH - filled)
            self._draw(f"{self.label} [{bar}] {fraction:4.0%}  sample {done}/{total}  {self._elapsed()}")
            self._drawn = True
        else:
            steps = int(fraction / PROGRESS_LINE_STEP + 1e-9)
            if steps > self._lines_printed:
                self._lines_printed = steps
                self.stream.write(f"{self.label}: {fraction:.0%} (sample {done}/{total}, {self._elapsed()})\n")
                self.stream.flush()

    def finish(self) -> None:
        if self.is_tty:
            self.stream.write("\r\033[K")
            self.stream.flush()

    def _draw(self, text: str) -> None:
        width = max(20, _terminal_width(self.stream) - 1)
        self.stream.write("\r\033[K" + text[:width])
        self.stream.flush()

    def _elapsed(self) -> str:
        seconds = time.monotonic() - self.start
        return f"{int(seconds // 60):02d}:{seconds % 60:04.1f}"


def _terminal_width(stream) -> int:
    try:
        return os.get_terminal_size(stream.fileno()).columns
    except (OSError, ValueError):
        return 80


# ---------------------------------------------------------------------------
# Rendering (bpy)
# ---------------------------------------------------------------------------

def _register_addon() -> None:
    """Register MC Engine (only done when it is the engine asked for)."""
    try:
        import mcengine_blender
        mcengine_blender.register()
    except Exception as exc:  # the add-on's failure must not hide behind a traceback
        raise CliError(f"the MC Engine add-on failed to register: {type(exc).__name__}: {exc}",
                       EXIT_RENDER_FAILED) from None


def _open_blend(bpy, path: Path, scene_name: str | None):
    try:
        bpy.ops.wm.open_mainfile(filepath=str(path), load_ui=False)
    except RuntimeError as exc:
        raise CliError(f"cannot open {path}: {error_message(exc)}", EXIT_RENDER_FAILED) from None
    if scene_name is None:
        return bpy.context.scene
    scene = bpy.data.scenes.get(scene_name)
    if scene is None:
        names = ", ".join(s.name for s in bpy.data.scenes)
        raise CliError(f"no scene named {scene_name!r} in {path.name} (scenes: {names})")
    return scene


def _apply_overrides(scene, request: RenderRequest) -> None:
    scene.render.engine = request.engine
    if request.samples is not None:
        scene.cycles.samples = request.samples
    if request.seed is not None:
        scene.cycles.seed = request.seed
    if request.resolution is not None:
        scene.render.resolution_x, scene.render.resolution_y = request.resolution
        scene.render.resolution_percentage = 100
    if request.threads is not None:
        scene.render.threads_mode = "AUTO" if request.threads == 0 else "FIXED"
        if request.threads:
            scene.render.threads = request.threads
    if request.frame is not None:
        scene.frame_set(request.frame)
    own = getattr(scene, "mcengine", None)
    if own is not None:
        if request.integrator is not None:
            own.integrator = request.integrator.upper()
        if request.depth is not None:
            own.depth = request.depth
        if request.branching is not None:
            own.branching = request.branching


def _set_image_format(scene, file_format: str) -> None:
    settings = scene.render.image_settings
    settings.media_type = "IMAGE"
    settings.file_format = file_format
    settings.color_mode = "RGBA"
    settings.color_depth = "32" if file_format == "OPEN_EXR" else "8"


def _render(bpy, scene, request: RenderRequest, paths: list[Path], log: BlenderLog) -> None:
    """Render once, save every output, raise CliError on any failure."""
    first, *others = zip(request.outputs, paths)
    _set_image_format(scene, first[0].file_format)
    scene.render.filepath = str(first[1])
    scene.render.use_file_extension = True
    progress = Progress(log.console, request.engine)
    log_start = log.mark()
    bpy.app.handlers.render_stats.append(progress.on_stats)
    try:
        with log.capture():
            bpy.ops.render.render(write_still=True, scene=scene.name)
    except RuntimeError as exc:
        raise CliError(f"render failed: {error_message(exc)}", EXIT_RENDER_FAILED) from None
    finally:
        bpy.app.handlers.render_stats.remove(progress.on_stats)
        progress.finish()
    crash = engine_traceback(log.text(since=log_start))
    if crash is not None:
        _remove_quietly(first[1])
        raise CliError(f"render failed: {request.engine} raised {crash}", EXIT_RENDER_FAILED)
    if not first[1].is_file():
        raise CliError(f"render finished but no image was written to {first[1]}", EXIT_RENDER_FAILED)
    result = bpy.data.images["Render Result"]
    for output, path in others:
        _set_image_format(scene, output.file_format)
        try:
            with log.capture():
                result.save_render(filepath=str(path), scene=scene)
        except RuntimeError as exc:
            raise CliError(f"cannot save {path}: {error_message(exc)}", EXIT_RENDER_FAILED) from None


def _remove_quietly(path: Path) -> None:
    with contextlib.suppress(OSError):
        path.unlink()


def run(request: RenderRequest) -> int:
    """Load, render and save; returns the exit status."""
    log = BlenderLog(passthrough=request.verbose)
    started = time.monotonic()
    with log.capture():
        try:
            import bpy
        except ImportError as exc:
            raise CliError(f"cannot import bpy (Blender 5.0 as a Python module): {exc}",
                           EXIT_RENDER_FAILED) from None
        if request.engine == "MCENGINE":
            _register_addon()  # before loading, as an enabled add-on would be
        scene = _open_blend(bpy, request.blendfile, request.scene)
        _apply_overrides(scene, request)
    frame = scene.frame_current
    paths = [frame_path(output.pattern, frame) for output in request.outputs]
    _render(bpy, scene, request, paths, log)
    for warning in warning_lines(log.text()):
        log.console.write(f"{PROG}: warning: {warning}\n")
    render = scene.render
    scale = render.resolution_percentage / 100
    log.console.write(
        f"{PROG}: rendered {scene.name!r} frame {frame} with {request.engine}, "
        f"{round(render.resolution_x * scale)}x{round(render.resolution_y * scale)}, "
        f"{scene.cycles.samples} samples, in {time.monotonic() - started:.1f} s\n")
    if request.engine == "MCENGINE":
        accounting = _ray_accounting()
        if accounting:
            log.console.write(f"{PROG}: {accounting}\n")
    for path in paths:
        print(path)
    return EXIT_OK


def _ray_accounting() -> str | None:
    """The last MC Engine render's ray accounting line (None if the engine kept none)."""
    from .engine import last_render
    return last_render.get("accounting")


def _import_bpy_with_addon():
    try:
        import bpy
    except ImportError as exc:
        raise CliError(f"cannot import bpy (Blender 5.0 as a Python module): {exc}",
                       EXIT_RENDER_FAILED) from None
    _register_addon()
    return bpy


class _CompareRenderer:
    """``render`` for the comparison: a progress bar per render, the engine's log checked.

Called while Blender's log is captured (the whole comparison runs inside
``BlenderLog.capture``); the progress bar goes to the real stderr.

    An engine's crash (a traceback in the log) is raised as RuntimeError, which
    the comparison reports as a failed render.
    """

    def __init__(self, bpy, log: BlenderLog, threads: int | None, bars: bool = True):
        self.bpy = bpy
        self.log = log
        self.threads = threads
        self.bars = bars           # False: no progress display per render
        self.label = ""
        self.warnings: list[str] = []

    def on_render(self, engine: str, index: int, total: int) -> None:
        self.label = f"[{index + 1}/{total}] {engine}"

    def __call__(self, scene, engine, **settings):
        from .batch import render_scene
        if self.threads is not None:
            scene.render.threads_mode = "AUTO" if self.threads == 0 else "FIXED"
            if self.threads:
                scene.render.threads = self.threads
        progress = Progress(self.log.console, self.label or engine)
        start = self.log.mark()
        if self.bars:
            self.bpy.app.handlers.render_stats.append(progress.on_stats)
        try:
            result = render_scene(scene, engine, **settings)
        finally:
            if self.bars:
                self.bpy.app.handlers.render_stats.remove(progress.on_stats)
                progress.finish()
        text = self.log.text(since=start)
        crash = engine_traceback(text)
        if crash is not None:
            raise RuntimeError(f"{engine} raised {crash}")
        for warning in warning_lines(text):
            if warning not in self.warnings:
                self.warnings.append(warning)
        return result


def _compare_options(request: CompareRequest):
    from .comparison import CompareOptions
    return CompareOptions(samples=request.samples, resolution=request.resolution,
                          percentage=request.percentage, seeds=request.seeds, alpha=request.alpha)


def run_compare(request: CompareRequest) -> int:
    """Compare one file or a suite; returns the exit status (0 agree, 3 differ)."""
    log = BlenderLog(passthrough=request.verbose)
    with log.capture():
        bpy = _import_bpy_with_addon()
    from mcengine.report import write_comparison

    from .comparison import CompareError, compare_file, run_suite
    renderer = _CompareRenderer(bpy, log, request.threads)
    options = _compare_options(request)
    console = log.console
    if request.suite is not None:
        def on_scene(path, index, total):
            console.write(f"{PROG}: comparing {path.name} ({index + 1}/{total})\n")

        def on_done(row):
            detail = row.error if row.verdict == "error" else (
                f"relMSE {row.relmse:.3g}, FLIP {row.flip:.3f}, blocks differ {row.blocks_differ}")
            console.write(f"{PROG}: {row.scene}: {row.verdict} ({detail})\n")

        with log.capture():
            rows, paths = run_suite(request.suite, options, request.out, render=renderer,
                                    on_scene=on_scene, on_render=renderer.on_render,
                                    on_done=on_done)
        verdicts = {row.verdict for row in rows}
        console.write(f"{PROG}: {sum(r.verdict == 'agree' for r in rows)}/{len(rows)} scenes agree; "
                      f"summary in {paths['summary.md']} and {paths['summary.html']}\n")
        print(paths["summary.json"])
        if "error" in verdicts:
            return EXIT_RENDER_FAILED
        return EXIT_DIFFER if "differ" in verdicts else EXIT_OK
    try:
        with log.capture():
            comparison = compare_file(request.blendfile, options, scene_name=request.scene,
                                      render=renderer, on_render=renderer.on_render)
            paths = write_comparison(comparison, request.out)
    except CompareError as exc:
        raise CliError(str(exc), EXIT_RENDER_FAILED) from None
    for warning in renderer.warnings:
        console.write(f"{PROG}: warning: {warning}\n")
    console.write(f"{PROG}: {comparison.summary()}\n{PROG}: wrote " + ", ".join(
        str(paths[name]) for name in ("side_by_side.png", "report.md", "mcengine.exr",
                                      "cycles.exr")) + "\n")
    print(paths["report.json"])
    return EXIT_OK if comparison.verdict == "agree" else EXIT_DIFFER


def run_study(request: StudyRequest) -> int:
    """Render the study and write its files; returns the exit status."""
    log = BlenderLog(passthrough=request.verbose)
    with log.capture():
        bpy = _import_bpy_with_addon()
    from mcengine.study import StudyError, StudyOptions, summarise, write_study

    from .study import StudySettings, study_file
    console = log.console
    # One line per render: a study makes a hundred, too many for a bar each.
    renderer = _CompareRenderer(bpy, log, None, bars=False)

    def on_render(label, index, total):
        renderer.label = label
        console.write(f"{PROG}: [{index + 1}/{total}] {label}\n")

    options = StudyOptions(integrators=request.integrators, with_cycles=request.with_cycles,
                           max_samples=request.max_samples, seeds=request.seeds,
                           reference_samples=request.reference_samples,
                           target_relmse=request.target)
    settings = StudySettings(resolution=request.resolution, depth=request.depth,
                             branching=request.branching, threads=request.threads)
    try:
        with log.capture():
            study = study_file(request.blendfile, options, settings, scene_name=request.scene,
                               render=renderer, on_render=on_render)
            paths = write_study(study, request.out)
    except (StudyError, RuntimeError) as exc:
        raise CliError(str(exc).splitlines()[0], EXIT_RENDER_FAILED) from None
    for warning in renderer.warnings:
        console.write(f"{PROG}: warning: {warning}\n")
    for name, s in summarise(study).items():
        console.write(f"{PROG}: {study_line(name, s)}\n")
    console.write(f"{PROG}: wrote {paths['csv']}, {paths['time']}, {paths['markdown']}\n")
    print(paths["html"])
    return EXIT_OK


def study_line(name: str, s) -> str:
    """One line per integrator: time to target, slope, plateau."""
    if s.time_to_target is None:
        reach = f"does not reach relMSE {s.target:g}"
    else:
        how = {"extrapolated": " (extrapolated)", "first rung": " (at 1 sample)"}.get(
            s.target_how, "")
        reach = f"relMSE {s.target:g} in {s.time_to_target:.2f} s{how}"
    parts = [f"{name}: {reach}"]
    if s.slope is not None:
        parts.append(f"slope {s.slope:.3f} ± {s.slope_ci:.3f}")
    if s.plateau:
        parts.append(f"plateau at relMSE {s.floor:.3g}")
    return ", ".join(parts)


def main(argv: list[str] | None = None) -> int:
    """Console entry point; returns the exit status."""
    argv = sys.argv[1:] if argv is None else argv
    verbose = "--verbose" in argv
    try:
        request = parse_args(argv)
        if request is None:
            return EXIT_OK
        if isinstance(request, CompareRequest):
            return run_compare(request)
        if isinstance(request, StudyRequest):
            return run_study(request)
        return run(request)
    except CliError as exc:
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print(f"{PROG}: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except Exception as exc:  # last resort: still one line unless asked for details
        if verbose:
            traceback.print_exc()
        print(f"{PROG}: error: internal error: {type(exc).__name__}: {exc} "
              "(run with --verbose for the traceback)", file=sys.stderr)
        return EXIT_RENDER_FAILED


if __name__ == "__main__":
    sys.exit(main())
