"""Optional C code generation of the stage functions, compiled once and cached on disk.

CasADi's virtual machine evaluates the stage Hessians about an order of magnitude slower
than the same expressions compiled to C. :func:`compile_functions` generates one C file for
a set of CasADi Functions, compiles it with the system C compiler (``gcc -O1``) into a shared
library whose name is the SHA-256 of the source, and loads the functions back with
``casadi.external``. A later call with identical expressions (same model, same ``dt``) reuses
the library, so the compile cost is paid once per model. Without a compiler, or if
compilation fails, the original (virtual-machine) functions are returned unchanged.
"""

from __future__ import annotations

import hashlib
import logging
import shutil
import subprocess
import tempfile
from pathlib import Path

import casadi as ca

from auvplan.optimization._kernel_cache import cache_root

__all__ = ["compile_functions", "default_cache_dir"]

logger = logging.getLogger(__name__)


def default_cache_dir() -> Path:
    """The ``casadi`` folder of the cache root (:func:`~._kernel_cache.cache_root`)."""
    return cache_root() / "casadi"


def compile_functions(
    functions: dict[str, ca.Function], cache_dir: Path | None = None
) -> dict[str, ca.Function]:
    """Compile CasADi Functions to one shared library (cached) and load them as externals.

    Parameters
    ----------
    functions : dict of str to casadi.Function
        Functions with distinct names.
    cache_dir : Path, optional
        Where the C source and the shared library live; default :func:`default_cache_dir`.

    Returns
    -------
    dict of str to casadi.Function
        Compiled equivalents (same keys), or the inputs when no C compiler works.
    """
    compiler = shutil.which("gcc") or shutil.which("cc")
    if compiler is None:
        logger.warning("no C compiler found: stage functions stay in CasADi's virtual machine")
        return functions
    generator = ca.CodeGenerator("auvplan_stage.c", {"with_header": False})
    for function in functions.values():
        generator.add(function)
    source = generator.dump()
    digest = hashlib.sha256(source.encode("utf-8")).hexdigest()[:24]
    directory = default_cache_dir() if cache_dir is None else Path(cache_dir)
    library = directory / f"auvplan_{digest}.so"
    if not library.exists():
        try:
            directory.mkdir(parents=True, exist_ok=True)
            with tempfile.TemporaryDirectory(dir=directory) as scratch:
                c_file = Path(scratch) / f"auvplan_{digest}.c"
                c_file.write_text(source, encoding="utf-8")
                built = Path(scratch) / library.name
                logger.info("compiling stage functions to %s (one-off)", library)
                subprocess.run(
                    [compiler, "-O1", "-fPIC", "-shared", str(c_file), "-o", str(built), "-lm"],
                    check=True,
                    capture_output=True,
                )
                built.replace(library)  # atomic: concurrent builders never see a partial file
        except (OSError, subprocess.CalledProcessError) as error:
            logger.warning("compiling stage functions failed (%s): using the CasADi VM", error)
            return functions
    return {key: ca.external(function.name(), str(library)) for key, function in functions.items()}
