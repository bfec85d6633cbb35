"""One cache for everything the app computes, bounded in bytes, least recently used out first.

Every result of :mod:`app.results.compute`, :mod:`app.results.resonance`,
:mod:`app.results.verdicts` and the dashboard's views is kept here by its key — the kind of
result, the parameter set's full hash (strength data included), the case record
(:mod:`app.results.case`) and the result's own arguments — and shared read-only between the
sessions of a server.  A dragged slider's preview looks up the same store without computing
(:meth:`ResultCache.peek`).

* **Bytes, not items.** An entry's size is :func:`deep_size` of its value: the ``nbytes`` of
  every numpy array it holds and ``sys.getsizeof`` of every other object it reaches (each object
  counted once).  An entry that grows after it is stored (a model keeps the decompositions of
  its last operating points) is measured again when an entry is added, at most every
  :data:`REMEASURE_S` seconds.  When the entries
  exceed the budget, the least recently used go first; the newest entry stays even if it alone
  exceeds the budget.
* **One computation per key.** A thread that asks for a key another thread is computing waits
  for that result instead of computing it again (the dashboard's coarse root locus and s0*(v)
  need the same sweep at once).  A computation that stops because nobody wants it any more
  raises :class:`Superseded`: a thread waiting for it computes the key itself.  Errors are not
  kept.

The budget is the server operator's (``bogie serve --cache-mb``, ``BOGIE_CACHE_MB``;
:data:`DEFAULT_CACHE_MB`); docs/memory.md states what else a server holds.  No Panel here.
"""

from __future__ import annotations

import sys
import threading
import time
import types
from collections import OrderedDict
from collections.abc import Callable, Hashable
from concurrent.futures import Future
from dataclasses import dataclass

import numpy as np

DEFAULT_CACHE_MB = 400  # the default budget [MB]: docs/memory.md gives a 2 GB container's sum
MB = 1_000_000  # bytes per MB (the budget's unit)
REMEASURE_S = 1.0  # growing entries are measured again at most this often [s] (a model: 3 ms)

# objects that are not a result's data: never walked into (a result holding a function or a
# class does not own it)
_SKIPPED = (type, types.ModuleType, types.FunctionType, types.BuiltinFunctionType,
            types.MethodType, types.CodeType)


def deep_size(value, seen: set[int] | None = None) -> int:
    """Bytes held by ``value`` and everything it reaches, each object once (``seen``: ids
    already counted): a numpy array counts ``sys.getsizeof`` (its header, and its data when it
    owns them) and its base array; containers, dataclasses and objects with a ``__dict__`` or
    ``__slots__`` count ``sys.getsizeof`` and their contents; functions, classes and modules
    count nothing."""
    seen = set() if seen is None else seen
    total = 0
    stack = [value]
    while stack:
        obj = stack.pop()
        if id(obj) in seen or isinstance(obj, _SKIPPED):
            continue
        seen.add(id(obj))
        total += sys.getsizeof(obj)
        if isinstance(obj, np.ndarray):
            if obj.base is not None:
                stack.append(obj.base)
            if obj.dtype == object:
                stack.extend(obj.ravel().tolist())
            continue
        if isinstance(obj, str | bytes | bytearray | int | float | complex | bool):
            continue
        if isinstance(obj, dict):
            stack.extend(obj.keys())
            stack.extend(obj.values())
            continue
        if isinstance(obj, list | tuple | set | frozenset):
            stack.extend(obj)
            continue
        attributes = getattr(obj, "__dict__", None)
        if isinstance(attributes, dict):
            stack.append(attributes)
        for cls in type(obj).__mro__:
            for slot in getattr(cls, "__slots__", ()):
                if slot not in ("__dict__", "__weakref__") and hasattr(obj, slot):
                    stack.append(getattr(obj, slot))
    return total


class Superseded(Exception):
    """A computation stopped because no one wants its result any more (a thread waiting for the
    same key computes it itself)."""


@dataclass
class _Entry:
    value: object
    size: int  # [bytes]
    growing: bool  # measured again when an entry is added


class ResultCache:
    """Results by key, at most ``budget`` bytes of them (thread-safe)."""

    def __init__(self, budget: int):
        self.budget = int(budget)
        self._entries: OrderedDict[Hashable, _Entry] = OrderedDict()  # oldest first
        self._pending: dict[Hashable, Future] = {}
        self._lock = threading.Lock()
        self._bytes = 0
        self._measured = -float("inf")  # when the growing entries were last measured
        self.hits = self.misses = self.evictions = 0

    # --- reading ------------------------------------------------------------------------------

    def get(self, key: Hashable, compute: Callable[[], object], growing: bool = False):
        """The value of ``key``: the kept one, the one another thread is computing, or
        ``compute()`` (kept unless it raises).  ``growing``: the value may grow after it is
        stored (it is measured again when entries are added)."""
        while True:
            with self._lock:
                entry = self._entries.get(key)
                if entry is not None:
                    self._entries.move_to_end(key)
                    self.hits += 1
                    return entry.value
                waiting = self._pending.get(key)
                if waiting is None:
                    future: Future = Future()
                    self._pending[key] = future
                    self.misses += 1
            if waiting is None:
                return self._compute(key, compute, future, growing)
            try:
                return waiting.result()
            except Superseded:
                continue  # the thread computing it gave up: compute it here

    def peek(self, key: Hashable):
        """The kept value of ``key``, or None (nothing is computed; the order is not changed)."""
        with self._lock:
            entry = self._entries.get(key)
            return None if entry is None else entry.value

    def __contains__(self, key: Hashable) -> bool:
        with self._lock:
            return key in self._entries

    def __len__(self) -> int:
        with self._lock:
            return len(self._entries)

    @property
    def bytes(self) -> int:
        """The bytes of the kept entries (as last measured)."""
        with self._lock:
            return self._bytes

    def sizes(self) -> list[tuple[Hashable, int]]:
        """(key, bytes) of the kept entries, least recently used first."""
        with self._lock:
            return [(key, entry.size) for key, entry in self._entries.items()]

    # --- writing ------------------------------------------------------------------------------

    def _compute(self, key, compute, future: Future, growing: bool):
        try:
            value = compute()
        except BaseException as error:
            with self._lock:
                self._pending.pop(key, None)
            future.set_exception(error)
            raise
        size = deep_size(value)
        with self._lock:
            self._pending.pop(key, None)
            self._store(key, _Entry(value, size, growing))
        future.set_result(value)
        return value

    def put(self, key: Hashable, value, growing: bool = False) -> None:
        """Keep ``value`` under ``key`` (replacing a kept one)."""
        size = deep_size(value)
        with self._lock:
            self._store(key, _Entry(value, size, growing))

    def _store(self, key, entry: _Entry) -> None:
        """Add ``entry`` (with the lock), measure the growing entries again, drop the least
        recently used beyond the budget."""
        old = self._entries.pop(key, None)
        if old is not None:
            self._bytes -= old.size
        self._entries[key] = entry
        self._bytes += entry.size
        now = time.monotonic()
        if now - self._measured >= REMEASURE_S:
            self._measure_growing(entry)
            self._measured = now
        while self._bytes > self.budget and len(self._entries) > 1:
            _, dropped = self._entries.popitem(last=False)
            self._bytes -= dropped.size
            self.evictions += 1

    def _measure_growing(self, skip=None) -> None:
        for other in self._entries.values():
            if other.growing and other is not skip:
                size = deep_size(other.value)
                self._bytes += size - other.size
                other.size = size

    def measure(self) -> int:
        """Measure the growing entries now; the bytes kept."""
        with self._lock:
            self._measure_growing()
            return self._bytes

    def set_budget(self, budget: int) -> None:
        """A new budget [bytes]; entries beyond it go at once."""
        with self._lock:
            self.budget = int(budget)
            while self._bytes > self.budget and len(self._entries) > 1:
                _, dropped = self._entries.popitem(last=False)
                self._bytes -= dropped.size
                self.evictions += 1

    def drop(self, kind: str) -> int:
        """Drop the kept entries of one kind of result (keys ``(kind, …)``; a benchmark's cold
        run); how many were dropped."""
        with self._lock:
            keys = [key for key in self._entries
                    if isinstance(key, tuple) and key and key[0] == kind]
            for key in keys:
                self._bytes -= self._entries.pop(key).size
            return len(keys)

    def clear(self) -> None:
        """Drop every kept entry (computations under way finish and are kept)."""
        with self._lock:
            self._entries.clear()
            self._bytes = 0


RESULTS = ResultCache(DEFAULT_CACHE_MB * MB)  # the process's cache


def configure(cache_mb: int) -> None:
    """The process's budget [MB] (``bogie serve --cache-mb``)."""
    RESULTS.set_budget(int(cache_mb) * MB)
