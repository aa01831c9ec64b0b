"""whirl's freeplay law (../shared/models.md section 7) on the real AUTO-07p and gfortran:
the generated Fortran never overflows, the offset equilibria of pitch freeplay are the closed
form with the stability of the linear model at K_theta = K_out, and doubling delta (epsilon /
delta fixed) leaves every bifurcation airspeed in place and doubles every amplitude."""

from __future__ import annotations

import math
import subprocess

import numpy as np
import pytest

from tests.strip_theory import coefficients
from whirl_cli.analysis import linear
from whirl_cli.auto.codegen import fortran_source
from whirl_cli.auto.constants import par_layout
from whirl_cli.models import get_model
from whirl_cli.pipeline import run_study
from whirl_cli.results import PointType
from whirl_cli.study import validate_text

from .helpers import offset_equilibria_at_zero

DELTA = math.radians(1.0)
K_PSI = 0.3


@pytest.fixture(scope="module")
def freeplay():
    return get_model("classical", ("freeplay", "polynomial"))


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    cache: dict = {}

    def get(text: str):
        if text not in cache:
            cache[text] = run_study(validate_text(text), tmp_path_factory.mktemp("freeplay"),
                                    jobs=2)
            # every run converged, but the short runs of the persistence check, which may
            # end in MX (their point is then recomputed by repeating the continuation)
            runs = [r for r in cache[text].runs if ".shrink_" not in r.name]
            assert [r.status for r in runs] == ["ok"] * len(runs), runs
        return cache[text]

    return get


# ------------------------------------------------------------------------------ Fortran
DRIVER = """
PROGRAM DRIVER
  IMPLICIT NONE
  INTEGER, PARAMETER :: N = {n}, NPAR = {npar}
  DOUBLE PRECISION :: U(N), PAR(NPAR), F(N), DFDU(N,N), DFDP(N,NPAR)
  INTEGER :: ICP(1)
  ICP = 1
  PAR = 0d0
  READ (*,*) U
  READ (*,*) PAR
  DFDP = 0d0
  CALL FUNC(N, U, ICP, PAR, 2, F, DFDU, DFDP)
  WRITE (*,'(ES25.16)') F, DFDU, DFDP
END PROGRAM DRIVER

DOUBLE PRECISION FUNCTION GETP(CODE, IC, UPS)
  CHARACTER(*), INTENT(IN) :: CODE
  INTEGER, INTENT(IN) :: IC
  DOUBLE PRECISION, INTENT(IN) :: UPS(*)
  GETP = 0d0
END FUNCTION GETP
"""


def test_generated_fortran_never_overflows(freeplay, tmp_path):
    """FUNC with its Jacobians DFDU and DFDP, compiled with gfortran trapping overflow,
    invalid operations and division by zero, at |theta| = 1e6 epsilon (epsilon = delta/100
    and 1e-9 delta): finite, and F equals the numpy module's right-hand side (1e-12)."""
    layout = par_layout(freeplay)
    (tmp_path / "model.f90").write_text(fortran_source(freeplay))
    (tmp_path / "driver.f90").write_text(DRIVER.format(n=freeplay.n_states, npar=layout.npar))
    subprocess.run(["gfortran", "-O1", "-ffpe-trap=overflow,invalid,zero", "-o", "driver",
                    "model.f90", "driver.f90"], cwd=tmp_path, check=True, capture_output=True)
    scale = np.asarray(freeplay.state_scale)
    for fraction in (1e-2, 1e-9):
        epsilon = fraction * DELTA
        values = {"K_psi": K_PSI, "delta_theta": DELTA, "epsilon_theta": epsilon}
        params = freeplay.parameter_vector(values)
        par = np.zeros(layout.npar)
        for name, value in zip(freeplay.parameter_names, params, strict=True):
            par[layout.parameters[name] - 1] = value
        for theta in (1e6 * epsilon, -1e6 * epsilon, DELTA + epsilon):
            y = np.array([theta, 0.5 * theta, 0.1, -0.1])
            text = "\n".join(" ".join(repr(float(v)) for v in row) for row in (y / scale, par))
            done = subprocess.run(["./driver"], cwd=tmp_path, input=text + "\n",
                                  capture_output=True, text=True, timeout=30)
            assert done.returncode == 0, done.stderr  # a trapped FPE is SIGFPE
            numbers = np.array(done.stdout.split(), dtype=float)
            assert np.isfinite(numbers).all()
            f = numbers[:freeplay.n_states] * scale * freeplay.time_scale
            np.testing.assert_allclose(f, freeplay.rhs_numpy(y, params), rtol=1e-12,
                                       atol=1e-12 * np.abs(f).max())


# ------------------------------------------------------------------------------ equilibria
def aerodynamic_stiffness(overrides: dict[str, float]) -> tuple[float, float]:
    """(k_d, k_c) of models.md 2.3 at the datum with ``overrides``, from the strip-theory
    formulas evaluated directly (sympy, not the generated code)."""
    model = get_model("classical")
    values = {**model.defaults(), **overrides}
    import sympy as sp

    symbols = {name: sp.Float(value, 30) for name, value in values.items()}
    k_d, k_c, _ = coefficients(symbols)
    return float(k_d), float(k_c)


EQUILIBRIA = f"""
name: freeplay-offset
model: classical
parameters: {{K_psi: {K_PSI}}}
nonlinearity: {{type: freeplay, dof: theta, delta: {DELTA!r}, K_out: 0.4, K_in: 0.1}}
continuations:
  - {{name: kin, type: one-parameter, parameter: K_in_theta, range: [0.0, 0.1],
      orbits_at: [0.0]}}
"""


def test_offset_equilibria_of_pitch_freeplay_are_the_closed_form(run):
    """Continued in K_in from 0.1 down to 0, the origin's pitchfork (at K_in = K_div) leads to
    the offset equilibria; at K_in = 0 (AUTO's labelled point) they are theta_e = +-delta
    K_out/(K_out - K_div), psi_e = k_c theta_e/(K_psi - k_d) (models.md 7 point 2 and 2.4)
    to 1e-6 relative, and their eigenvalues are the linear model's at K_theta = K_out (1e-5
    relative: AUTO prints 6 digits), so the stability too."""
    k_d, k_c = aerodynamic_stiffness({"K_psi": K_PSI})
    assert (k_d, k_c) == pytest.approx((0.04657, 0.05179), abs=1e-5)  # models.md 2.3 datum
    k_div = k_d - k_c**2 / (K_PSI - k_d)
    theta_e = DELTA * 0.4 / (0.4 - k_div)
    psi_e = k_c * theta_e / (K_PSI - k_d)
    result = run(EQUILIBRIA)
    (continuation,) = result.continuations
    (pitchfork,) = [p for p in continuation.special_points if p.point_type == PointType.BP]
    assert pitchfork.parameters[0] == pytest.approx(k_div, rel=1e-6)
    model = get_model("classical")
    at_k_out = model.parameter_vector({"K_psi": K_PSI, "K_theta": 0.4})[:, None]
    expected = np.sort_complex(linear.analyse(model, at_k_out)[0][0])
    found = 0
    for branch, row in offset_equilibria_at_zero(continuation):
        theta, psi = branch.state_max[row, :2]
        sign = np.sign(theta)
        assert theta == pytest.approx(sign * theta_e, rel=1e-6)
        assert psi == pytest.approx(sign * psi_e, rel=1e-6)
        ours = np.sort_complex(branch.eigenvalues[row])
        np.testing.assert_allclose(ours, expected, rtol=1e-5)
        assert bool(branch.stable[row]) == bool((expected.real < 0).all())
        found += 1
    assert found == 2


# ------------------------------------------------------------------------------ scaling
def airspeed_study(delta: float) -> str:
    """Pitch freeplay with K_in = 0.05 (the origin's pitchfork at V where K_div(V) = K_in)
    and K_out = 0.6 (the offset equilibria's Hopf point inside the range), equilibria in V;
    small steps: AUTO's arc length mixes V with states in rad, and the gap is ~1e-2 rad."""
    return f"""
name: freeplay-scaling
model: classical
parameters: {{K_psi: {K_PSI}}}
nonlinearity: {{type: freeplay, dof: theta, delta: {delta!r}, K_out: 0.6, K_in: 0.05,
                epsilon: {delta / 100!r}}}
continuations:
  - {{name: v, type: one-parameter, parameter: V, start: 5.0, range: [5.0, 11.0]}}
auto: {{step_max: 0.0005, step_initial: 0.0001, max_steps: 4000}}
"""


def test_doubling_delta_keeps_bifurcation_airspeeds_and_doubles_amplitudes(run):
    """models.md 7 point 1: under (state, delta) -> (2 state, 2 delta) with epsilon/delta
    fixed, every Hopf and branch point keeps its airspeed (1e-4 relative, here far closer) and
    doubles its state (1e-6 of delta); the offset equilibria theta(V), psi(V) double (1e-6 of
    delta, compared where they lie outside the gap, interpolated at common airspeeds)."""
    one, two = run(airspeed_study(DELTA)), run(airspeed_study(2 * DELTA))

    def points(result):
        found = [(p.type_name, p.branch, float(p.parameters[0]), p.state[:2])
                 for p in result.continuations[0].special_points
                 if p.point_type in (PointType.HB, PointType.BP)]
        return sorted(found, key=lambda f: (f[0], f[1], f[2]))

    ones, twos = points(one), points(two)
    kinds = [(kind, branch) for kind, branch, _, _ in ones]
    assert kinds == [(kind, branch) for kind, branch, _, _ in twos]
    # the origin's Hopf point and pitchfork, two Hopf points on each offset branch
    assert sum(k == "HB" for k, _ in kinds) == 5 and sum(k == "BP" for k, _ in kinds) == 1
    for (_, _, v1, s1), (_, _, v2, s2) in zip(ones, twos, strict=True):
        assert v2 == pytest.approx(v1, rel=1e-4)
        np.testing.assert_allclose(s2, 2 * s1, atol=1e-6 * DELTA)
    compared = 0
    for a in one.continuations[0].branches:
        if not a.name.startswith("secondary"):
            continue
        (b,) = [x for x in two.continuations[0].branches if x.name == a.name]
        outside = lambda br, d: np.abs(br.state_max[:, 0]) > 1.02 * d  # noqa: E731
        va, vb = a.parameters[outside(a, DELTA), 0], b.parameters[outside(b, 2 * DELTA), 0]
        assert np.all(np.diff(va) > 0) and np.all(np.diff(vb) > 0)  # one monotone stretch
        common = np.linspace(max(va[0], vb[0]), min(va[-1], vb[-1]), 50)
        for dof in range(2):
            ya = np.interp(common, va, a.state_max[outside(a, DELTA), dof])
            yb = np.interp(common, vb, b.state_max[outside(b, 2 * DELTA), dof])
            np.testing.assert_allclose(yb, 2 * ya, atol=1e-6 * DELTA)
        compared += 1
    assert compared == 2


# ------------------------------------------------------------------------------ limit cycles
LCO = f"""
name: freeplay-lco
model: classical
parameters: {{K_psi: {K_PSI}}}
nonlinearity:
  - {{type: freeplay, dof: theta, delta: {DELTA!r}, K_out: 0.4, K_in: 0.05}}
  - {{type: polynomial, dof: psi, K2: 100.0}}
continuations:
  - {{name: v, type: one-parameter, parameter: V, start: 5.0, range: [5.0, 7.2],
      periodic: true, branch_points: false}}
auto: {{step_max: 0.001, step_initial: 0.0001}}
cross_check: true
"""


def test_freeplay_lco_cross_check_simulates_the_exact_law_too(run):
    """The family of the origin's Hopf point (K_in = 0.05 in the gap; a cubic on yaw bends it)
    grows out of the gap (A/delta > 1.2 at 7.2 m/s); the orbit cross-checks simulate the
    smoothed and the exact piecewise law from AUTO's orbit, and both maxima stay within 1 % of
    AUTO's half peak-to-peak value, also for an orbit outside the gap."""
    (continuation,) = run(LCO).continuations
    (family,) = [b for b in continuation.branches if b.is_periodic]
    orbits = [x for x in continuation.cross_checks if x.kind == "orbit"]
    assert orbits and all(x.passed for x in orbits), orbits
    (found,) = continuation.freeplay
    outside = 0
    for x in orbits:
        assert x.exact is not None and np.isfinite(x.exact) and x.state == "theta"
        half = (family.state_max[x.index, 0] - family.state_min[x.index, 0]) / 2
        assert abs(x.exact - x.expected) < 0.01 * half
        assert abs(x.simulated - x.expected) < 0.01 * half
        outside += found.amplitude_ratio[x.index] > 1.1
    assert outside >= 1


def test_freeplay_amplitudes_and_describing_function_estimate(run, tmp_path):
    """A/delta of every row is the stored orbit's half peak-to-peak pitch over delta (1e-6);
    each estimate row is a Hopf point of the linear model with K_theta = K_eq(A) (the
    eigenvalues there have a pair on the imaginary axis, |Re| < 1e-7 |lambda|), K_eq rises
    from K_in at A = delta; both survive the HDF5 file and draw as the amplitude plot."""
    from whirl_cli.output import store
    from whirl_cli.plots.files import render_study_plots

    result = run(LCO)
    (continuation,) = result.continuations
    (family,) = [b for b in continuation.branches if b.is_periodic]
    (found,) = continuation.freeplay
    assert found.branch == family.name and found.dof == "theta"
    assert found.amplitude_ratio.max() > 1.2
    for orbit in family.orbits:
        half = np.ptp(orbit.states[:, 0]) / 2
        assert found.amplitude_ratio[orbit.index] == pytest.approx(half / DELTA, rel=1e-6)
    assert found.estimate_ratio[0] == 1.0 and found.estimate_stiffness[0] == pytest.approx(0.05)
    assert np.all(np.diff(found.estimate_stiffness) > 0)
    model = get_model("classical")
    for k_eq, speed in zip(found.estimate_stiffness, found.estimate_parameter, strict=True):
        params = model.parameter_vector({"K_psi": K_PSI, "K2_psi": 100.0, "K_theta": k_eq,
                                         "V": speed})
        eigenvalues = np.linalg.eigvals(model.jacobian_numpy(np.zeros(4), params))
        critical = eigenvalues[np.argmin(np.abs(eigenvalues.real))]
        assert abs(critical.real) < 1e-7 * abs(critical) and abs(critical.imag) > 1.0
    path = tmp_path / "lco.h5"
    store.write(result, path)
    stored = store.read(path).continuations[0]
    assert stored.cross_checks == continuation.cross_checks  # the exact-law maxima too
    (again,) = stored.freeplay
    for key in ("amplitude_ratio", "estimate_ratio", "estimate_stiffness",
                "estimate_parameter"):
        np.testing.assert_array_equal(getattr(again, key), getattr(found, key))
    (name, png), = render_study_plots(result, ("amplitude",), "lco")
    assert name == "lco_v_amplitude.png" and png.startswith(b"\x89PNG")
