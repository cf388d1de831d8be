"""Keep numba's on-disk cache of the compiled kernels consistent with their sources.

numba invalidates a cached function when the file that defines it changes,
but a cached kernel also embeds the compiled code of the kernels it calls
from other files, and those changes go unnoticed (numba's documentation on
``cache=True``). Worse, two cached libraries that embed different versions
of one callee export the same symbol, and in a process that loads both, the
first one loaded serves both: the biped's integrator once ran the TSLIP's
older five-component dense output after a TSLIP Floquet computation had
loaded a stale cached kernel, and fell in its first stride.

So every kernel module calls :func:`check` once at import, before any kernel
runs: the cache directory of the module carries a marker with a hash of all
kernel sources (:data:`SOURCES`), and entries written under another hash
are deleted (they are recompiled on first use). Concurrent imports (spawned
workers) at worst delete each other's fresh entries, which costs a compile.

A first run waits for numba to compile the kernels. :data:`FAMILIES` names
the groups a user waits for, each by the numba index files of its kernels,
and :func:`missing_families` tells from a cache folder (the kernels'
:func:`cache_dirs`) which have no entry yet, so that a run can say so before
it starts compiling.
"""

from __future__ import annotations

import functools
import hashlib
import os
from collections.abc import Mapping
from pathlib import Path

__all__ = ["FAMILIES", "SOURCES", "check", "missing_families", "sources_hash"]

_ROOT = Path(__file__).parent

#: Package files whose code is compiled into the kernels (njit functions, the
#: layout constants they read); a test
#: checks that every module defining or feeding a kernel is listed.
SOURCES: tuple[str, ...] = (
    "model/_pack.py", "simulation/_rk.py", "simulation/_stance.py",
    "simulation/_flight.py", "simulation/_stepper.py", "simulation/_stride.py",
    "simulation/_sincos.py", "simulation/_record.py", "simulation/_kernels.py",
    "simulation/_variational.py",
    "biped/_pack.py", "biped/_jit.py", "biped/_tmt.py", "biped/_control.py", "biped/_contact.py",
    "biped/_rhs.py", "biped/_events.py", "biped/_stride.py", "biped/_kernels.py", "_nrt.py",
    "spatial/_kernels.py", "spatial/_trunk_kernels.py", "spatial/_trunk_stride.py",
    "spatial/_trunk_variational.py",
)


@functools.cache
def sources_hash() -> str:
    """SHA-256 of the kernel sources (with numba's version); computed once a process."""
    import numba

    h = hashlib.sha256(numba.__version__.encode())
    for rel in SOURCES:
        h.update(rel.encode())
        h.update((_ROOT / rel).read_bytes())
    return h.hexdigest()


def check(dispatcher: object, module_file: str) -> None:
    """Delete the cached kernels of ``module_file`` if they predate the sources.

    ``dispatcher`` is any ``cache=True`` kernel of that module (it tells
    where numba keeps the module's cache, which ``NUMBA_CACHE_DIR`` moves).
    Never raises: a cache that cannot be checked is left to numba.
    """
    try:
        cache_dir = Path(dispatcher._cache.cache_path)  # type: ignore[attr-defined]
        stem = Path(module_file).stem
        marker = cache_dir / f"{stem}.tslip-sources"
        digest = sources_hash()
        if marker.is_file() and marker.read_text() == digest:
            return
        for f in cache_dir.glob(f"{stem}.*.nb[ic]"):
            f.unlink(missing_ok=True)
        cache_dir.mkdir(parents=True, exist_ok=True)
        tmp = marker.with_name(f"{marker.name}.{os.getpid()}.tmp")
        tmp.write_text(digest)
        os.replace(tmp, marker)
    except (OSError, AttributeError, TypeError):  # TypeError: a kernel without cache=True
        return


#: The kernel families a first run compiles, as a user would name them: each
#: its subpackage and the kernels (``module.function`` as numba names their
#: index files ``module.function-LINE.pyXY.nbi``) that must all be cached.
#: Measured: the kernels each workload of :mod:`tslip.sweeps._warmup` compiles
#: that no other family compiles (their callees are cached with them). The TSLIP's
#: strides (the stride kernel and a run of strides) are the one part both the gait
#: search and the recorded runs call: a family of their own, compiled first, so that
#: neither waits for the other whole (numba's compile events, 2026-12-06). The
#: biped's family (one stride loop for both Runge-Kutta pairs) also holds the
#: helpers Appendix E calls from Python
#: (body kinematics, controller references), which workers compiled otherwise.
FAMILIES: dict[str, tuple[str, tuple[str, ...]]] = {
    "TSLIP strides": ("simulation", ("_stride.stride", "_stride.run_row")),
    "TSLIP gait search and analyses": ("simulation", (
        "_stride.section_map", "_variational.stride_jacobian", "_flight.alpha_r_column")),
    "TSLIP recorded runs": ("simulation", (
        "_record.record_run", "_stride.run_batch_serial", "_flight.flight_state")),
    "biped": ("biped", ("_stride._integrate", "_tmt.kinematics", "_control.references")),
    "3-D spring-mass runner": ("spatial", ("_kernels.stance",)),
    "3-D TSLIP": ("spatial", ("_trunk_stride.stride", "_trunk_variational.run_phase_var")),
}


def missing_families(dirs: Mapping[str, Path], digest: str | None = None,
                     families: Mapping[str, tuple[str, tuple[str, ...]]] | None = None,
                     ) -> list[str]:
    """The ``families`` (default :data:`FAMILIES`) with a kernel not cached in ``dirs``.

    ``dirs`` maps subpackages to their cache folders
    (:func:`tslip.sweeps._warmup.cache_dirs`);
    families of other subpackages are left out.
    With ``digest`` (:func:`sources_hash`), a kernel counts as cached only if
    its module's marker holds that digest (else :func:`check` deletes it).
    Reads file names only: a pure function of the folders' contents.
    """
    out = []
    for name, (package, kernels) in (FAMILIES if families is None else families).items():
        if package not in dirs:
            continue
        folder = Path(dirs[package])
        for kernel in kernels:
            stem = kernel.split(".")[0]
            marker = folder / f"{stem}.tslip-sources"
            stale = digest is not None and (not marker.is_file() or marker.read_text() != digest)
            if stale or not any(folder.glob(f"{kernel}-*.nbi")):
                out.append(name)
                break
    return out
