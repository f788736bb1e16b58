"""What a script prints besides its own output: compiler messages silenced, a notice before the
first compilation.

- DOLFINx compiles the forms and elements of a scene with FFCx, which builds C extensions
  through cffi and setuptools; their "running build_ext", "building …" and gcc command lines
  go to the root :mod:`logging` logger at level INFO and reach stderr. They are dropped here
  unless asked for: :func:`show_compiler_output` (or ``DC_COMPILER_OUTPUT=1`` in the
  environment) lets them through. Warnings and errors of the compilers always pass.
- The element kernels are numba functions compiled once and cached on disk beside the
  package's sources; the first part of a kind in a fresh installation compiles its kernels
  (10–20 s a kind on one core; the set-up compiles them all). :func:`announce_compilation` says
  so on standard output (rank 0) before it starts.
"""
from __future__ import annotations

import glob
import logging
import os
import sys

__all__ = ["announce_compilation", "show_compiler_output"]

_PACKAGE = os.path.dirname(os.path.abspath(__file__))


class _CompilerMessages(logging.Filter):
    """Drops the build messages (below WARNING) that setuptools' distutils logs at the root logger."""

    def filter(self, record: logging.LogRecord) -> bool:
        if record.levelno >= logging.WARNING:
            return True
        path = record.pathname.replace("\\", "/")
        return not ("/distutils/" in path or "/setuptools/" in path or "/cffi/" in path)


_FILTER = _CompilerMessages()


def show_compiler_output(show: bool = True) -> None:
    """Let the compilers' build messages (FFCx's C extensions: gcc command lines) through to
    the root logger's handlers (``show=True``), or drop them again (``False``, the default)."""
    root = logging.getLogger()
    if show:
        root.removeFilter(_FILTER)
    elif _FILTER not in root.filters:
        root.addFilter(_FILTER)


def kernels_cached(kind: str = "*") -> bool:
    """Whether numba's cache of the element kernels of ``kind`` (a module of
    :mod:`dolfinx_corot.kernels`: 'beam3d', 'line2d', 'shell3d', 'membrane_quad'; '*': any) exists,
    beside the sources or under ``$NUMBA_CACHE_DIR``."""
    name = f"{kind}.vector_kernel_tabulate_*.nbi"
    if glob.glob(os.path.join(_PACKAGE, "kernels", "__pycache__", name)):
        return True
    cache = os.environ.get("NUMBA_CACHE_DIR")
    return bool(cache) and bool(glob.glob(os.path.join(cache, "**", "*dolfinx_corot*", "**", name), recursive=True))


def announce_compilation(kind: str = "*", stream=None) -> bool:
    """Say on standard output (rank 0 of ``MPI.COMM_WORLD``) that the element kernels of ``kind``
    are about to be compiled, when their cache is empty; returns whether it was."""
    if kernels_cached(kind):
        return False
    from mpi4py import MPI

    if MPI.COMM_WORLD.rank == 0:
        out = sys.stdout if stream is None else stream
        what = "the element kernels, once: about 40 s" if kind == "*" else \
            f"the {kind} element kernels, once: about 15 s"
        out.write(f"dolfinx_corot: compiling {what}\n")
        out.flush()
    return True
