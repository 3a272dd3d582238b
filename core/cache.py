"""Bounded, thread-safe caches for the solver's pure stages.

Each stage of the pipeline (kernel operator, basis, Galerkin matrix, gap vector, modes,
time solve) is a pure function of a few inputs. A :class:`StageCache` memoises one stage
on exactly those inputs, bounded both in items and in bytes, and counts how often the
stage was really evaluated, so tests can prove that a load slider never recomputes the
kernel matrix or the basis.

Keys are built with :func:`fingerprint`, which hashes numpy arrays by content (an object
with no content to hash goes in a key as :class:`SameObject`, never as its ``id()``). A
value is shared by every caller that gets it: its arrays are made read-only when it is
stored (:func:`freeze`), so a caller writing into one raises instead of changing the
answers of the next.
"""

from __future__ import annotations

import hashlib
import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable
from dataclasses import fields, is_dataclass
from typing import Any, TypeVar

import numpy as np

T = TypeVar("T")

_REGISTRY: dict[str, StageCache] = {}
_REGISTRY_LOCK = threading.Lock()


def fingerprint(*parts: Any) -> str:
    """A content hash of numbers, strings, tuples and numpy arrays (hex string).

    Floats are hashed by their exact bit pattern, arrays by dtype, shape and bytes.
    """
    h = hashlib.blake2b(digest_size=16)

    def feed(obj: Any) -> None:
        if isinstance(obj, np.ndarray):
            arr = np.ascontiguousarray(obj)
            h.update(b"A" + str(arr.dtype).encode() + str(arr.shape).encode())
            h.update(arr.tobytes())
        elif isinstance(obj, (tuple, list)):
            h.update(b"(" + str(len(obj)).encode())
            for item in obj:
                feed(item)
            h.update(b")")
        elif isinstance(obj, (float, np.floating)):
            h.update(b"f" + np.float64(obj).tobytes())
        elif isinstance(obj, (bool, int, np.integer, str)) or obj is None:
            h.update(b"s" + repr(obj).encode())
        else:
            raise TypeError(f"cannot fingerprint object of type {type(obj).__name__}")

    for part in parts:
        feed(part)
    return h.hexdigest()


class SameObject:
    """A cache key part equal only to one for the very same object (compared with ``is``).

    For values with no content to hash (a plain callable): unlike ``id(obj)``, it holds
    the object, so while the key is kept no other object can take over its id.
    """

    __slots__ = ("obj",)

    def __init__(self, obj: Any) -> None:
        self.obj = obj

    def __eq__(self, other: object) -> bool:
        return isinstance(other, SameObject) and other.obj is self.obj

    def __hash__(self) -> int:
        return id(self.obj)


def content_key(obj: Any) -> tuple[str, SameObject | None]:
    """How a cache knows ``obj`` (a creep kernel): a fingerprint of its content
    (``obj.key``) and None, or, where it has no key the fingerprint can hash, the object
    itself (:class:`SameObject`) beside ``fingerprint(None)``. Keyed by ``id()`` alone, a
    kernel freed and replaced by another at the same address handed the new one the old
    one's answers."""
    content = getattr(obj, "key", None)
    identity = SameObject(obj) if content is None and obj is not None else None
    try:
        return fingerprint(content), identity
    except TypeError:  # a key of objects the fingerprint does not know: the instance
        return fingerprint(None), SameObject(obj)


def freeze(value: T, depth: int = 0) -> T:
    """Make the numpy arrays of a cached value read-only, in place; returns ``value``.

    Looks into tuples, lists, dict values and dataclass fields (as :func:`_nbytes` does).
    A cached value is shared by every later caller: one that wrote into it (``+=``, a
    slice assignment, a LAPACK call with ``overwrite_a``) would change the answer of the
    next, so such a write raises instead.
    """
    if depth > 4:
        return value
    if isinstance(value, np.ndarray):
        value.setflags(write=False)
    elif isinstance(value, (tuple, list)):
        for item in value:
            freeze(item, depth + 1)
    elif isinstance(value, dict):
        for item in value.values():
            freeze(item, depth + 1)
    elif is_dataclass(value) and not isinstance(value, type):
        for f in fields(value):
            freeze(getattr(value, f.name, None), depth + 1)
    return value


def _nbytes(obj: Any, depth: int = 0) -> int:
    """Approximate memory held by a cached value (arrays dominate)."""
    if depth > 4:
        return 0
    if isinstance(obj, np.ndarray):
        return int(obj.nbytes)
    if isinstance(obj, (tuple, list)):
        return sum(_nbytes(o, depth + 1) for o in obj)
    if isinstance(obj, dict):
        return sum(_nbytes(o, depth + 1) for o in obj.values())
    if is_dataclass(obj):
        return sum(_nbytes(getattr(obj, f.name), depth + 1) for f in fields(obj))
    return 64


class StageCache:
    """LRU memo for one pipeline stage, bounded in items and bytes, safe across threads.

    Concurrent requests for the same key compute the value once: later callers wait for
    the first one instead of repeating the work.
    """

    def __init__(self, name: str, max_items: int = 32, max_bytes: int = 256 * 2**20,
                 sizeof: Callable[[Any], int] | None = None) -> None:
        """``max_bytes`` bounds the sum of ``sizeof(value)`` over the values held [bytes];
        ``sizeof`` defaults to the buffers of numpy arrays in tuples, dicts and
        dataclasses."""
        self.name = name
        self.max_items = max_items
        self.max_bytes = max_bytes
        self._sizeof = sizeof or _nbytes
        self._data: OrderedDict[Hashable, tuple[Any, int]] = OrderedDict()
        self._bytes = 0
        self._lock = threading.Lock()
        self._in_flight: dict[Hashable, threading.Event] = {}
        self.evaluations = 0
        self.hits = 0
        with _REGISTRY_LOCK:
            _REGISTRY[name] = self

    def get_or_compute(self, key: Hashable, compute: Callable[[], T]) -> tuple[T, bool]:
        """Return ``(value, was_cached)`` for ``key``, calling ``compute()`` on a miss."""
        while True:
            with self._lock:
                if key in self._data:
                    self._data.move_to_end(key)
                    self.hits += 1
                    return self._data[key][0], True
                event = self._in_flight.get(key)
                if event is None:
                    event = threading.Event()
                    self._in_flight[key] = event
                    break
            event.wait()
        try:
            value = compute()
        except BaseException:
            with self._lock:
                self._in_flight.pop(key, None)
            event.set()
            raise
        freeze(value)  # shared from now on: a caller's in-place write must not change it
        # measured outside the lock: sizing a large value takes milliseconds
        size = self._sizeof(value)
        with self._lock:
            self.evaluations += 1
            self._in_flight.pop(key, None)
            if size <= self.max_bytes:  # a value larger than the whole budget is not kept
                self._data[key] = (value, size)
                self._bytes += size
                while len(self._data) > self.max_items or self._bytes > self.max_bytes:
                    _, (_, dropped) = self._data.popitem(last=False)
                    self._bytes -= dropped
        event.set()
        return value, False

    def get(self, key: Hashable) -> Any | None:
        """The value held for ``key``, or None (nothing is computed)."""
        with self._lock:
            entry = self._data.get(key)
            if entry is None:
                return None
            self._data.move_to_end(key)
            self.hits += 1
            return entry[0]


    def resize(self, value: Any) -> None:
        """Measure ``value`` again, held under any key (by identity), after it grew in
        place (answers kept with a prepared geometry for later load changes), and drop
        the least recently used others while the budget is exceeded; a value grown
        larger than the whole budget is no longer kept. Nothing happens when the value is
        not held."""
        with self._lock:
            if not any(held is value for held, _ in self._data.values()):
                return
        size = self._sizeof(value)  # outside the lock, as on insertion
        with self._lock:
            key = next((k for k, (held, _) in self._data.items() if held is value), None)
            if key is None:
                return
            self._bytes += size - self._data[key][1]
            self._data[key] = (value, size)
            if size > self.max_bytes:
                del self._data[key]
                self._bytes -= size
            while self._bytes > self.max_bytes:
                oldest = next(iter(self._data))
                if oldest == key:  # the grown value was just used: keep it, drop others
                    self._data.move_to_end(key)
                    oldest = next(iter(self._data))
                _, dropped = self._data.pop(oldest)
                self._bytes -= dropped

    def values(self) -> list[Any]:
        """A snapshot of the values held, least recently used first."""
        with self._lock:
            return [value for value, _ in self._data.values()]

    def clear(self) -> None:
        """Drop every cached value (the counters are kept)."""
        with self._lock:
            self._data.clear()
            self._bytes = 0

    @property
    def size_bytes(self) -> int:
        """Bytes currently held (approximate)."""
        return self._bytes

    def __len__(self) -> int:
        return len(self._data)


class KeptValues:
    """What one object keeps for its own later use (the time-stepped responses of a
    prepared geometry, q at points asked for before), least recently used first, bounded
    in items and bytes; the newest value is always kept. Not shared across the process
    (no registry, no counters) and not locked: its owner holds its own lock around it."""

    def __init__(self, max_items: int, max_bytes: int,
                 sizeof: Callable[[Any], int] | None = None) -> None:
        self.max_items = max_items
        self.max_bytes = max_bytes
        self._sizeof = sizeof or _nbytes
        self._data: OrderedDict[Hashable, tuple[Any, int]] = OrderedDict()
        self.nbytes = 0

    def get(self, key: Hashable) -> Any | None:
        """The value kept for ``key`` (now the most recently used), or None."""
        entry = self._data.get(key)
        if entry is None:
            return None
        self._data.move_to_end(key)
        return entry[0]

    def put(self, key: Hashable, value: Any) -> list[Any]:
        """Keep ``value`` under ``key``; the values dropped to stay within the bounds."""
        old = self._data.pop(key, None)
        if old is not None:
            self.nbytes -= old[1]
        size = int(self._sizeof(value))
        self._data[key] = (value, size)
        self.nbytes += size
        dropped = []
        while len(self._data) > 1 and (len(self._data) > self.max_items
                                       or self.nbytes > self.max_bytes):
            _, (gone, gone_size) = self._data.popitem(last=False)
            self.nbytes -= gone_size
            dropped.append(gone)
        return dropped

    def drop(self, keep: Callable[[Hashable], bool]) -> None:
        """Drop every value whose key ``keep`` refuses."""
        for key in [k for k in self._data if not keep(k)]:
            self.nbytes -= self._data.pop(key)[1]

    def values(self) -> list[Any]:
        """The values kept, least recently used first."""
        return [value for value, _ in self._data.values()]

    def clear(self) -> None:
        self._data.clear()
        self.nbytes = 0

    def __contains__(self, key: Hashable) -> bool:
        return key in self._data

    def __len__(self) -> int:
        return len(self._data)


def stage_counts() -> dict[str, int]:
    """Number of real evaluations of every stage since start (cache hits not counted)."""
    with _REGISTRY_LOCK:
        return {name: cache.evaluations for name, cache in _REGISTRY.items()}


def cache_report() -> dict[str, dict[str, int]]:
    """Per stage: evaluations, hits, items and bytes held."""
    with _REGISTRY_LOCK:
        return {
            name: {
                "evaluations": c.evaluations,
                "hits": c.hits,
                "items": len(c),
                "bytes": c.size_bytes,
            }
            for name, c in _REGISTRY.items()
        }


def clear_caches() -> None:
    """Empty every stage cache of this process (tests and benchmarks measuring cold solves;
    the explorer's server once idle, explorer/solving/idle_release.py)."""
    with _REGISTRY_LOCK:
        caches = list(_REGISTRY.values())
    for cache in caches:
        cache.clear()
