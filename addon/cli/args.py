"""The command line's arguments: parsed and checked without Blender.

:func:`parse_args` turns ``argv`` into a validated request, one of
:class:`RenderRequest`, :class:`CompareRequest` and :class:`StudyRequest`, or
raises :class:`~.errors.CliError` with a one-line message.  Every argument,
the input file (its magic bytes) and the output folders are checked here,
before ``bpy`` is imported, so bad input fails in well under a second.
Blender's own ``-b FILE ...`` syntax is rewritten to ``render FILE ...``.
Output paths follow Blender (``//``, ``#`` frame digits, the format's
extension appended).
"""
from __future__ import annotations

import argparse
import gzip
import math
import os
import re
import tempfile
from dataclasses import dataclass
from pathlib import Path

from mcengine.evaluation.study import DEFAULT_MAX_SAMPLES, DEFAULT_TARGET_RELMSE, REFERENCE_RENDERS
from mcengine.evaluation.study import DEFAULT_SEEDS as STUDY_SEEDS
from mcengine.integrators import BRANCHING_RANGE, DEPTH_RANGE, INTEGRATORS
from mcengine.integrators import DEFAULT as DEFAULT_INTEGRATOR
from mcengine.integrators import NAMES as INTEGRATOR_NAMES
from mcengine.samplers import NAMES as SAMPLER_NAMES

from ..batch.render import ENGINES
from .errors import PROG, CliError
from .frames import (
    FrameAction,
    frame_path,
    parse_frame_list,
    parse_relative,
    parse_step,
    plan_frames,
    renders_several,
)

__all__ = ["RenderRequest", "CompareRequest", "StudyRequest", "Output", "parse_args",
           "build_parser", "check_blend_file", "check_output_folder", "check_output_paths",
           "check_folder_creatable", "partial_path"]

DEFAULT_ENGINE = ENGINES["mcengine"]


# Blender image format -> file extension.  Only the formats whose pixel meaning is
# unambiguous are offered: linear float EXR (Combined only, or every render pass
# and view layer in one multilayer file) and display-referred PNG.
FORMATS = {"OPEN_EXR": ".exr", "OPEN_EXR_MULTILAYER": ".exr", "PNG": ".png"}
DEFAULT_FORMAT = "OPEN_EXR"
# Extensions of other image formats: a name ending in one of these is a mistake,
# not a name to which ".exr" should be appended.
OTHER_IMAGE_EXTENSIONS = {".jpg", ".jpeg", ".tif", ".tiff", ".hdr", ".bmp", ".tga",
                          ".webp", ".jp2", ".dpx", ".cin", ".rgb", ".sgi", ".mp4", ".mkv"}

# Blender's hard limits (RNA ranges of RenderSettings, CyclesRenderSettings, Scene).
MIN_RESOLUTION, MAX_RESOLUTION = 4, 65536
MAX_SAMPLES = 16_777_216
MAX_SEED = 2_147_483_647
MAX_THREADS = 1024
# compare: renders per engine.  Two is the minimum that estimates the noise;
# more than this is never needed (the test pools every pixel's variance).
DEFAULT_SEEDS, MAX_SEEDS = 2, 64     # the study's default is its own (STUDY_SEEDS)
MAX_PERCENTAGE = 1000
DEFAULT_ALPHA = 1e-3
# The comparison tests an 8x8 grid of blocks, so each side needs 8 pixels.
MIN_COMPARE_SIZE = 8
# study: the ladder's largest sample count (25 rungs at most, see mcengine.evaluation.study).
MAX_STUDY_SAMPLES = 1 << 24

# A .blend starts with "BLENDER"; Blender 3.0+ may zstd-compress the whole file,
# older versions gzip it.
BLEND_MAGIC = b"BLENDER"
ZSTD_MAGIC = b"\x28\xb5\x2f\xfd"
GZIP_MAGIC = b"\x1f\x8b"


class _Parser(argparse.ArgumentParser):
    """argparse that raises instead of printing usage and exiting."""

    def error(self, message):
        raise CliError(message)


def _positive_int(text: str, what: str, maximum: int, minimum: int = 1) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{what} must be a whole number, got {text!r}") from None
    if not minimum <= value <= maximum:
        raise argparse.ArgumentTypeError(f"{what} must be between {minimum} and {maximum}, "
                                         f"got {value}")
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


def _one_of(kind: str, names):
    """An argparse type: ``names``' member that the text names (any case); an unknown one
    is a one-line error listing the choices."""
    def parse(text: str) -> str:
        name = text.lower()
        if name not in names:
            raise argparse.ArgumentTypeError(
                f"unknown {kind} {text!r} (choose from {', '.join(names)})")
        return name
    return parse


_integrator = _one_of("integrator", INTEGRATOR_NAMES)
_sampler = _one_of("sampler", SAMPLER_NAMES)


def _integrator_list(text: str) -> tuple[str, ...]:
    names = tuple(_integrator(part.strip()) for part in text.split(",") if part.strip())
    if not names:
        raise argparse.ArgumentTypeError("--integrators needs at least one name, e.g. path,raycast")
    if len(set(names)) != len(names):
        raise argparse.ArgumentTypeError(f"an integrator is listed twice in {text!r}")
    return names


def _depth(text: str) -> int:
    return _positive_int(text, "depth", DEPTH_RANGE[1], DEPTH_RANGE[0])


def _branching(text: str) -> int:
    return _positive_int(text, "branching", BRANCHING_RANGE[1], BRANCHING_RANGE[0])


def _readers(parameter: str) -> list[str]:
    """Names of the integrators that read ``parameter`` ("depth", "branching", "sampler")."""
    return [name for name, info in INTEGRATORS.items() if getattr(info, f"uses_{parameter}")]


def _in_words(names) -> str:
    """'a', 'a and b', 'a, b or c'."""
    names = list(names)
    return names[0] if len(names) == 1 else ", ".join(names[:-1]) + " or " + names[-1]


def _add_integrator_options(parser, for_study: bool = False) -> None:
    """--depth, --branching and --sampler (and --integrator for a render)."""
    if not for_study:
        choices = [f"{name} (default)" if name == DEFAULT_INTEGRATOR else name
                   for name in INTEGRATOR_NAMES]
        parser.add_argument("--integrator", type=_integrator, default=None,
                            help=f"MC Engine's algorithm: {_in_words(choices)} "
                                 "(default: the file's setting)")
    parser.add_argument("--depth", type=_depth, default=None, metavar="R",
                        help=f"ray levels of {' and '.join(_readers('depth'))}, "
                             f"{DEPTH_RANGE[0]}..{DEPTH_RANGE[1]} (the camera ray is level 1)")
    parser.add_argument("--branching", type=_branching, default=None, metavar="B",
                        help=f"rays per hit of {' and '.join(_readers('branching'))}, "
                             f"{BRANCHING_RANGE[0]}..{BRANCHING_RANGE[1]}")
    parser.add_argument("--sampler", type=_sampler, default=None,
                        help=f"random numbers of the {_in_words(_readers('sampler'))} "
                             f"integrator: {_in_words(SAMPLER_NAMES)} (default: the file's "
                             f"setting, as Cycles: sobol)")


def _check_integrator_options(integrators, depth, branching, engine=None, sampler=None) -> None:
    """One-line errors for options that the chosen integrators would ignore."""
    if engine == ENGINES["cycles"] and (integrators or depth or branching or sampler):
        raise CliError("--integrator, --depth, --branching and --sampler choose MC Engine's "
                       "algorithm; they do not apply to --engine cycles")
    if not integrators:
        return
    for option, value in (("depth", depth), ("branching", branching), ("sampler", sampler)):
        readers = _readers(option)
        if value is not None and not set(readers) & set(integrators):
            plural = "s" if len(readers) > 1 else ""
            raise CliError(f"--{option} applies to the {' and '.join(readers)} "
                           f"integrator{plural} only")


def _format(text: str) -> str:
    name = text.upper()
    if name not in FORMATS:
        raise argparse.ArgumentTypeError(
            f"unsupported format {text!r} (choose from {', '.join(FORMATS)})")
    return name


class _FrameOption(argparse.Action):
    """Collects -f, -a, -s, -e and -j in command-line order (Blender applies them in order)."""

    PARSE = {"frames": parse_frame_list, "start": lambda t: parse_relative(t, "-s/--frame-start"),
             "end": lambda t: parse_relative(t, "-e/--frame-end"), "step": parse_step,
             "animation": lambda t: None}

    def __init__(self, option_strings, dest, kind, **kwargs):
        self.kind = kind
        super().__init__(option_strings, dest, nargs=0 if kind == "animation" else None, **kwargs)

    def __call__(self, parser, namespace, values, option_string=None):
        text = values if isinstance(values, str) else ""
        action = FrameAction(self.kind, self.PARSE[self.kind](text), text)
        setattr(namespace, self.dest, (*(getattr(namespace, self.dest) or ()), action))


# Frame options whose value may start with '-' (an end-relative frame): argparse would
# take "-2" for an option, so such values are attached to their option first.
_FRAME_VALUE_OPTIONS = ("-f", "--frame", "--render-frame", "-s", "--frame-start", "-e",
                        "--frame-end", "-j", "--frame-jump")


def _add_frame_options(parser) -> None:
    """Blender's frame options: -f (frames, lists, ranges), -a, -s, -e, -j."""
    def add(*names, kind, help, metavar=None):
        parser.add_argument(*names, dest="frame_actions", action=_FrameOption, kind=kind,
                            default=(), help=help, **({"metavar": metavar} if metavar else {}))

    add("-f", "--frame", "--render-frame", kind="frames", metavar="FRAMES",
        help="frames to render: N, +N (from the start frame), -N (from the end: -1 is the "
             "end frame), lists and ranges as 1,3,5..7 (default: the file's current frame)")
    add("-a", "--render-anim", kind="animation",
        help="render the animation: start to end frame, every step frames")
    add("-s", "--frame-start", kind="start", metavar="F",
        help="start frame for -a and +N of -f (+N/-N: relative to the file's start)")
    add("-e", "--frame-end", kind="end", metavar="F",
        help="end frame for -a and -N of -f (+N/-N: relative to the file's end)")
    add("-j", "--frame-jump", kind="step", metavar="N", help="frame step of -a")
    parser.add_argument("--overwrite", action=argparse.BooleanOptionalAction, default=None,
                        help="with -f/-a: replace existing images (default: the file's Output > "
                             "Overwrite); --no-overwrite skips frames whose images exist")
    parser.add_argument("--placeholders", action=argparse.BooleanOptionalAction, default=None,
                        help="with -f/-a: create an empty image file while its frame renders, so "
                             "other machines skip it (default: the file's Output > Placeholders)")


def _attach_frame_values(argv: list[str]) -> list[str]:
    """``-f -2`` -> ``-f-2`` and ``--frame -2`` -> ``--frame=-2``."""
    out, i = [], 0
    while i < len(argv):
        arg = argv[i]
        if arg in _FRAME_VALUE_OPTIONS and i + 1 < len(argv) and argv[i + 1].startswith("-") \
                and argv[i + 1][1:2].isdigit():
            out.append(arg + ("=" if arg.startswith("--") else "") + argv[i + 1])
            i += 2
        else:
            out.append(arg)
            i += 1
    return out


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
        "render", help="render a frame, a list of frames or the animation of a .blend file",
        description="Render frames of a .blend file and save them as EXR and/or PNG "
                    "(by default the file's current frame).")
    render.add_argument("blendfile", metavar="SCENE.blend", help="the file to render")
    render.add_argument("-E", "--engine", type=_engine, default=None,
                        help="mcengine (default) or cycles; Blender's MCENGINE/CYCLES also work")
    render.add_argument("--samples", type=_samples, default=None,
                        help="samples per pixel (default: the file's Cycles samples)")
    render.add_argument("--resolution", type=_resolution, default=None, metavar="WxH",
                        help="image size in pixels, at 100%% (default: the file's)")
    render.add_argument("--seed", type=_seed, default=None,
                        help="sampling seed (default: the file's Cycles seed)")
    _add_frame_options(render)
    render.add_argument("-o", "--output", "--render-output", dest="outputs", action="append",
                        default=None, metavar="PATH",
                        help="output image; .exr or .png, '//' = folder of the .blend, "
                             "'#' = frame digits; repeat to save several formats "
                             "(default: ./SCENE.exr)")
    render.add_argument("-F", "--render-format", dest="format", type=_format, default=None,
                        metavar="FORMAT", help="OPEN_EXR, OPEN_EXR_MULTILAYER (every render pass) or "
                                               "PNG (default: from the extension, else OPEN_EXR)")
    render.add_argument("-S", "--scene", default=None, help="scene to render (default: the file's active scene)")
    render.add_argument("-t", "--threads", type=_threads, default=None,
                        help="CPU threads, 0 = all (default: the file's setting)")
    _add_integrator_options(render)
    render.add_argument("--keep-partial", action="store_true",
                        help="if the render is interrupted (Ctrl-C, SIGTERM), save the image so far "
                             "as NAME.partial.exr/.png next to each output (MC Engine only)")
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
    study.add_argument("--integrators", type=_integrator_list, default=INTEGRATOR_NAMES,
                       metavar="LIST", help="comma-separated, from " + ",".join(INTEGRATOR_NAMES)
                                            + " (default: all)")
    study.add_argument("--with-cycles", action="store_true",
                       help="also study Cycles, against its own reference")
    study.add_argument("--seeds", type=_seeds, default=STUDY_SEEDS, metavar="K",
                       help=f"renders per sample count, 2..{MAX_SEEDS} (default {STUDY_SEEDS})")
    study.add_argument("--resolution", type=_resolution, default=None, metavar="WxH",
                       help="image size in pixels (default: the file's size and percentage)")
    study.add_argument("--target", type=_target, default=DEFAULT_TARGET_RELMSE,
                       metavar="RELMSE", help=f"relMSE whose time to reach is reported "
                                              f"(default {DEFAULT_TARGET_RELMSE:g})")
    study.add_argument("--reference-samples", type=_samples, default=None, metavar="M",
                       help="samples per pixel of each reference (default: 16 x N)")
    study.add_argument("--reference", type=_integrator, default="path", metavar="NAME",
                       help="integrator of MC Engine's reference: path (default), or light where "
                            "path tracing misses caustics of point lamps")
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
    simply dropped; Python options are refused (this command runs no scripts).
    """
    unsupported = {"-P", "--python", "--python-expr", "-x", "--use-extension"}
    for arg in argv:
        if arg in unsupported:
            raise CliError(f"Blender option {arg} is not supported (see {PROG} render --help)")
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
    scene: str | None
    threads: int | None
    verbose: bool
    integrator: str | None = None
    depth: int | None = None
    branching: int | None = None
    sampler: str | None = None
    keep_partial: bool = False
    # -f, -a, -s, -e, -j in order (frames.plan_frames); empty: the file's current frame.
    frame_actions: tuple = ()
    overwrite: bool | None = None       # None: the file's render.use_overwrite
    placeholders: bool | None = None    # None: the file's render.use_placeholder

    @property
    def several_frames(self) -> bool:
        """Rendered through Blender's frame options: output names get frame digits."""
        return renders_several(self.frame_actions)


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


def _output_for(raw: str, forced_format: str | None, blend_dir: Path,
                several: bool = False) -> Output:
    """Resolve ``//`` and the format of one ``-o`` value (frame digits come later).

    With ``several`` frames, a file name without ``#`` gets Blender's four frame
    digits at its end, before the extension (``out`` -> ``out####.exr``).
    """
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
    if forced_format and by_extension and suffix != FORMATS[forced_format]:
        raise CliError(f"output {raw} has extension {suffix} but the format is {forced_format}")
    file_format = forced_format or by_extension or DEFAULT_FORMAT
    extension = pattern.suffix if by_extension else FORMATS[file_format]
    stem = pattern.name[:-len(extension)] if by_extension else pattern.name
    if several and "#" not in stem:
        stem += "####"
    return Output(pattern.with_name(stem + extension), file_format)


def check_output_folder(path: Path) -> None:
    """Raise CliError unless an image can be created at ``path`` (tested by writing).

    A symbolic link is followed: the file it points to is the one replaced.
    """
    folder = path.parent
    if not folder.exists():
        raise CliError(f"output folder does not exist: {folder}")
    if not folder.is_dir():
        raise CliError(f"output folder is not a folder: {folder}")
    if path.is_dir():
        raise CliError(f"output path is a folder: {path}")
    real = Path(os.path.realpath(path))
    for where in dict.fromkeys((folder, real.parent)):
        if not where.is_dir():
            raise CliError(f"output {path} is a link into a missing folder: {real}")
        try:
            with tempfile.TemporaryFile(dir=where):
                pass
        except OSError as exc:
            raise CliError(f"cannot write to output folder {where}: {_os_reason(exc)}") from None


def _same_file(a: Path, b: Path) -> bool:
    """Same real path (symbolic links followed) or same inode (hard links)."""
    if os.path.realpath(a) == os.path.realpath(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def check_output_paths(paths, blendfile: Path) -> None:
    """Raise CliError (exit 2) for output paths that must not be written.

    ``paths`` are final (frame digits substituted): none may be a folder,
    name the scene file itself (through a symbolic or hard link too), or be
    given twice.
    """
    seen = {}
    for path in paths:
        if path.is_dir():
            raise CliError(f"output path is a folder: {path}")
        if _same_file(path, blendfile):
            what = ("the scene file" if os.path.abspath(path) == os.path.abspath(blendfile)
                    else f"the scene file {blendfile} under another name (a link)")
            raise CliError(f"output {path} is {what}; rendering would overwrite the scene "
                           "(choose another -o)")
        real = os.path.realpath(path)
        if real in seen:
            raise CliError(f"output {path} is given twice" + (
                f" (as {seen[real]})" if str(seen[real]) != str(path) else ""))
        seen[real] = path


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


def check_folder_creatable(folder: Path) -> None:
    """Raise CliError unless ``folder`` exists and is writable, or can be created.

    Nothing is created here: the folder is made when the results are written,
    so a command that fails or is interrupted before leaves no empty folder.
    """
    if folder.exists() and not folder.is_dir():
        raise CliError(f"output path is not a folder: {folder}")
    existing = folder
    while not existing.exists():
        existing = existing.parent
    if not existing.is_dir():
        raise CliError(f"cannot create output folder {folder}: {existing} is not a folder")
    try:
        with tempfile.TemporaryFile(dir=existing):
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
    kind, value = args.resolution if args.resolution is not None else (None, None)
    if kind == "size" and min(value) < MIN_COMPARE_SIZE:
        raise CliError(f"resolution {value[0]}x{value[1]} is too small for the comparison's "
                       f"{MIN_COMPARE_SIZE}x{MIN_COMPARE_SIZE} block grid")
    out = Path(args.out if args.out is not None else default_out).absolute()
    check_folder_creatable(out)
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
    reference: str
    depth: int | None
    branching: int | None
    scene: str | None
    threads: int | None
    verbose: bool
    sampler: str | None = None


def _study_request(args) -> StudyRequest:
    blendfile = Path(args.blendfile).absolute()
    check_blend_file(blendfile)
    _check_integrator_options(args.integrators, args.depth, args.branching, sampler=args.sampler)
    if args.reference_samples is not None and args.reference_samples < max(
            2 * args.max_samples, REFERENCE_RENDERS):
        raise CliError(f"--reference-samples {args.reference_samples} is too few to measure "
                       f"errors against: use at least {max(2 * args.max_samples, REFERENCE_RENDERS)} "
                       f"(twice --max-samples), ideally 16 times")
    out = Path(args.out if args.out is not None else f"study-{blendfile.stem}").absolute()
    check_folder_creatable(out)
    return StudyRequest(
        blendfile=blendfile, out=out, max_samples=args.max_samples,
        integrators=args.integrators, with_cycles=args.with_cycles, seeds=args.seeds,
        resolution=args.resolution, target=args.target,
        reference_samples=args.reference_samples, reference=args.reference, depth=args.depth,
        branching=args.branching, scene=args.scene, threads=args.threads, verbose=args.verbose,
        sampler=args.sampler)


def parse_args(argv: list[str]) -> RenderRequest | CompareRequest | StudyRequest | None:
    """Validate the command line; None means help/version was printed."""
    if any(arg in ("-b", "--background") for arg in argv):
        argv = _blender_style(argv)
    parser = build_parser()
    if not argv:
        raise CliError(f"no command given (try '{PROG} render SCENE.blend' or '{PROG} --help')")
    try:
        args = parser.parse_args(_attach_frame_values(argv))
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
                              args.branching, engine, args.sampler)
    if args.keep_partial and engine != DEFAULT_ENGINE:
        raise CliError("--keep-partial applies to MC Engine renders only (a Cycles render "
                       "cannot be stopped part-way from Python)")
    actions = tuple(args.frame_actions)
    _check_frame_actions(actions, args)
    several = renders_several(actions)
    blendfile = Path(args.blendfile).absolute()
    check_blend_file(blendfile)
    default_name = f"{blendfile.stem}{'_####' if several else ''}"
    raw_outputs = args.outputs or [default_name + FORMATS[args.format or DEFAULT_FORMAT]]
    outputs = tuple(_output_for(raw, args.format, blendfile.parent, several)
                    for raw in raw_outputs)
    for output in outputs:
        check_output_folder(output.pattern)
    # The frames are known now if they are absolute numbers (or no name has '#');
    # otherwise the same check runs once the file is loaded (commands.run_render).
    absolute = all(a.kind == "frames" and all(not f.sign for pair in a.value for f in pair)
                   for a in actions)
    if absolute and actions:
        frames = plan_frames(actions, 0, 0, 1).frames
        check_output_paths([frame_path(o.pattern, f) for f in frames for o in outputs],
                           blendfile)
    elif not any("#" in o.pattern.name for o in outputs):
        check_output_paths([o.pattern for o in outputs], blendfile)
    return RenderRequest(
        blendfile=blendfile, engine=engine, outputs=outputs,
        samples=args.samples, resolution=args.resolution, seed=args.seed,
        scene=args.scene, threads=args.threads, verbose=args.verbose,
        integrator=args.integrator, depth=args.depth, branching=args.branching,
        sampler=args.sampler, keep_partial=args.keep_partial, frame_actions=actions,
        overwrite=args.overwrite, placeholders=args.placeholders)


def _check_frame_actions(actions, args) -> None:
    """-s, -e and -j act on the -a and -f after them; Overwrite/Placeholders need frames."""
    renders = [i for i, a in enumerate(actions) if a.kind in ("animation", "frames")]
    late = [a for i, a in enumerate(actions)
            if a.kind in ("start", "end", "step") and (not renders or i > renders[-1])]
    if late:
        option = {"start": "-s", "end": "-e", "step": "-j"}[late[0].kind]
        raise CliError(f"{option} changes the frames of the -a or -f after it, and none follows "
                       f"(Blender applies frame options in order: put {option} before -a/-f)")
    if not renders and (args.overwrite is not None or args.placeholders is not None):
        raise CliError("--overwrite and --placeholders apply to frames given with -f or -a")


def partial_path(path: Path) -> Path:
    """Where ``--keep-partial`` saves an interrupted render: ``shot.exr`` -> ``shot.partial.exr``."""
    return path.with_name(f"{path.stem}.partial{path.suffix}")
