"""How the command line fails: its name, its exit statuses and the one-line error.

Every failure is raised as :class:`CliError` and printed by ``main`` as one
line, ``mcengine: error: ...``, with the error's exit status.
"""
from __future__ import annotations

__all__ = ["PROG", "EXIT_OK", "EXIT_RENDER_FAILED", "EXIT_BAD_INPUT", "EXIT_DIFFER",
           "EXIT_INTERRUPTED", "EXIT_TERMINATED", "CliError"]

PROG = "mcengine"

EXIT_OK = 0
EXIT_RENDER_FAILED = 1
EXIT_BAD_INPUT = 2
EXIT_DIFFER = 3
EXIT_INTERRUPTED = 130      # SIGINT (Ctrl-C): 128 + 2, as shells report it
EXIT_TERMINATED = 143       # SIGTERM: 128 + 15


class CliError(Exception):
    """An error reported as one line; ``exit_code`` is the process exit status."""

    def __init__(self, message: str, exit_code: int = EXIT_BAD_INPUT):
        super().__init__(message)
        self.exit_code = exit_code
