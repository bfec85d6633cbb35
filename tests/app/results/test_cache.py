"""The one results cache (app.results.cache): its byte accounting against ``nbytes`` and
``sys.getsizeof``, least recently used out first within the budget, one computation per key
however many threads ask, and no error kept."""

from __future__ import annotations

import sys
import threading
import time
from dataclasses import dataclass

import numpy as np
import pytest

from app.results import cache
from app.results.cache import ResultCache, Superseded, deep_size

MB = 1_000_000


@dataclass(frozen=True)
class Result:
    """A result as the app keeps them: arrays, a dict of arrays, numbers, a text."""

    t: np.ndarray
    outputs: dict
    peak: float
    name: str


def test_deep_size_counts_array_data_once_and_the_objects_around_them():
    a = np.zeros(100_000)
    assert deep_size(a) == sys.getsizeof(a) >= a.nbytes  # an array owning its data
    view = a[::2]
    assert deep_size(view) == sys.getsizeof(view) + sys.getsizeof(a)  # the view and its base
    both = [a, view]
    assert deep_size(both) == sys.getsizeof(both) + sys.getsizeof(a) + sys.getsizeof(view)
    result = Result(a, {"x": np.ones(1000), "y": a}, 1.5, "linear creep")
    arrays = a.nbytes + 1000 * 8
    size = deep_size(result)
    assert arrays < size < arrays + 2_000  # the data, and a little for the objects around it
    assert deep_size({"k": (1.0, "text")}) == (sys.getsizeof({"k": 0}) + sys.getsizeof("k")
                                               + sys.getsizeof((1.0, "text"))
                                               + sys.getsizeof(1.0) + sys.getsizeof("text"))
    assert deep_size(deep_size) == 0  # a function is not a result's data


def test_the_kept_bytes_are_the_entries_sizes():
    store = ResultCache(100 * MB)
    values = {f"k{i}": Result(np.zeros(10_000 * (i + 1)), {}, 0.0, "x") for i in range(5)}
    for key, value in values.items():
        assert store.get(key, lambda value=value: value) is value
    assert store.bytes == sum(deep_size(v) for v in values.values())
    assert store.bytes >= sum(v.t.nbytes for v in values.values())
    assert dict(store.sizes()) == {key: deep_size(v) for key, v in values.items()}


def test_least_recently_used_out_first_within_the_budget():
    one = deep_size(np.zeros(125_000))  # 1 MB and a header
    store = ResultCache(3 * one)
    for key in "abc":
        store.get(key, lambda: np.zeros(125_000))
    assert [key for key, _ in store.sizes()] == ["a", "b", "c"]
    store.get("a", lambda: pytest.fail("kept: not computed again"))  # a used again
    store.get("d", lambda: np.zeros(125_000))
    assert [key for key, _ in store.sizes()] == ["c", "a", "d"]  # b, the least recent, went
    assert store.peek("b") is None
    assert store.evictions == 1
    assert store.bytes <= store.budget
    store.set_budget(one)
    assert [key for key, _ in store.sizes()] == ["d"]
    big = store.get("big", lambda: np.zeros(500_000))  # larger than the budget alone: kept
    assert store.peek("big") is big  # until the next entry
    assert len(store) == 1


def test_a_growing_entry_is_measured_again(monkeypatch):
    monkeypatch.setattr(cache, "REMEASURE_S", 0.0)
    store = ResultCache(100 * MB)
    holder = {"systems": []}
    store.get("model", lambda: holder, growing=True)
    before = store.bytes
    holder["systems"].append(np.zeros(250_000))  # 2 MB more after it was stored
    store.get("other", lambda: 1.0)
    assert store.bytes >= before + 2 * MB
    assert store.measure() == store.bytes


def test_one_computation_per_key_however_many_threads_ask():
    store = ResultCache(100 * MB)
    calls = []

    def compute():
        calls.append(1)
        time.sleep(0.2)
        return np.arange(10)

    results = []
    threads = [threading.Thread(target=lambda: results.append(store.get("k", compute)))
               for _ in range(4)]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    assert len(calls) == 1
    assert all(r is results[0] for r in results)
    assert (store.hits, store.misses) == (0, 1)  # three waited for the one computation


def test_errors_are_not_kept_and_a_superseded_computation_is_done_again():
    store = ResultCache(100 * MB)
    with pytest.raises(ValueError, match="rejected"):
        store.get("k", lambda: (_ for _ in ()).throw(ValueError("rejected")))
    assert store.peek("k") is None
    assert store.get("k", lambda: 2.0) == 2.0
    started, release = threading.Event(), threading.Event()

    def gives_up():
        started.set()
        release.wait(5)
        raise Superseded  # its session moved on

    outcome = []

    def first_asks() -> None:
        try:
            store.get("s", gives_up)
        except Superseded:
            outcome.append("gave up")

    first = threading.Thread(target=first_asks)
    first.start()
    started.wait(5)
    second = threading.Thread(target=lambda: outcome.append(store.get("s", lambda: "mine")))
    second.start()
    time.sleep(0.1)  # the second waits for the first
    release.set()
    first.join()
    second.join()
    assert sorted(outcome) == ["gave up", "mine"]  # the second computed the key itself
    assert store.peek("s") == "mine"
