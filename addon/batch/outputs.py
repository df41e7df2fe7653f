"""Files written for the user: never half-written, never over what they must not replace.

Every image and report goes first to a temporary file in the folder of its
target (so that the final rename stays on one file system), is read back and
checked (:func:`verify`: an EXR is decoded with OpenEXR, a PNG checked chunk
by chunk and decompressed), and only then renamed over the target with
``os.replace``, which is atomic.  A render that fails or is interrupted,
or a disk that fills up, therefore leaves the previous file as it was.
Blender does not report write errors (``save_render`` and ``write_still``
return normally after a short write), which is why the files are read back.

* :class:`Staging` holds the temporary files of one command's outputs and
  removes what it did not commit;
* :func:`staged_folder` does the same for a folder of files written by a
  Python writer (a comparison's report, a study);
* :data:`COMMIT_LOCK` is held while files are renamed into place: the
  command line's signal handler takes it before it ends the process, so an
  exit never falls between the renames of one command's outputs;
* :func:`pending` lists the temporary files and folders in flight, and
  :func:`remove_pending` removes them, as that handler does before it ends the
  process;
* :func:`touch_placeholder` creates Blender's placeholder for a frame being
  rendered (an empty file at the target, so that other machines rendering
  the same animation skip the frame); :func:`remove_placeholder` removes it
  if it is still empty once the frame is abandoned, and so does
  :func:`remove_pending`.  Committing a target takes its placeholder off the
  list (both under :data:`COMMIT_LOCK`).

A symbolic link as target is followed (the file it points to is replaced, as
a plain write would do).  No bpy here.
"""
from __future__ import annotations

import contextlib
import os
import secrets
import shutil
import stat
import struct
import threading
import zlib
from pathlib import Path

__all__ = ["OutputError", "COMMIT_LOCK", "pending", "remove_pending", "touch_placeholder",
           "remove_placeholder", "Staging", "staged_folder", "write_folder", "verify",
           "verify_exr", "verify_png", "resolve", "same_file", "TEMP_MARK"]

# Temporary files are named ".NAME.mcengine-XXXXXXXX.tmp" next to their target.
TEMP_MARK = ".mcengine-"

COMMIT_LOCK = threading.RLock()
_pending_lock = threading.Lock()
_pending: set[Path] = set()
_placeholders: set[Path] = set()    # empty files this process created at targets

PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"
# PNG colour type -> channels.
_PNG_CHANNELS = {0: 1, 2: 3, 3: 1, 4: 2, 6: 4}


class OutputError(Exception):
    """A file could not be written or checked; the message is one line for the user."""


def pending() -> list[Path]:
    """Temporary files and folders not yet committed or removed (any thread may call)."""
    with _pending_lock:
        return list(_pending)


def remove_pending() -> None:
    """Remove the temporary files and folders in flight, and the placeholders still empty."""
    for path in pending():
        if path.is_dir():
            shutil.rmtree(path, ignore_errors=True)
        else:
            with contextlib.suppress(OSError):
                path.unlink()
    with _pending_lock:
        placeholders = list(_placeholders)
    for path in placeholders:
        remove_placeholder(path)


def touch_placeholder(target) -> Path | None:
    """Create an empty file at ``target`` if nothing is there (Blender's Placeholders).

    Returns the file created (symbolic links followed), or None if the target
    existed.  Raises OutputError if it cannot be created.
    """
    real = resolve(target)
    try:
        fd = os.open(real, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
    except FileExistsError:
        return None
    except OSError as exc:
        raise OutputError(f"cannot create the placeholder {real}: {_reason(exc)}") from None
    os.close(fd)
    with _pending_lock:
        _placeholders.add(real)
    return real


def remove_placeholder(path) -> None:
    """Remove a placeholder made by :func:`touch_placeholder` unless something was written
    into it or over it since (then it is only forgotten)."""
    path = Path(path)
    with COMMIT_LOCK:
        with _pending_lock:
            if path not in _placeholders:
                return
            _placeholders.discard(path)
        with contextlib.suppress(OSError):
            if path.stat().st_size == 0:
                path.unlink()


def _track(path: Path) -> None:
    with _pending_lock:
        _pending.add(path)


def _untrack(path: Path) -> None:
    with _pending_lock:
        _pending.discard(path)


def resolve(path) -> Path:
    """The file a write to ``path`` would change: symbolic links followed."""
    return Path(os.path.realpath(path))


def same_file(a, b) -> bool:
    """True if ``a`` and ``b`` are the same file: same real path, or same inode (hard links)."""
    if resolve(a) == resolve(b):
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _reason(exc: OSError) -> str:
    return exc.strerror or str(exc)


def _temp_file(target: Path) -> Path:
    """Create an empty temporary file next to ``target`` (mode from the umask)."""
    for _ in range(100):
        path = target.with_name(f".{target.name}{TEMP_MARK}{secrets.token_hex(4)}.tmp")
        try:
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)
        except FileExistsError:
            continue
        _track(path)
        os.close(fd)
        return path
    raise OutputError(f"cannot create a temporary file in {target.parent}")


def _keep_mode(temp: Path, target: Path) -> None:
    """Give ``temp`` the permissions of the file it replaces (if there is one)."""
    with contextlib.suppress(OSError):
        os.chmod(temp, stat.S_IMODE(os.stat(target).st_mode))


class Staging:
    """Temporary files for a set of targets, committed together or not at all.

    ``temp(target)`` creates the temporary file to write ``target`` to;
    ``commit()`` renames every temporary file over its target; leaving the
    ``with`` block removes whatever was not committed.
    """

    def __init__(self):
        self._files: list[tuple[Path, Path]] = []    # (temporary, real target)

    def __enter__(self) -> "Staging":
        return self

    def __exit__(self, *exc) -> None:
        self.discard()

    def temp(self, target) -> Path:
        real = resolve(target)
        try:
            temp = _temp_file(real)
        except OSError as exc:
            raise OutputError(f"cannot write to {real.parent}: {_reason(exc)}") from None
        self._files.append((temp, real))
        return temp

    def commit(self) -> None:
        """Rename every temporary file over its target (under :data:`COMMIT_LOCK`)."""
        with COMMIT_LOCK:
            for temp, target in self._files:
                _keep_mode(temp, target)
                try:
                    os.replace(temp, target)
                except OSError as exc:
                    raise OutputError(f"cannot write {target}: {_reason(exc)}") from None
                _untrack(temp)
                with _pending_lock:
                    _placeholders.discard(target)   # the image replaced it
            self._files = []

    def discard(self) -> None:
        """Remove the temporary files that were not committed."""
        for temp, _target in self._files:
            with contextlib.suppress(OSError):
                temp.unlink()
            _untrack(temp)
        self._files = []


@contextlib.contextmanager
def staged_folder(folder):
    """Write a folder's files in a hidden folder inside it, then move them into place.

    Yields the staging folder; the caller's writer fills it.  When the block
    ends without an exception, every file is checked (:func:`verify`) and
    renamed into ``folder`` (created if missing) under :data:`COMMIT_LOCK`.
    The staging folder is always removed, so a failed or interrupted writer
    leaves ``folder`` as it was (a folder created for nothing is removed).
    """
    folder = Path(folder)
    created = not folder.exists()
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create {folder}: {_reason(exc)}") from None
    stage = None
    for _ in range(100):
        candidate = folder / f"{TEMP_MARK}{secrets.token_hex(4)}.tmp"
        try:
            candidate.mkdir()
        except FileExistsError:
            continue
        except OSError as exc:
            raise OutputError(f"cannot write to {folder}: {_reason(exc)}") from None
        stage = candidate
        break
    if stage is None:
        raise OutputError(f"cannot create a temporary folder in {folder}")
    _track(stage)
    committed = False
    try:
        yield stage
        names = sorted(p.name for p in stage.iterdir())
        for name in names:
            try:
                verify(stage / name)
            except OutputError as exc:
                raise OutputError(f"cannot write {folder / name}: the file written is {exc} "
                                  "(is the disk full?)") from None
        with COMMIT_LOCK:
            for name in names:
                _keep_mode(stage / name, folder / name)
                try:
                    os.replace(stage / name, folder / name)
                except OSError as exc:
                    raise OutputError(f"cannot write {folder / name}: {_reason(exc)}") from None
        committed = True
    finally:
        shutil.rmtree(stage, ignore_errors=True)
        _untrack(stage)
        if created and not committed:
            with contextlib.suppress(OSError):
                folder.rmdir()      # only if still empty


def write_folder(write, result, folder) -> dict:
    """``write(result, staging_folder)`` through :func:`staged_folder`, for the writers of
    :mod:`mcengine.evaluation.output`; returns their name -> path with ``folder`` as parent."""
    from mcengine.imageio import ImageError
    folder = Path(folder)
    with staged_folder(folder) as stage:
        try:
            paths = write(result, stage)
        except (OSError, ImageError) as exc:
            reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
            raise OutputError(f"cannot write the files of {folder}: {reason}") from None
    return {name: folder / Path(path).name for name, path in paths.items()}


# ---------------------------------------------------------------------------
# Checking what was written
# ---------------------------------------------------------------------------

def verify(path, file_format: str | None = None) -> tuple[int, int] | None:
    """Raise OutputError unless ``path`` holds a complete file of its format.

    ``file_format`` is "OPEN_EXR", "OPEN_EXR_MULTILAYER" or "PNG" (default: from the
    extension; other files are only checked to be non-empty).  Returns (width, height) of an
    image.  The error's message says what the file is instead, as a noun
    phrase ("an incomplete EXR file"), for the caller's sentence.
    """
    path = Path(path)
    if file_format is None:
        file_format = {".exr": "OPEN_EXR", ".png": "PNG"}.get(path.suffix.lower())
    try:
        size = path.stat().st_size
    except OSError as exc:
        raise OutputError(f"missing ({_reason(exc)})") from None
    if size == 0:
        raise OutputError("an empty file")
    if file_format == "OPEN_EXR":
        return verify_exr(path)
    if file_format == "OPEN_EXR_MULTILAYER":
        return verify_exr_layers(path)
    if file_format == "PNG":
        return verify_png(path)
    return None


def verify_exr(path) -> tuple[int, int]:
    """Decode the whole EXR (OpenEXR, through ``mcengine.imageio.read_exr``)."""
    from mcengine.imageio import ImageError, read_exr
    try:
        image = read_exr(path)
    except ImageError:
        raise OutputError("an incomplete or unreadable EXR file") from None
    return image.shape[1], image.shape[0]


def verify_exr_layers(path) -> tuple[int, int]:
    """Decode every layer and pass of a multilayer (multi-part) EXR."""
    from mcengine.imageio import ImageError, read_exr_layers
    try:
        layers = read_exr_layers(path)
    except ImageError:
        raise OutputError("an incomplete or unreadable EXR file") from None
    first = next(iter(layers.values()))
    return first.shape[1], first.shape[0]


def verify_png(path) -> tuple[int, int]:
    """Check a PNG's signature, every chunk's CRC, IHDR, and that its IDAT data
    decompresses to exactly the rows IHDR announces; nothing after IEND."""
    try:
        data = Path(path).read_bytes()
    except OSError as exc:
        raise OutputError(f"unreadable ({_reason(exc)})") from None

    def bad(why: str) -> OutputError:
        return OutputError(f"an incomplete or unreadable PNG file ({why})")

    if not data.startswith(PNG_SIGNATURE):
        raise bad("no PNG signature")
    pos, header, idat, ended = len(PNG_SIGNATURE), None, [], False
    while pos < len(data):
        if pos + 12 > len(data):
            raise bad("truncated chunk")
        length, tag = struct.unpack(">I4s", data[pos:pos + 8])
        end = pos + 12 + length
        if end > len(data):
            raise bad(f"truncated {tag.decode('latin-1')} chunk")
        body = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[end - 4:end])
        if zlib.crc32(tag + body) & 0xFFFFFFFF != crc:
            raise bad(f"bad CRC in {tag.decode('latin-1')}")
        if tag == b"IHDR":
            header = struct.unpack(">IIBBBBB", body)
        elif tag == b"IDAT":
            idat.append(body)
        elif tag == b"IEND":
            ended = end == len(data)
            if not ended:
                raise bad("data after IEND")
        pos = end
    if header is None or not idat or not ended:
        raise bad("missing " + ("IHDR" if header is None else "IDAT" if not idat else "IEND"))
    width, height, depth, colour, _, _, interlace = header
    channels = _PNG_CHANNELS.get(colour)
    if channels is None or width == 0 or height == 0:
        raise bad("invalid header")
    try:
        raw = zlib.decompress(b"".join(idat))
    except zlib.error:
        raise bad("corrupt image data") from None
    if interlace == 0 and len(raw) != height * (1 + (width * channels * depth + 7) // 8):
        raise bad("image data of the wrong size")
    return width, height
