"""The exact motion of a linear model whose one dof has a freeplay law, for tests, apart from
whirl: within each piece of the law (inside the gap, beyond +delta, beyond -delta) the model is
affine, y' = A y + b, and its motion from y0 is y(s) = r + V exp(L s) V^-1 (y0 - r), with A's
eigenvalues L and eigenvectors V and r its rest state (A r + b = 0). A piece ends where the dof
reaches a gap edge, found by a root-finder on that closed form; the next piece starts there.

No step-size control stands between the law and the motion: the only errors are rounding and
the root-finder's (1e-15 s). An edge crossing is looked for between points a twentieth of the
fastest mode's period apart (at most one extremum of the dof between two), and at the extremum
between them where the dof's rate changes sign, so a grazing of the edge is not missed.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
from scipy.optimize import brentq

EPS = np.finfo(float).eps


class Piece:
    """y' = a y + b, solved in closed form."""

    def __init__(self, a: np.ndarray, b: np.ndarray):
        self.rates, self.modes = np.linalg.eig(a)
        self.inverse = np.linalg.inv(self.modes)
        self.rest = -np.linalg.solve(a, b) if np.any(b) else np.zeros(len(b))

    def states(self, y0: np.ndarray, s: np.ndarray) -> np.ndarray:
        """The states at the times ``s`` after the piece starts at ``y0`` (one row each)."""
        w = self.inverse @ (y0 - self.rest)
        return (self.modes @ (np.exp(np.multiply.outer(self.rates, s)) * w[:, None])).real.T \
            + self.rest

    def coordinate(self, y0: np.ndarray, k: int, s):
        """State ``k`` at the time(s) ``s`` after the piece starts at ``y0``."""
        w = self.inverse @ (y0 - self.rest)
        return ((self.modes[k] * w) @ np.exp(np.multiply.outer(self.rates, s))).real \
            + self.rest[k]


def affine_pieces(a_of, b_of) -> dict[int, Piece]:
    """The three pieces -1 (beyond -delta), 0 (the gap), 1 (beyond +delta) from their matrix
    ``a_of(piece)`` and constant ``b_of(piece)``."""
    return {piece: Piece(a_of(piece), b_of(piece)) for piece in (-1, 0, 1)}


def _leaving(piece: int, delta: float, x: np.ndarray) -> np.ndarray:
    """True where the dof at ``x`` is no longer in ``piece``."""
    return np.abs(x) >= delta if piece == 0 else piece * x < delta


def _edge(piece: int, delta: float, x: float) -> float:
    return delta * np.sign(x) if piece == 0 else piece * delta


def _exit(p: Piece, y: np.ndarray, j: int, rate: int, piece: int, delta: float,
          lo: float, hi: float) -> float | None:
    """The time in (lo, hi] at which the dof leaves ``piece``, or None: where it is outside at
    ``hi``, or at the extremum where its rate changes sign in between."""
    x_hi = float(p.coordinate(y, j, hi))
    if not _leaving(piece, delta, np.array(x_hi)):
        v_lo, v_hi = (float(p.coordinate(y, rate, s)) for s in (lo, hi))
        if v_lo * v_hi >= 0:
            return None
        turn = brentq(lambda s: float(p.coordinate(y, rate, s)), lo, hi, xtol=1e-16,
                      rtol=4 * EPS)
        x_turn = float(p.coordinate(y, j, turn))
        if not _leaving(piece, delta, np.array(x_turn)):
            return None
        hi, x_hi = turn, x_turn
    level = _edge(piece, delta, x_hi)
    low = lo if lo > 0 else hi * 1e-9  # the piece starts on an edge

    def g(s: float) -> float:
        return float(p.coordinate(y, j, s)) - level

    if g(low) * g(hi) > 0:  # leaves at once: it grazed the edge it came in by
        return low
    return brentq(g, low, hi, xtol=1e-16, rtol=4 * EPS)


def motion(pieces: Mapping[int, Piece], j: int, rate: int, delta: float, y0, grid: np.ndarray,
           limit: tuple[tuple[int, ...], float] | None = None, visits: list | None = None):
    """(t, y): the motion from ``y0`` at time 0, at the times ``grid`` (evenly spaced, from 0),
    of the model whose dof ``j`` (its rate: state ``rate``) meets a freeplay law of half-gap
    ``delta``; ``pieces`` as :func:`affine_pieces` gives them. ``limit`` (states, size): the
    samples end before the first where one of those states exceeds size (diverged).
    ``visits``, if given, receives (piece, time spent in it) for each piece the motion passes
    through up to the grid's end."""
    fastest = max(abs(r) for p in pieces.values() for r in p.rates)
    step = min(grid[1] - grid[0], 2 * np.pi / fastest / 20)
    duration = grid[-1]
    y = np.array(y0, dtype=float)
    piece = 0 if abs(y[j]) < delta else int(np.sign(y[j]))
    t0, out_t, out_y = 0.0, [], []
    while True:
        p = pieces[piece]
        hit, start, count = None, 0.0, 64
        while hit is None and t0 + start < duration:
            s = start + step * np.arange(count + 1)
            out = _leaving(piece, delta, p.coordinate(y, j, s[1:]))
            turns = np.diff(np.sign(p.coordinate(y, rate, s))) != 0
            for k in np.flatnonzero(out | turns):  # in order, up to the first it leaves in
                hit = _exit(p, y, j, rate, piece, delta, s[k], s[k + 1])
                if hit is not None or out[k]:
                    break
            start, count = s[-1], min(2 * count, 4096)
        end = duration if hit is None else min(duration, t0 + hit)
        if visits is not None:
            visits.append((piece, end - t0))
        times = grid[(grid >= t0) & (grid <= end)] if not out_t else \
            grid[(grid > t0) & (grid <= end)]
        states = p.states(y, times - t0)
        if limit is not None:
            over = np.flatnonzero(np.abs(states[:, list(limit[0])]).max(axis=1) > limit[1])
            if over.size:
                out_t.append(times[:over[0]])
                out_y.append(states[:over[0]])
                return np.concatenate(out_t), np.vstack(out_y)
        out_t.append(times)
        out_y.append(states)
        if hit is None or t0 + hit >= duration:
            return np.concatenate(out_t), np.vstack(out_y)
        y = p.states(y, np.array([hit]))[0]
        level = _edge(piece, delta, y[j])
        t0, y[j] = t0 + hit, level  # exactly on the edge
        piece = int(np.sign(level)) if piece == 0 else 0
