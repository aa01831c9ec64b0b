"""The loci's waves (one per slice): the next wave's first chunks traced while a wave grows,
on engine slots it leaves idle, give the loci of tracing wave after wave. (The runs are
stubs: this is the recipe's control and the engine's slots, not a continuation result.)"""

from __future__ import annotations

import threading
import time

import numpy as np

from whirl_cli.continuation import loci
from whirl_cli.continuation.engine import _Slots
from whirl_cli.continuation.numerics import Numerics
from whirl_cli.results import BranchKind, Origin, PointType, SpecialPoint

from .locus_data import make_locus


class _SeenWaiting(threading.Condition):
    """A condition that records the name of each thread that waits on it."""

    def __init__(self) -> None:
        super().__init__()
        self.waiting: set[str] = set()

    def wait(self, timeout=None):
        self.waiting.add(threading.current_thread().name)
        return super().wait(timeout)


def test_background_holders_wait_while_a_foreground_request_waits():
    """Two foreground holders fill both slots; two more foreground requests and a background
    one wait. When both slots free, the waiting foreground requests get them and the
    background one only after (each step waits for a state, not for a time)."""
    slots = _Slots(2)
    slots._changed = seen = _SeenWaiting()
    order, holding = [], []
    lock = threading.Lock()
    entered = {tag: threading.Event() for tag in ("f1", "f2", "f3", "f4", "b")}
    release = threading.Event()

    def hold(tag: str, background: bool) -> None:
        with slots.held(background):
            with lock:
                order.append(tag)
                holding.append(tag)
                assert len(holding) <= 2
            entered[tag].set()
            release.wait(5)
            with lock:
                holding.remove(tag)

    threads = {tag: threading.Thread(target=hold, args=(tag, tag == "b"), name=tag)
               for tag in entered}
    for tag in ("f1", "f2"):
        threads[tag].start()
        assert entered[tag].wait(5)
    for tag in ("f3", "f4", "b"):
        threads[tag].start()
    for _ in range(60_000):  # a guard against a hang: ends once all three wait for a slot
        if {"f3", "f4", "b"} <= seen.waiting:
            break
        time.sleep(0.001)
    assert {"f3", "f4", "b"} <= seen.waiting and order == ["f1", "f2"]
    release.set()
    for thread in threads.values():
        thread.join(5)
    assert order[:2] == ["f1", "f2"] and order[-1] == "b" and sorted(order[2:4]) == ["f3", "f4"]


def test_background_takes_an_idle_slot():
    slots = _Slots(2)
    with slots.held():
        done = threading.Event()

        def background() -> None:
            with slots.held(background=True):
                done.set()

        thread = threading.Thread(target=background)
        thread.start()
        assert done.wait(5)  # one slot free, no foreground request waiting
        thread.join(5)


def _start(slice_k: int, k1: float, kq: float) -> SpecialPoint:
    return SpecialPoint(f"slice_{slice_k}.periodic_1", 3, int(PointType.LPC), ("p", "q"),
                        np.array([k1, kq]), np.array([0.1, 0.0]), 1.0 + k1, False)


def test_a_next_wave_start_on_a_locus_of_the_wave_before_is_set_aside(monkeypatch):
    """Wave 0's locus passes wave 1's first start: its first chunk, traced ahead, is set
    aside, and wave 1 grows the other start's loci in the order tracing them then would give
    (loci of equilibria and cycles' first stages, then cycles' second stages)."""
    traced_sets, background_flags, grown = [], [], []

    def trace(_engine, _name, _pair, _bounds, _numerics, starts, background=False):
        traced_sets.append([k for k, _, _ in starts])
        background_flags.append(background)
        rows = []
        for k, point, _ in starts:
            for tag in "ab":
                spec = loci.RunSpec(f"c/fold_of_cycles_{k}{tag}2", {},
                                    BranchKind.FOLD_OF_CYCLES_LOCUS, Origin(""), ("p", "q"))
                rows.append((k, PointType.LPC, spec, make_locus(np.array(
                    [point.parameters, point.parameters + [0.0, 0.1 if tag == "a" else -0.1]]))))
        return rows[::-1]  # any order: the recipe puts them in its own

    def wave(_engine, _pair, _bounds, _numerics, traced, curves, _width, _checked):
        grown.append([spec.name for _, spec, _ in traced.values()])
        if len(grown) == 1:  # wave 0's locus runs through (0.5, 0.3), wave 1's first start
            return [(PointType.LPC, make_locus(np.array([[0.5, 0.0], [0.5, 0.5]])))]
        return [(kind, curve) for kind, _, curve in traced.values()]

    monkeypatch.setattr(loci, "_trace", trace)
    monkeypatch.setattr(loci, "_wave", wave)
    starts = [(_start(0, 0.5, 0.1), "r0"), (_start(1, 0.5, 0.3), "r1"),
              (_start(1, 0.8, 0.3), "r1")]
    loci._loci(None, "c", ("p", "q"), {"p": (0.0, 1.0), "q": (0.0, 0.5)}, Numerics(), starts)
    assert traced_sets == [[1], [2, 3]] and background_flags == [False, True]
    assert grown == [["c/fold_of_cycles_1a2", "c/fold_of_cycles_1b2"],
                     ["c/fold_of_cycles_3a2", "c/fold_of_cycles_3b2"]]
