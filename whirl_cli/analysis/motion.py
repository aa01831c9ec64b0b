"""What a simulation settles to, where AUTO cannot continue: equilibrium, periodic,
quasi-periodic, chaotic (or diverged), from three independent pieces of evidence.

:func:`classify` takes any ODE (``f(y) -> dy/dt``, ``jac(y) -> df/dy``, numpy); it integrates a
transient and then the settled window with one tangent vector
(:func:`whirl_cli.analysis.lyapunov.tangent_run`; ``method`` "odeint", classify_model's, is
LSODA through scipy's ``odeint``: the same steps as ``solve_ivp``'s LSODA with far less Python
per step), and reads the samples three ways:

(a) **Poincaré section**: the crossings of y_k = mean(y_k) with y_k rising (k: the state that
    moves most relative to its scale), located on a cubic through the four samples around
    each crossing, every state interpolated there (:func:`poincare_section`). Normalised by
    each state's standard deviation over the window (at least 1e-2 of the largest one in the
    states' scales), the points either repeat with a lag k
    (a period-k orbit: the largest distance between point i and i + k, over the last half of
    the points, below ``section_tolerance``; :func:`section_geometry`) or fill a set whose
    correlation dimension D2 = ln 6 / ln(r_30 / r_5) (r_q: the q-th percentile of the
    distances between pairs of points: C(r) ~ r^D2 from 5 to 30 % of the pairs, which a
    circle meets with D2 = 1.02; smaller r see the gaps of the few, evenly spread points of
    an irrational rotation) is near 1 (a closed curve: a torus) or above (a cloud).
(b) **Largest Lyapunov exponent** lambda (1/s) from the variational equations with the
    analytic Jacobian (Benettin), measured between section crossings, with its standard
    error over 10 blocks (:func:`whirl_cli.analysis.lyapunov.exponent_between`).
(c) **Spectrum**: the sum over the states of the Hann-windowed power spectra of y_i / scale_i
    (mean removed), its peaks down to 1e-4 of the largest (-40 dB; peaks within 4 bins of a
    larger one are its window side lobes), located by a parabola through log power; the
    peaks are explained by one fundamental (all within 1.5 bins of integer multiples of the
    lowest peak), two (all within 1.5 bins of |m f_a + n f_b|, |m|, |n| <= 6, f_a the
    strongest peak and f_b the strongest other one) or neither (broadband). ``broadband``
    is the fraction of the power farther than 3 bins from every peak.

The class (:class:`MotionClass`), in this order:

1. ``diverged``: some |y_i| exceeded ``bound`` or the integration failed;
2. ``equilibrium``: the settled motion spans less than ``amplitude_tolerance`` (in the states'
   scales), or lambda < -(threshold + 3 error): only a fixed point attracts with a negative
   largest exponent (on any other bounded orbit the flow direction gives lambda >= 0);
3. ``chaotic``: lambda > threshold + 3 error;
4. otherwise lambda is zero within its confidence, and the section decides: points repeating
   with a lag k, or whose lag-k distances shrink steadily (a period-k orbit not yet reached,
   said in the evidence) -> ``periodic`` (period-k; ``multiplicity`` k); else a spectrum of
   one fundamental and its harmonics (under 1 % broadband) -> ``periodic`` (the evidence says
   the section did not repeat); else points on a curve (D2 < 1.5) or a spectrum of two base
   frequencies -> ``quasi-periodic``; else (a cloud, a broadband spectrum) -> ``chaotic``
   (weakly: lambda not resolved from zero; the evidence says so).

**The window, sampled finer.** A window whose spectrum reaches its Nyquist frequency (more
than ALIASED_POWER of its power above 3/4 of it) holds a motion faster than its sampling, whose
aliased lines would read as frequencies of their own: it is integrated again from its end
(state and tangent vector) RESAMPLE times finer, at most MAX_RESAMPLES times.
**The window, doubled once.** Where the section does not repeat but the spectrum reads one
fundamental (rule 4's spectrum-only ``periodic``), or lambda is not resolved and the section
is a cloud (weakly ``chaotic``), section and spectrum disagree: near a resonance p:q of a
torus the spectrum cannot tell f_a from q/p f_b within 1.5 bins (bin = 1 / window), while the
section is a closed curve. With ``extend`` = 1 (``classify_model``'s default) the window is
then continued as long again from its end (state and tangent vector, no new transient) and
the whole is classified again: bins half as wide, twice the section points; a cycle whose
section merely had not settled then repeats, and the evidence says so. A spectrum that still
reads one fundamental keeps ``periodic`` (the section's interpolation noise on the fast
harmonics of a cycle can keep it from repeating to 1e-2, the gimballed study at K1 = 0.2).

threshold = ``lyapunov_tolerance`` (1/s), by default 0.01 x 2 pi f_dom (an e-fold in 16
periods of the dominant frequency f_dom of the spectrum). Frequencies (Hz) reported: the
fundamental 1 / (k x mean return time) of a period-k orbit, the section's 1 / mean return time
and the other base of the spectrum for a torus, the three strongest peaks otherwise.

:func:`classify_model` is the wrapper for whirl's models at fixed parameters: durations from
the linearisation at the start, see its docstring. Time in seconds, frequencies in Hz.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..kinds import MotionKind
from .lyapunov import TangentRun, exponent_between, tangent_run

#: Largest lag k tried for a period-k orbit on the section.
MAX_MULTIPLICITY = 8
#: Correlation dimension of the section below which its points lie on a curve.
CURVE_DIMENSION = 1.5
#: Spectral peaks kept, down to this fraction of the largest (power).
PEAK_FLOOR = 1e-4
#: A window whose spectrum holds more than this fraction of its power above 3/4 of the Nyquist
#: frequency is sampled too coarsely for its motion (aliased lines would read as frequencies
#: of their own): it is sampled again, RESAMPLE times finer, at most MAX_RESAMPLES times.
ALIASED_POWER = 1e-3
RESAMPLE = 4
MAX_RESAMPLES = 2
#: The evidence of a cycle read from the spectrum alone, and of chaos not resolved by lambda.
SPECTRUM_ONLY = ("the spectrum is one fundamental and its harmonics, though the section did "
                 "not repeat")
WEAKLY_CHAOTIC = "weakly chaotic"


@dataclass(frozen=True, eq=False)
class MotionClass:
    """The settled motion at one parameter point.

    ``kind``: what it settled on; ``lyapunov``, ``lyapunov_error``: the largest exponent and
    its standard error (1/s; NaN if diverged); ``frequencies`` (Hz): see the module doc;
    ``section`` (m, n): the Poincaré section points (SI states); ``section_dimension``: D2 of
    the section (NaN with fewer than 10 points); ``multiplicity``: k of a period-k orbit (0
    otherwise); ``peaks`` (Hz): the spectral peaks, strongest first; ``broadband``: the
    fraction of spectral power away from the peaks; ``evidence``: the three readings, text."""

    kind: MotionKind
    lyapunov: float
    lyapunov_error: float
    frequencies: tuple[float, ...]
    section: np.ndarray
    section_dimension: float
    multiplicity: int
    peaks: tuple[float, ...]
    broadband: float
    evidence: str


# ------------------------------------------------------------------------------ (a) section
def poincare_section(time: np.ndarray, states: np.ndarray, index: int,
                     level: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """(times (m,), points (m, n)) where ``states[:, index]`` crosses ``level`` (default: its
    mean) upwards; between samples i and i + 1 by the cubic through samples i - 1 .. i + 2
    (uniform ``time``), its root by Newton from the linear guess, and every state at it."""
    signal = states[:, index] - (np.mean(states[:, index]) if level is None else level)
    i = np.nonzero((signal[:-1] < 0) & (signal[1:] >= 0))[0]
    i = i[(i >= 1) & (i <= len(signal) - 3)]
    if not len(i):
        return np.zeros(0), np.zeros((0, states.shape[1]))
    window = signal[i[:, None] + np.arange(-1, 3)]  # (m, 4) at s = -1, 0, 1, 2
    s = -window[:, 1] / (window[:, 2] - window[:, 1])
    for _ in range(8):
        value = np.sum(_lagrange(s) * window, axis=1)
        slope = np.sum(_lagrange_slope(s) * window, axis=1)
        s = np.clip(s - value / np.where(slope == 0, 1.0, slope), 0.0, 1.0)
    weights = _lagrange(s)  # (m, 4)
    points = np.einsum("mk,mkn->mn", weights, states[i[:, None] + np.arange(-1, 3)])
    step = time[1] - time[0]
    return time[i] + s * step, points


def _lagrange(s: np.ndarray) -> np.ndarray:
    """Cubic Lagrange weights at nodes -1, 0, 1, 2 for positions ``s`` (m,): (m, 4)."""
    s = s[:, None]
    return np.hstack([-s * (s - 1) * (s - 2) / 6, (s + 1) * (s - 1) * (s - 2) / 2,
                      -(s + 1) * s * (s - 2) / 2, (s + 1) * s * (s - 1) / 6])


def _lagrange_slope(s: np.ndarray) -> np.ndarray:
    s = s[:, None]
    return np.hstack([-(3 * s**2 - 6 * s + 2) / 6, (3 * s**2 - 4 * s - 1) / 2,
                      -(3 * s**2 - 2 * s - 2) / 2, (3 * s**2 - 1) / 6])


def section_geometry(points: np.ndarray, scale: np.ndarray,
                     tolerance: float = 1e-2) -> tuple[int, float, float, int, float]:
    """(k, D2, spread, k_c, rate) of section ``points`` (m, n) in units of ``scale`` (n,): k the
    smallest lag <= :data:`MAX_MULTIPLICITY` with max |p_i+k - p_i| <= ``tolerance`` over the
    last half of the points and every shorter lag above 10 x ``tolerance`` (its k points
    distinct; 0 if none), spread that largest distance for k (or for k = 1), D2 the correlation
    dimension (NaN below 10 points); k_c the smallest lag whose distances s_i = max |p_i+k -
    p_i| shrink steadily over the last half of the points (correlation of ln s_i with i below
    -0.9, at least 8 of them: a period-k orbit not yet reached, where a torus's distances only
    fluctuate; 0 if none) and rate the factor by which they shrink per return (a fit of ln
    s_i)."""
    m = len(points)
    if m < 3:
        return 0, np.nan, np.nan, 0, np.nan
    unit = points / scale
    late = unit[m // 2:]
    spreads = [np.max(np.abs(late[k:] - late[:-k])) for k in range(1, MAX_MULTIPLICITY + 1)
               if len(late) > k + 1]
    # lag k: its k points distinct (every shorter lag misses by 10 x the tolerance), else a
    # slow spiral onto one point that turns by about 1/k per return would pass for period k
    found = [k + 1 for k, value in enumerate(spreads)
             if value <= tolerance and all(v > 10 * tolerance for v in spreads[:k])]
    multiplicity = found[0] if found else 0
    spread = float(spreads[multiplicity - 1 if multiplicity else 0]) if spreads else np.nan
    dimension = np.nan
    if m >= 10:
        distances = np.sqrt(((unit[:, None, :] - unit[None, :, :]) ** 2).sum(-1))
        pairs = distances[np.triu_indices(m, 1)]
        low, high = np.percentile(pairs, [5.0, 30.0])
        dimension = float(np.log(6.0) / np.log(high / low)) if low > 0 else 0.0
    converging, rate = 0, np.nan
    for k in range(1, MAX_MULTIPLICITY + 1):
        lags = np.max(np.abs(unit[k:] - unit[:-k]), axis=1)
        lags = lags[len(lags) // 2:]  # the approach is steady only near the orbit
        if len(lags) < 8 or np.any(lags <= 0):
            continue
        logs = np.log(lags)
        order = np.arange(len(logs))
        if np.corrcoef(order, logs)[0, 1] < -0.9:
            converging, rate = k, float(np.exp(np.polyfit(order, logs, 1)[0]))
            break
    return multiplicity, dimension, spread, converging, rate


# ------------------------------------------------------------------------------ (c) spectrum
def spectrum(time: np.ndarray, states: np.ndarray,
             scale: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(frequency (Hz), power): the sum over states of the Hann-windowed power spectra of
    (y_i - mean) / scale_i, uniform ``time``."""
    unit = (states - states.mean(axis=0)) / scale
    window = np.hanning(len(time))[:, None]
    power = (np.abs(np.fft.rfft(unit * window, axis=0)) ** 2).sum(axis=1)
    return np.fft.rfftfreq(len(time), time[1] - time[0]), power


def spectral_peaks(frequency: np.ndarray, power: np.ndarray, floor: float = PEAK_FLOOR,
                   most: int = 12) -> tuple[np.ndarray, np.ndarray, float]:
    """(peak frequencies (Hz), their powers, broadband fraction): local maxima above ``floor``
    x the largest, strongest first, at most ``most``, none within 4 bins of a stronger one,
    each placed by a parabola through the log power of its bin and neighbours; broadband:
    the fraction of power farther than 3 bins from every peak."""
    if len(power) < 5 or power[1:].max() <= 0:
        return np.zeros(0), np.zeros(0), 1.0
    p = power.copy()
    p[0] = 0.0
    local = np.nonzero((p[1:-1] > p[:-2]) & (p[1:-1] >= p[2:]) & (p[1:-1] >= floor * p.max()))
    bins = local[0] + 1
    bins = bins[np.argsort(-p[bins])]
    kept: list[int] = []
    for b in bins:  # a handful of peaks: the loop is over peaks, not samples
        if all(abs(int(b) - k) > 4 for k in kept):
            kept.append(int(b))
        if len(kept) == most:
            break
    kept_bins = np.array(kept, dtype=int)
    lo, mid, hi = (np.log(np.maximum(p[kept_bins + d], 1e-300)) for d in (-1, 0, 1))
    curvature = lo - 2 * mid + hi
    shift = np.where(curvature < 0, 0.5 * (lo - hi) / np.where(curvature < 0, curvature, -1),
                     0.0)
    step = frequency[1] - frequency[0]
    near = np.zeros(len(p), dtype=bool)
    for b in kept_bins:
        near[max(b - 3, 0):b + 4] = True
    broadband = float(p[~near].sum() / p.sum())
    return frequency[kept_bins] + shift * step, p[kept_bins], broadband


def base_frequencies(peaks: np.ndarray, tolerance: float) -> tuple[float, ...]:
    """The fewest base frequencies (one or two, Hz) of which every peak is an integer
    combination within ``tolerance`` (Hz): one, the lowest peak, if all are its multiples;
    two, the strongest and the strongest other peak, if all are |m f_a + n f_b| with |m|,
    |n| <= 6; () if neither (broadband, or no peaks)."""
    if not len(peaks):
        return ()
    lowest = float(peaks.min())
    ratio = peaks / lowest
    if lowest > 3 * tolerance and np.all(np.abs(ratio - np.round(ratio)) * lowest <= tolerance):
        return (lowest,)  # (a fundamental within a few bins of 0 would explain anything)
    first = float(peaks[0])
    harmonic = np.abs(peaks / first - np.round(peaks / first)) * first <= tolerance
    if harmonic.all() or first <= 3 * tolerance:
        return (first,) if harmonic.all() and first > 3 * tolerance else ()
    second = float(peaks[~harmonic][0])
    if second <= 3 * tolerance:
        return ()
    orders = np.arange(-6, 7)
    combinations = np.abs(orders[:, None] * first + orders[None, :] * second).ravel()
    distance = np.abs(peaks[:, None] - combinations[None, :]).min(axis=1)
    if np.all(distance <= tolerance):
        return tuple(sorted((first, second)))
    return ()


# ------------------------------------------------------------------------------ the class
def classify(f, jac, y0, *, transient: float, duration: float, dt: float,
             scale: np.ndarray | float | None = None, section_state: int | None = None,
             rtol: float = 1e-8, atol: np.ndarray | float | None = None,
             bound: np.ndarray | float = np.inf, method: str = "DOP853",
             renormalise: float | None = None, amplitude_tolerance: float = 1e-6,
             section_tolerance: float = 1e-2, lyapunov_tolerance: float | None = None,
             seed: int = 0, extend: int = 0) -> MotionClass:
    """The settled motion of dy/dt = ``f(y)`` from ``y0`` (see the module doc for the rule).

    ``transient``: seconds discarded (state only); ``duration``: seconds of settled window
    (state + tangent vector), sampled every ``dt`` seconds (at least ~30 samples per period
    of the fastest motion that matters: the section's cubic interpolation and the spectrum
    use the samples); ``scale`` (per state, default 1): typical sizes, for the amplitude
    test, the spectrum and the default ``atol`` (``rtol`` x 1e-3 x scale); ``bound``: |y_i|
    beyond it is divergence (per state or one number); ``section_state``: the state whose
    mean level, crossed upwards, defines the section (default: the one with the largest
    standard deviation / scale); ``method``, ``rtol``, ``renormalise``: the integration
    (:func:`whirl_cli.analysis.lyapunov.tangent_run`); ``extend``: how many times the window
    may be doubled where section and spectrum disagree (module doc; the run continued from
    its end)."""
    y0 = np.asarray(y0, dtype=float)
    n = y0.size
    scale = np.broadcast_to(np.asarray(1.0 if scale is None else scale, dtype=float), (n,))
    if atol is None:
        atol = rtol * 1e-3 * scale
    run = tangent_run(f, jac, y0, transient, duration, dt, renormalise=renormalise, rtol=rtol,
                      atol=atol, bound=bound, method=method, scale=scale, seed=seed,
                      at_rest=amplitude_tolerance)
    finer = 0
    while finer < MAX_RESAMPLES and _aliased(run, scale):
        # a motion faster than ``dt`` resolves: the window again, from its end, finer
        dt, finer = dt / RESAMPLE, finer + 1
        run = tangent_run(f, jac, run.states[-1], 0.0, duration, dt, rtol=rtol, atol=atol,
                          bound=bound, method=method, scale=scale, renormalise=renormalise,
                          tangent=run.tangent)
    motion = _classified(run, scale, amplitude_tolerance, section_state, section_tolerance,
                         lyapunov_tolerance)
    if finer:
        motion = replace(motion, evidence=f"{motion.evidence}; sampled {RESAMPLE ** finer}x "
                         "finer (the first window's spectrum reached its Nyquist frequency)")
    if np.isfinite(run.settled):
        motion = replace(motion, evidence=f"{motion.evidence}; the transient ended at t = "
                         f"{run.settled:.4g} s, at rest at a linearly stable point")
    for _ in range(extend):
        if not _undecided(motion) or run.tangent is None:
            break
        # the section and the spectrum disagree: a window as long again, continued (state and
        # tangent) from its end, resolves a second frequency twice as fine
        more = tangent_run(f, jac, run.states[-1], 0.0, run.time[-1], dt, rtol=rtol,
                           atol=atol, bound=bound, method=method, scale=scale,
                           renormalise=renormalise, tangent=run.tangent)
        run = TangentRun(np.r_[run.time, run.time[-1] + more.time[1:]],
                         np.concatenate((run.states, more.states[1:])),
                         np.r_[run.growth, run.growth[-1] + more.growth[1:]], more.diverged,
                         more.message, more.tangent)
        first = motion.evidence.split(":")[0]
        motion = _classified(run, scale, amplitude_tolerance, section_state, section_tolerance,
                             lyapunov_tolerance)
        motion = replace(motion, evidence=f"{motion.evidence}; window doubled to "
                         f"{run.time[-1]:.4g} s (before: {first}, the section and the spectrum "
                         "disagreeing)")
    return motion


def _aliased(run: TangentRun, scale: np.ndarray) -> bool:
    """True if the window's spectrum holds more than ALIASED_POWER of its power above 3/4 of
    its Nyquist frequency (a window that diverged, came to rest or is too short: False)."""
    if run.diverged or run.tangent is None or len(run.time) < 16 or np.isfinite(run.settled):
        return False
    frequency, power = spectrum(run.time, run.states, scale)
    total = power[1:].sum()
    return bool(total > 0 and power[frequency > 0.75 * frequency[-1]].sum() > ALIASED_POWER
                * total)


def _undecided(motion: MotionClass) -> bool:
    """The section did not repeat while the spectrum says periodic, or lambda is not resolved
    from zero and the section is a cloud: what a longer window may settle."""
    return motion.kind != MotionKind.DIVERGED and (SPECTRUM_ONLY in motion.evidence
                                          or WEAKLY_CHAOTIC in motion.evidence)


def _classified(run: TangentRun, scale: np.ndarray, amplitude_tolerance: float,
                section_state: int | None, section_tolerance: float,
                lyapunov_tolerance: float | None) -> MotionClass:
    """The class of a :class:`~whirl_cli.analysis.lyapunov.TangentRun` (the module doc's rule)."""
    n = run.states.shape[1]
    empty = np.zeros((0, n))
    if run.diverged:
        return MotionClass(MotionKind.DIVERGED, np.nan, np.nan, (), empty, np.nan, 0, (), np.nan,
                           f"diverged: the trajectory {run.message}")
    time, states = run.time, run.states
    span = np.ptp(states, axis=0) / scale
    spread = np.std(states, axis=0)
    if span.max() < amplitude_tolerance or len(time) < 8:
        exponent, error = exponent_between(time, run.growth)
        return MotionClass(MotionKind.EQUILIBRIUM, exponent, error, (), empty, np.nan, 0, (),
                           np.nan,
                           f"equilibrium: the settled motion spans {span.max():.2g} scales "
                           f"(< {amplitude_tolerance:g}); lambda = {exponent:.3g} 1/s")
    index = int(np.argmax(spread / scale)) if section_state is None else int(section_state)
    crossings, section = poincare_section(time, states, index)
    exponent, error = exponent_between(time, run.growth,
                                       crossings if len(crossings) > 11 else None)
    # (a) section geometry in units of each state's spread, at least 1e-2 of the largest
    # motion (in the states' scales): a state that hardly moves is not judged by its
    # integration error
    units = np.maximum(spread, 1e-2 * scale * np.max(spread / scale))
    multiplicity, dimension, drift, converging, rate = section_geometry(section, units,
                                                                         section_tolerance)
    # (c) spectrum
    frequency, power = spectrum(time, states, scale)
    peaks, _, broadband = spectral_peaks(frequency, power)
    bins = frequency[1]
    bases = base_frequencies(peaks, 1.5 * bins)
    dominant = float(peaks[0]) if len(peaks) else 0.0
    threshold = (lyapunov_tolerance if lyapunov_tolerance is not None
                 else 0.01 * 2 * np.pi * max(dominant, 1.0 / time[-1]))
    returns = float(np.mean(np.diff(crossings))) if len(crossings) > 1 else np.nan
    evidence = [
        f"Lyapunov: lambda = {exponent:.4g} +- {error:.2g} 1/s (threshold {threshold:.3g})",
        f"section on state {index}: {len(section)} points, "
        + (f"repeats with lag {multiplicity} (within {drift:.2g})" if multiplicity else
           f"no repeat with lag <= {MAX_MULTIPLICITY} (lag-1 spread {drift:.2g})")
        + f", correlation dimension {dimension:.2f}",
        f"spectrum: peaks {', '.join(f'{p:.4g}' for p in peaks[:6])} Hz, "
        + (f"{len(bases)} base frequenc{'y' if len(bases) == 1 else 'ies'}" if bases
           else "no one or two bases") + f", {100 * broadband:.2g} % broadband"]
    strongest = tuple(float(p) for p in peaks[:3])
    if exponent < -(threshold + 3 * error) or len(section) < 3:
        kind, found = MotionKind.EQUILIBRIUM, ()
        if len(section) < 3 and exponent >= -(threshold + 3 * error):
            evidence.append("fewer than 3 section crossings: no oscillation left")
    elif exponent > threshold + 3 * error:
        kind, found = MotionKind.CHAOTIC, strongest
    elif multiplicity:
        kind, found = MotionKind.PERIODIC, (1.0 / (multiplicity * returns),)
    elif converging:
        multiplicity = converging
        kind, found = MotionKind.PERIODIC, (1.0 / (multiplicity * returns),)
        evidence.append(f"not settled: the section's lag-{converging} distances shrink by "
                        f"{rate:.3g} per return, towards a period-{converging} orbit")
    elif len(bases) == 1 and broadband < 0.01:
        kind, found = MotionKind.PERIODIC, bases
        evidence.append(f"{SPECTRUM_ONLY} within {section_tolerance:g}")
    elif (np.isfinite(dimension) and dimension < CURVE_DIMENSION) or len(bases) == 2:
        others = [p for p in peaks if abs(p * returns - round(p * returns)) > 1.5 * bins
                  * returns]
        kind, found = MotionKind.QUASI_PERIODIC, (1.0 / returns,) + ((float(others[0]),) if others
                                                             else ())
    else:
        kind, found = MotionKind.CHAOTIC, strongest
        evidence.append(f"{WEAKLY_CHAOTIC}: lambda not resolved from zero, the section a cloud")
    return MotionClass(kind, exponent, error, tuple(found), section, dimension, multiplicity,
                       tuple(float(p) for p in peaks), broadband,
                       f"{kind}: " + "; ".join(evidence))


# ------------------------------------------------------------------------------ whirl models
def classify_model(model, overrides: dict[str, float] | None = None, y0=None, *,
                   periods: float = 20.0, transient_periods: float = 15.0,
                   samples_per_period: int = 40, rtol: float = 1e-6,
                   bound: float = 10.0, method: str = "odeint", extend: int = 1,
                   **options) -> MotionClass:
    """:func:`classify` for a whirl model (:class:`whirl_cli.models.Model`) at the parameter
    values ``overrides`` (study names, as :func:`whirl_cli.analysis.simulate.integrate`'s
    callers build them: defaults with these applied), from ``y0`` (SI; default: every dof at
    1e-2 of its typical amplitude, rates zero), with the model's analytic Jacobian
    (``Model.field_at``).

    Durations from the linearisation at the origin (the models' trivial equilibrium; at ``y0``
    if the origin is not an equilibrium): T_w = 2 pi / Im(lambda) of the least damped
    oscillatory eigenvalue (the whirl mode that goes unstable; without one, the slowest decay
    time 1 / |Re lambda|); the transient is ``transient_periods`` T_w (state only), the window
    ``periods`` T_w (state + tangent), sampled at T_w / ``samples_per_period``, doubled once
    (``extend``) where section and spectrum disagree. LSODA through ``odeint`` (``method``; it
    steps over the lightly excited fast gimbal modes of the gimballed model where DOP853 has
    to resolve them: half the cost) at ``rtol`` (1e-6; atol ``rtol`` x 1e-3 x the state
    scales, i.e. 1e-9 rad for the classical model's angles), on the generated field with
    Python-float states (the generated scalar code is faster on them than on numpy scalars);
    |y_i| > ``bound`` x the state scale (10 rad) is divergence. ``options``: the other
    keywords of :func:`classify`. The cost grows with the simulated time (a slow whirl mode
    means long periods) and with the fastest mode, which sets LSODA's step (the gimballed
    model's gimbal modes); ``docs/performance.md`` gives the current figures."""
    params = model.parameter_vector(overrides or {})
    field, jacobian = model.field_at(params)
    scale = np.asarray(model.state_scale, dtype=float)
    if y0 is None:
        y0 = np.zeros(model.n_states)
        y0[list(model.positions)] = 1e-2 * scale[list(model.positions)]
    y0 = np.asarray(y0, dtype=float)
    origin = np.zeros(model.n_states)
    at = origin if np.allclose(field(origin), 0.0, atol=1e-12) else y0
    eigenvalues = np.linalg.eigvals(jacobian(at))
    oscillatory = eigenvalues[np.abs(eigenvalues.imag) > 1e-9 * np.abs(eigenvalues).max()]
    if len(oscillatory):
        period = 2 * np.pi / abs(oscillatory[np.argmax(oscillatory.real)].imag)
    else:
        period = 1.0 / max(float(np.abs(eigenvalues.real).min()), 1e-3)
    dt = period / samples_per_period
    return classify(field, jacobian, y0, transient=transient_periods * period,
                    duration=periods * period, dt=dt, scale=scale,
                    rtol=rtol, bound=bound * scale, method=method, extend=extend, **options)
