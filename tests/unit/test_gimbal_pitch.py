"""How the gimballed rotor holds blade pitch, checked against strip theory derived here
(tests/gimbal_strip_theory.py): the built-in ``gimballed`` model at ``pitch_on_disc = 1`` (the
datum) is the derivation with blade pitch held relative to the tilted disc, at 0 the one with
pitch held relative to the shaft (a swashplate's pitch links, delta3 = 0), in between the linear
interpolation of the two. Only the shaft pitch has the rotating frame's flap damping, and only
the disc pitch the low-speed flutter of the gimbal's low-frequency mode at tiltrotor gimbals
(1.02-1.10/rev).
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest
import sympy as sp
from scipy.optimize import brentq

from tests.gimbal_strip_theory import A_LEVER, MU, aerodynamic, matrices
from tests.gimballed_exact import DATUM
from whirl_cli.analysis import linear
from whirl_cli.models import get_model
from whirl_cli.models.symbolic import Symbolic

MODEL = get_model("gimballed")
#: the parameter that holds blade pitch on the shaft
SHAFT = {"pitch_on_disc": 0.0}
#: whirl's (thesis) frame to the derivation frame: psi and beta_z negated
FRAME = np.array([1, -1, 1, -1], dtype=float)
#: K_beta of a gimbal at nu per rev: I_d Omega^2 (nu^2 - 1), the datum I_d and Omega
TILTROTOR = {nu: DATUM["I_d"] * DATUM["Omega"] ** 2 * (nu**2 - 1) for nu in (1.02, 1.05, 1.10)}
#: the stiffness terms the feathering of the blades touches: the nacelle rows' gimbal columns,
#: each gimbal row's other gimbal column
FEATHERING = np.zeros((4, 8), dtype=bool)
FEATHERING[0:2, 2:4] = FEATHERING[2, 3] = FEATHERING[3, 2] = True
#: parameter sets of the term-by-term comparison: the datum at three airspeeds, and one with
#: every parameter the terms hold moved off the datum
CASES = [{"V": 0.5}, {"V": 6.7, "K_beta": 0.01}, {"V": 15.0},
         {"V": 4.0, "a": 0.4, "c": 0.03, "R": 0.17, "Omega": 55.0, "rho": 1.1, "N": 3.0,
          "I_x": 0.00012, "I_d": 0.00006, "K_beta": 0.5, "C_beta": 0.002}]


@cache
def _compiled_terms(model):
    """d R_i / d(q_j, q'_j) at the origin of ``model``'s own expressions (R = M q'' in whirl's
    frame), compiled in the model's parameters."""
    sym = Symbolic(model)
    names = [sp.Symbol(n, real=True) for n in model.state_names]
    origin = {n: 0 for n in names}
    terms = sp.Matrix([[sp.diff(row, n).subs(origin) for n in names] for row in sym.residual[:4]])
    return sp.lambdify([sp.Symbol(p.name, real=True) for p in model.parameters], terms, "numpy")


def _model_terms(model, values: dict) -> np.ndarray:
    """The terms of :func:`_compiled_terms` at ``values`` over the datum, mapped to the
    derivation frame: a 4 x 8 array."""
    terms = np.array(_compiled_terms(model)(*model.parameter_vector(values)), dtype=float)
    frame = np.concatenate([FRAME, FRAME])
    return FRAME[:, None] * terms * frame[None, :]


def _derived_terms(values: dict, shaft: bool) -> np.ndarray:
    """The same terms from the strip-theory derivation: -(K | D) of its matrices."""
    v = {**DATUM, **values}
    _, damping, stiffness = matrices(v, shaft)
    return -np.hstack([stiffness, damping])


@pytest.mark.parametrize("values", CASES)
def test_the_built_in_model_is_the_derivation_with_pitch_held_on_the_tilted_disc(values):
    """Every stiffness and damping term of every row of the built-in model equals strip theory
    with pitch relative to the tilted disc (1e-9 of the row's largest term); the shaft-pitch
    derivation differs from it in exactly the terms the blades' feathering touches."""
    generated = _model_terms(MODEL, values)
    disc, shaft = _derived_terms(values, False), _derived_terms(values, True)
    scale = np.abs(disc).max(axis=1, keepdims=True)
    np.testing.assert_allclose(generated / scale, disc / scale, rtol=0, atol=1e-9)
    differs = np.abs(shaft - disc) > 1e-6 * scale
    assert (differs == FEATHERING).all()


@pytest.mark.parametrize("values", CASES)
def test_pitch_on_disc_0_is_the_derivation_with_pitch_held_on_the_shaft(values):
    """At pitch_on_disc = 0 the model's terms equal strip theory with pitch relative to the
    shaft (1e-9); at 1 (given or the datum) the disc's, and at 0.3 the linear interpolation
    0.3 disc + 0.7 shaft of the two derivations."""
    disc, shaft = _derived_terms(values, False), _derived_terms(values, True)
    scale = np.abs(shaft).max(axis=1, keepdims=True)
    for fraction in (0.0, 0.3, 1.0):
        generated = _model_terms(MODEL, {**values, "pitch_on_disc": fraction})
        expected = fraction * disc + (1 - fraction) * shaft
        np.testing.assert_allclose(generated / scale, expected / scale, rtol=0, atol=1e-9)
    assert MODEL.parameter("pitch_on_disc").default == 1.0


def test_the_two_derivations_differ_by_the_feathering_of_the_blades():
    """Shaft minus disc, in units of Q c/R: the stiffness on the gimbal coordinates of a blade
    feathered by -(beta_y cos + beta_z sin), -(A_3 + A'_2) and -a (A_2 + A'_1) in the closed
    forms of models.md 2.2 (per c/R), and nothing else."""
    ash, root = sp.asinh(1 / MU), sp.sqrt(1 + MU**2)
    a1, a2 = MU**2 * ash, (MU / 2) * (root - MU**2 * ash)
    a3 = ((2 - 3 * MU**2) * root + 3 * MU**4 * ash) / 8
    tilt, lever = a3 + MU * a2, A_LEVER * (a2 + MU * a1)
    expected = sp.zeros(4, 8)
    expected[0, 2], expected[0, 3] = -lever, -tilt
    expected[1, 2], expected[1, 3] = tilt, -lever
    expected[2, 3], expected[3, 2] = -tilt, tilt
    difference = aerodynamic(True) - aerodynamic(False)
    assert sp.simplify(difference - expected) == sp.zeros(4, 8)


def test_at_hover_the_shaft_pitch_gimbal_has_the_rotating_frames_flap_damping():
    """V = 0, nacelle held (K_theta = K_psi = 1e9): the rotating frame's flap equation
    b'' + (gamma/8) Omega b' + nu^2 Omega^2 b = 0 (Lock number gamma = rho C_l_alpha c R^4 /
    (I_x / N), nu^2 = 1 + K_beta / (I_d Omega^2)) seen from the nacelle puts both gimbal modes
    at Re = -gamma Omega / 16 and Im = Omega (1 +- sqrt(nu^2 - (gamma/16)^2)). The model with
    pitch on the shaft has them (1e-6); with pitch on the disc it does not (its low mode is
    damped at a third of that rate or less)."""
    v = DATUM
    gamma = v["rho"] * v["C_l_alpha"] * v["c"] * v["R"] ** 4 / (v["I_x"] / v["N"])
    omega, nu = v["Omega"], 1.05
    held = {"V": 0.0, "K_theta": 1e9, "K_psi": 1e9, "K_beta": TILTROTOR[nu]}
    rotating = np.sqrt(nu**2 - (gamma / 16) ** 2)
    expected = np.sort(omega * np.array([1 + rotating, abs(1 - rotating)]))
    for pitch, textbook in ((SHAFT, True), ({}, False)):
        values = np.linalg.eigvals(MODEL.jacobian_numpy(
            np.zeros(8), MODEL.parameter_vector({**held, **pitch})))
        gimbal = values[(np.abs(values) < 3 * omega) & (values.imag > 0)]
        gimbal = gimbal[np.argsort(gimbal.imag)]
        assert len(gimbal) == 2
        if textbook:
            np.testing.assert_allclose(gimbal.real, -gamma * omega / 16, rtol=1e-6)
            np.testing.assert_allclose(gimbal.imag, expected, rtol=1e-6)
        else:
            assert gimbal[0].real > -gamma * omega / 16 / 3


def _growth(v: float, values: dict, shaft: bool) -> float:
    mass, damping, stiffness = matrices({**values, "V": v}, shaft)
    minv = np.linalg.inv(mass)
    first_order = np.block([[np.zeros((4, 4)), np.eye(4)], [-minv @ stiffness, -minv @ damping]])
    return np.linalg.eigvals(first_order).real.max()


@pytest.mark.parametrize("nu", sorted(TILTROTOR))
def test_the_low_speed_gimbal_flutter_is_the_disc_pitchs(nu):
    """Tiltrotor gimbal, K_psi = 0.3, eigenvalues of the derived matrices: with pitch on the
    tilted disc the origin is stable at V = 0.05 and loses stability below 1.5 m/s, where the
    built-in model's first critical point lies (1e-6); with pitch on the shaft no eigenvalue
    has Re >= 0 from 0 to 15 m/s, and the model's first critical point at pitch_on_disc = 0 is
    the derived first one (1e-6), above 15 m/s."""
    values = {"K_psi": 0.3, "K_beta": TILTROTOR[nu]}
    speeds = np.linspace(0.05, 1.5, 30)
    growth = [_growth(v, values, False) for v in speeds]
    assert growth[0] < 0 < growth[-1]
    k = int(np.argmax(np.array(growth) > 0))
    onset = brentq(_growth, speeds[k - 1], speeds[k], args=(values, False), xtol=1e-12)
    (first, *_) = linear.critical_points(MODEL, values, "V", 0.0, 3.0)
    assert first.value == pytest.approx(onset, rel=1e-6)

    speeds = np.linspace(0.0, 30.0, 601)
    growth = np.array([_growth(v, values, True) for v in speeds])
    assert (growth[speeds <= 15.0] < 0).all()
    k = int(np.argmax(growth > 0))
    onset = brentq(_growth, speeds[k - 1], speeds[k], args=(values, True), xtol=1e-12)
    (first, *_) = linear.critical_points(MODEL, {**values, **SHAFT}, "V", 0.0, 30.0,
                                         points=6001)
    assert first.value == pytest.approx(onset, rel=1e-6) and onset > 15.0
