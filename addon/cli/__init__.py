"""Command line: render a .blend file headless with MC Engine or Cycles, compare the two,
or study what accuracy costs in time.

Two spellings take the same options::

    mcengine render SCENE.blend [--engine mcengine|cycles] [--samples N] [--resolution WxH]
                                [--seed S] [-f FRAMES | -s F -e F -j N -a]
                                [--[no-]overwrite] [--[no-]placeholders]
                                [-o OUT.exr|OUT.png ...] [-F FORMAT]
                                [--integrator path|raycast|whitted|distribution]
                                [--depth R] [--branching B]
    mcengine -b SCENE.blend -E MCENGINE -o /tmp/out_#### -F OPEN_EXR -f 1,3,5..7

The second one is Blender's own background-render syntax (``-b -E -o -f -a -s -e
-j -F -S -t`` and their long forms), so ``blender -b`` scripts carry over
unchanged; frame options act in order, as in Blender (see ``frames``).

``compare`` renders a scene with both engines and tests whether they agree
(see ``mcengine_blender.batch.comparison`` and ``mcengine.evaluation``)::

    mcengine compare SCENE.blend [--samples N] [--resolution WxH|P%] [--seeds K] [--out DIR]
    mcengine compare --suite FOLDER [same options]      # every .blend in FOLDER, one summary

``study`` renders a ladder of sample counts with each integrator (and Cycles)
and reports error against time (see ``mcengine_blender.batch.study`` and
``mcengine.evaluation.study``)::

    mcengine study SCENE.blend [--out DIR] [--max-samples N] [--integrators path,raycast,...]
                               [--with-cycles] [--seeds K] [--resolution WxH]
                               [--depth R] [--branching B] [--target RELMSE]

Conventions
-----------
* Every argument, the input file (its magic bytes) and the output folders are
  checked before ``bpy`` is imported, so bad input fails in well under a second.
  What needs the loaded file (an unknown ``-S`` scene; an output whose ``#``
  frame digits make it a folder or the scene file) is found after loading,
  before rendering, with the same exit status 2.
* Failures are one line on stderr, ``mcengine: error: ...``, never a traceback.
  Exit status: 0 rendered, 1 the render (or file loading, or saving) failed,
  2 bad input, 130 interrupted (SIGINT, Ctrl-C), 143 terminated (SIGTERM);
  ``compare`` exits 0 when the engines agree and 3 when they differ (1 and 2 as
  above; in a suite, any failed scene gives 1, else any difference 3).
* Outputs are atomic (``batch.outputs``): written to a temporary file in the
  target's folder, read back and checked, then renamed over the target, all
  outputs of a command together.  A failed or interrupted command leaves what
  was there; an output that is the scene file itself is refused (exit 2).
* SIGINT and SIGTERM only set a flag (``signals``, ``batch.interrupt``): the
  command stops at the next safe point, an MC Engine render within a tenth of
  a second; what cannot stop in order within half a second (a Cycles render,
  Blender loading) is ended by the command itself after removing its
  temporary files.  Temporary files live in a folder of the command's own in
  ``$TMPDIR``, Blender's included, removed at exit.
* Output paths follow Blender: ``//`` is the .blend file's folder, the last run
  of ``#`` in the file name becomes the zero-padded frame number, and the
  format's extension is appended when the name has none; when several frames
  can render, a name without ``#`` gets four frame digits.  ``-o`` may be given
  several times to save the same render in several formats.
* Frames given with ``-f``/``-a`` follow Output > Overwrite and Placeholders as
  Blender's animation render does (skip frames whose images exist; an empty
  file while a frame renders).  Each frame is committed and its paths printed
  as soon as it is rendered; stderr gets one line per frame.
* Overrides change this render only, never the file.  Samples go to
  ``scene.cycles.samples`` and the seed to ``scene.cycles.seed`` (MC Engine reads
  Cycles' sampling settings); ``--resolution`` sets x, y and 100 %.
* EXR output is OPEN_EXR, 32-bit float RGBA, scene-linear, with the file's EXR
  codec; OPEN_EXR_MULTILAYER (``-F``) writes every render pass of every view
  layer, 32-bit float, with the render's metadata (statistics, Cryptomatte
  manifests); PNG output is 8-bit RGBA through the file's view transform.
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

Layout
------
* ``args``: the parser, the validators and the requests they produce (no bpy);
* ``frames``: Blender's frame options and frame-numbered names (no bpy);
* ``console``: Blender's log captured, the progress display;
* ``commands``: what ``render``, ``compare`` and ``study`` do (bpy from here on);
* ``signals``: SIGINT and SIGTERM, the temporary folder, ending early and cleanly;
* ``errors``: the program name, the exit statuses and the one-line error;
* ``main`` (here) ties them together; ``python -m mcengine_blender.cli`` and
  the ``mcengine`` console script both call it.
"""
from __future__ import annotations

import sys
import traceback

# Only light modules here: main installs the signal handlers before numpy,
# bpy or numba are imported (by .args and .commands).
from ..batch.interrupt import Interrupted, requested
from . import signals
from .errors import EXIT_OK, EXIT_RENDER_FAILED, PROG, CliError

__all__ = ["main"]


def main(argv: list[str] | None = None) -> int:
    """Console entry point; returns the exit status.

    Without ``argv`` (the ``mcengine`` process itself) the signal handlers stay
    installed until the process exits; with it (a caller in Python) the
    previous handlers are put back.
    """
    with signals.handling(restore=argv is not None):
        argv = sys.argv[1:] if argv is None else argv
        return _run(argv)


def _run(argv: list[str]) -> int:
    verbose = "--verbose" in argv
    try:
        from .args import CompareRequest, StudyRequest, parse_args
        request = parse_args(argv)
        if request is None:
            return EXIT_OK
        from .commands import run_compare, run_render, run_study
        if isinstance(request, CompareRequest):
            return run_compare(request)
        if isinstance(request, StudyRequest):
            return run_study(request)
        return run_render(request)
    except Interrupted as exc:
        return _interrupted(exc.signum)
    except CliError as exc:
        if requested() is not None:     # the failure came from stopping
            return _interrupted(requested())
        print(f"{PROG}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except Exception as exc:  # last resort: still one line unless asked for details
        if requested() is not None:
            return _interrupted(requested())
        if verbose:
            traceback.print_exc()
        print(f"{PROG}: error: internal error: {type(exc).__name__}: {exc} "
              "(run with --verbose for the traceback)", file=sys.stderr)
        return EXIT_RENDER_FAILED


def _interrupted(signum: int) -> int:
    signals.announce(signum)
    return signals.exit_status(signum)
