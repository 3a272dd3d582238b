"""Bounds on the memory of the processes that do a server's work.

A solver worker and a study's process each get a bound on their address space (POSIX
``RLIMIT_AS``), so that no scene, study or download can take the machine: past the bound
an allocation raises ``MemoryError`` in that process alone, and the page is told so. The
bounds are far above what the work needs (measured below): they are a backstop behind the
input limits of ``core/SCENES.md``, not the limits themselves.

Nothing here imports Panel.
"""

from __future__ import annotations

from core.work import address_space_bound

#: The address space of a solver worker [bytes]: a worker that has written both reports
#: (HoloViews, Bokeh and Matplotlib loaded) maps ~1.7 GiB with ~0.3 GiB resident, the FE
#: coating check it runs peaks at ~1.6 GiB mapped (0.5 GiB resident; the default and
#: worn-coating presets), and it holds its share of the stage caches
#: (``core.STAGE_CACHE_BYTES`` divided among the workers).
WORKER_MEMORY_BYTES = 4 * 1024**3
#: The address space of a study's process [bytes]: 400 points of the young-concrete
#: preset (200 output times) peaked at 1.09 GiB mapped, 0.71 GiB resident; 100 points at
#: 2000 output times at 1.14 GiB.
STUDY_MEMORY_BYTES = 2 * 1024**3


def out_of_memory(what: str, work_bytes: int, advice: str) -> str:
    """What the page says when ``what`` needed more than its bound (of ``work_bytes``
    [bytes] of work)."""
    return (f"{what} needed more than the {address_space_bound(work_bytes) / 1024**3:.3g} "
            f"GiB of memory it may take on this server; {advice}")


#: A worker gives the memory its work freed back to the system
#: (``core.release_freed_memory``) after a request that took at least this long [s] (an
#: FE coating check, a fit, a slow solve): glibc keeps freed heap pages for reuse, so a
#: worker that ran three FE checks stayed at 345 MiB resident where it had started at 180,
#: and went back to 187 MiB once trimmed. The trim costs ~70 ms after an FE check and
#: under 1 ms after ordinary solves; it runs after the answer is sent, and only when no
#: request waits.
RELEASE_AFTER_S = 1.0
