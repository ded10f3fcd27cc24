"""The drivers of the public API (:mod:`fretwear`), and the one place that decides the
time-domain fallback for them and for the case-file analyses.

One vocabulary and one argument order at every entry point: ``(model, basis, ...)`` first
(``model`` alone for the time-domain drivers, which have no Fourier basis), then what the call
is about (``frequency`` [Hz], or ``f_min, f_max, n_points`` [Hz] for a frequency band); the
stick anchors are ``anchor``, the initial wear ``wear0``, the Archard coefficient
``wear_coefficient``; ``frequency`` is required wherever it matters (a quasi-static solve can
do without: it then only scales time). The older spellings (``stick_anchor``, ``W0``,
``k_w``) are refused with a TypeError that names the new one.

:func:`fretwear.hb.sweep.sweep`, :func:`fretwear.hb.periodic.solve_periodic` and
:func:`fretwear.wear.simulate.simulate_wear` never import the time-domain solver
(:mod:`fretwear.hb.fallback`); the drivers here pass
:data:`fretwear.timedomain.fallback.FALLBACK` unless ``time_domain=False``: on by default, as
in case files, whose key ``time_domain`` is this argument (the analyses of
:mod:`fretwear.analyses` call these drivers). Every other keyword is passed to the function
named in the docstring unchanged, with its default: each option has one default, that of the
function that uses it. :func:`sweep` and :func:`simulate_wear`, the drivers a user calls
first, have real signatures instead (every keyword of the core function, each documented, so
that ``help()`` and an IDE show them; docs/architecture.md records why they take more than
nine parameters). ``condenser=`` is among the keywords: the condenser of the model
(:func:`fretwear.hb.reduce.exact_condenser` or :func:`fretwear.hb.modal.modal_condenser`),
built once by the caller and passed to every driver that condenses the same model.
"""

from __future__ import annotations

import contextlib
import dataclasses
import functools
import math
import warnings

from fretwear import linear as _linear
from fretwear import wear as _wear
from fretwear.errors import InputError
from fretwear.hb import mode_synthesis as _synth
from fretwear.hb import nonlinear_modes as _modes
from fretwear.hb import periodic as _periodic
from fretwear.hb import sweep as _sweep
from fretwear.hb.dynamics import structure_dynamics
from fretwear.hb.fourier import FourierBasis
from fretwear.hb.options import SolveOptions, SweepOptions, sweep_options
from fretwear.limits import UnusualValueWarning
from fretwear.model.checks import model_argument
from fretwear.threads import limited
from fretwear.timedomain import integrate as _integrate
from fretwear.timedomain import quasistatic as _quasistatic
from fretwear.timedomain import steady as _steady
from fretwear.timedomain.fallback import FALLBACK
from fretwear.validate import ArgumentTypeError, flag, instance, is_real, number, reals, whole
from fretwear.wear.worn_frf import WORN_FRF
from fretwear.wear.worn_state import WornStateOptions as _WornStateOptions
from fretwear.wear.worn_state import worn_state as _worn_state

#: spellings of other entry points -> the public one
_RENAMED = {"stick_anchor": "anchor", "W0": "wear0", "k_w": "wear_coefficient",
            "frequencies_hz": "f_min, f_max, n_points"}


def _fallback(time_domain: bool):
    return FALLBACK if flag(time_domain, "time_domain") else None


def _band(f_min, f_max, n_points) -> None:
    """Refuse a frequency band that is not two numbers [Hz] and a whole number of points
    (their values are checked by the sweep's own messages)."""
    for name, value in (("f_min", f_min), ("f_max", f_max)):
        if not is_real(value):
            raise InputError(f"{name} = {value!r}: expected a frequency > 0 [Hz]")
    whole(n_points, "n_points")


def _basis(basis) -> None:
    """Refuse a ``basis`` that is not a :class:`~fretwear.hb.fourier.FourierBasis`."""
    if not isinstance(basis, FourierBasis):
        raise ArgumentTypeError(f"basis = {basis!r}: expected a fretwear FourierBasis (e.g. "
                                "FourierBasis.up_to(7, 128))")


#: where the time-domain drivers take the stick anchors
_IN_START = {"anchor": " (start=InitialState(anchor=...))"}


def _public_names(func: str, kwargs: dict, where: dict | None = None) -> None:
    """A TypeError for a keyword spelt as another entry point spells it (``where``: the
    record that holds the public name, for the drivers that take it in one)."""
    for old, new in _RENAMED.items():
        if old in kwargs:
            raise TypeError(f"{func}() takes {new}, not {old}{(where or {}).get(new, '')}")


def _frequency(frequency, quasi_static: bool) -> dict:
    """The ``frequency`` keyword of the core function: required unless ``quasi_static``
    (where it only scales time, and the core's default applies)."""
    if frequency is None:
        if flag(quasi_static, "quasi_static"):
            return {}
        raise InputError("frequency = None: expected the excitation frequency [Hz], a number "
                         "> 0 (only a quasi_static solve can do without)")
    flag(quasi_static, "quasi_static")
    if not is_real(frequency):  # its value is checked by the solver's own message
        raise InputError(f"frequency = {frequency!r}: expected a number > 0 [Hz]")
    return {"frequency": frequency}


#: what a wear run whose Archard coefficients are all zero says (a case run says it as a note)
NOTHING_WEARS = ("contact.wear_coefficient = 0 on every contact node (and on their partners): "
                 "nothing wears under the Archard law, and the run will report no wear; give "
                 "Archard's k_w [1/Pa] (metals: 1e-17 to 1e-12)")


def _nothing_wears(model, law: str | None, stacklevel: int) -> None:
    """Warn when an Archard wear run cannot wear (every coefficient 0, the default of a
    contact): it would stop at once with "no wear" and ``success=True``. ``law`` None: options
    of the wrong type, refused by the run's own check. ``stacklevel``: the frames from here
    to the user's call (this function, the driver and its decorators, which differ between
    the drivers)."""
    c = model.contact
    if law == "archard" and c is not None and c.n_nodes and not (
            c.wear_nodes().any() or c.partner_wear_nodes().any()):
        warnings.warn(NOTHING_WEARS, UnusualValueWarning, stacklevel=stacklevel)


@contextlib.contextmanager
def _sweep_progress(progress, options, n_points):
    """The sweep's ``progress`` callable: ``True`` draws a tqdm bar over the grid frequencies
    (stderr), a callable is used as it is, ``False``/``None`` shows nothing. Yields the
    options with it."""
    if progress is None or progress is False:
        yield options
        return
    if options.progress is not None:
        raise InputError("progress given twice (progress= and options.progress); give one")
    if callable(progress) and not isinstance(progress, bool):
        yield options.replace(progress=progress)
        return
    if progress is not True:
        raise InputError(f"progress = {progress!r}: expected True, False or a callable "
                         "(i, n, point) called after each grid frequency")
    from tqdm import tqdm

    with tqdm(total=n_points, desc="sweep", leave=False, unit="freq") as bar:
        def tick(i, total, point):
            bar.update(1)
            bar.set_postfix_str(f"{point.frequency_hz:.6g} Hz"
                                f"{'' if point.success else ' (not converged)'}")

        yield options.replace(progress=tick)


@model_argument
@limited
def solve_periodic(model, basis, frequency: float | None = None, *, quasi_static: bool = False,
                   time_domain: bool = True, **kwargs) -> _periodic.PeriodicSolution:
    """Periodic response of ``model`` at the excitation ``frequency`` [Hz] with the DLFT (paper
    section 3.1-3.2).

    Parameters
    ----------
    model, basis : the structure and the Fourier basis (kept harmonics, samples per period).
    frequency : excitation frequency [Hz]; required unless ``quasi_static`` (then it only
        scales time; default 1 Hz).
    quasi_static : drop inertia and damping (slow cyclic loading).
    time_domain : when every attempt of the solve strategy failed, integrate in time from rest:
        a periodic steady state starts one more solve, any other response is reported
        (``solution.time_domain``). The case-file key ``time_domain`` of a periodic analysis.
    **kwargs : the other keywords of :func:`fretwear.hb.periodic.solve_periodic`, with its
        defaults: ``reduced`` (a :class:`~fretwear.hb.reduce.Reduced` to reuse), ``gap``
        (nc,) [m], ``eps`` (DLFT penalty [N/m] or ``"auto"``/``"top"``/``"stiff"``/
        ``"contact"``/``"static"``), ``anchor`` (nc, d-1) stick anchors [m], ``U0`` (start),
        ``options``
        (:class:`~fretwear.hb.options.SolveOptions`: ``solver``, ``tol``, ``max_iter``,
        ``strategy``, ``jacobian``, ``time_domain_periods``), ``raise_on_failure``,
        ``condenser``.

    Returns
    -------
    :class:`~fretwear.hb.solution.PeriodicSolution`: ``success``, ``message``, ``attempts``,
    the harmonics and time histories of the contact (see its docstring).
    """
    _public_names("solve_periodic", kwargs)
    _basis(basis)
    return _periodic.solve_periodic(model, basis, **_frequency(frequency, quasi_static),
                                    quasi_static=quasi_static,
                                    time_domain=_fallback(time_domain), **kwargs)


def _other_spellings(name: str):
    """Decorator of a driver with a real signature: a keyword spelt as another entry point
    spells it is a TypeError that names the public one (before Python's own "unexpected
    keyword"); the signature shown by ``help()`` and IDEs is the driver's own."""

    def decorate(func):
        @functools.wraps(func)
        def wrapper(*args, **kwargs):
            _public_names(name, kwargs)
            return func(*args, **kwargs)

        return wrapper

    return decorate


@model_argument
@limited
@_other_spellings("sweep")
def sweep(model, basis, f_min: float, f_max: float, n_points: int, *,
          options: SweepOptions | SolveOptions | None = None, gap=None, anchor=None,
          condenser=None, time_domain: bool = True, progress=False) -> _sweep.SweepResult:
    """Nonlinear FRF: periodic solutions of the DLFT from ``f_min`` to ``f_max`` [Hz] on
    ``n_points`` grid frequencies, each starting from its neighbours (continuation).

    Parameters
    ----------
    model, basis : the structure and the Fourier basis.
    f_min, f_max, n_points : the frequency band [Hz] and its number of grid frequencies.
    options : :class:`~fretwear.hb.options.SweepOptions` (default
        :data:`~fretwear.hb.options.SWEEP`; a :class:`~fretwear.hb.options.SolveOptions`
        alone stands for ``SweepOptions(solve=...)``), the case-file keys of a sweep:

        - ``solve``: the solve of one point (:class:`~fretwear.hb.options.SolveOptions`:
          ``solver``, ``tol``, ``max_iter`` (40 by default), ``strategy``, ``jacobian``,
          ``time_domain_periods``);
        - ``spacing``: ``"log"`` (default) or ``"linear"`` grid;
        - ``eps``: the DLFT penalty [N/m], or ``"contact"`` (default), ``"top"``,
          ``"stiff"``, ``"static"``, ``"auto"`` (:func:`fretwear.hb.sweep.sweep` explains
          each);
          ``eps_band``: the band [Hz] over which ``"top"``/``"stiff"`` are taken;
        - ``continuation`` (True): continue along the branch where it turns;
          ``max_bisections`` (4): halvings of a step before the next rung;
        - ``flag``: a check of each converged point (e.g. a stability check);
        - ``checkpoint`` (a ``.npz`` path) and ``resume``: save after every grid frequency
          and continue a stopped sweep to the same points, bit for bit;
        - ``progress``: a callable ``(i, n, point)`` (or give ``progress=`` here).
    gap : (nc,) initial normal gaps [m] (default the model's).
    anchor : (nc, d-1) stick anchors [m] (default: the static preload state).
    condenser : the condenser of the model (:func:`fretwear.condenser`), built once by the
        caller and shared by the drivers that condense the same model (default: a new one).
    time_domain : at points whose balance still fails, integrate in time from the neighbour
        (the case-file key ``time_domain`` of a sweep; replaces ``options.time_domain``).
    progress : True draws a progress bar over the grid frequencies (stderr); a callable
        ``(i, n, point)`` is called after each grid frequency instead; False: nothing.

    Returns
    -------
    :class:`~fretwear.hb.sweep.SweepResult`: ``success`` (every point converged),
    ``message`` (how many did), ``points`` (each a :class:`~fretwear.hb.sweep.SweepPoint`
    with ``frequency_hz`` [Hz], ``solution`` or None, ``success``, ``message``, ``flags``),
    ``frequency_hz`` [Hz], ``point_success``, ``amplitude(point, axis)`` [m].
    """
    _basis(basis)
    _band(f_min, f_max, n_points)
    options = sweep_options(options)
    with _sweep_progress(progress, options, n_points) as options:
        return _sweep.sweep(model, basis, f_min, f_max, n_points,
                            options=options.replace(time_domain=_fallback(time_domain)),
                            gap=gap, anchor=anchor, condenser=condenser)


def _wear_run(run, progress):
    """The :class:`~fretwear.wear.simulate.RunControl` of ``run=`` and ``progress=``."""
    if progress is None or progress is False:
        return run
    if progress is not True:
        raise InputError(f"progress = {progress!r}: expected True or False (a bar of the "
                         "run's steps; a callable goes to run=RunControl(callback=...))")
    run = _wear.RunControl() if run is None else run
    if run.progress:
        raise InputError("progress given twice (progress= and run.progress); give one")
    return dataclasses.replace(run, progress=True)


@model_argument
@limited
@_other_spellings("simulate_wear")
def simulate_wear(model, basis, frequency: float | None = None, *, quasi_static: bool = False,
                  options: _wear.WearOptions | None = None, wear0=None,
                  balance: _wear.BalanceSetup | None = None, run: _wear.RunControl | None = None,
                  time_domain: bool = True, condenser=None,
                  progress: bool = False) -> _wear.WearResult:
    """Fretting wear on the slow time scale (paper section 3.3, eq. 29-30) at the excitation
    ``frequency`` [Hz] or under quasi-static loading.

    Parameters
    ----------
    model, basis : the structure (``contact.wear_coefficient`` [1/Pa]) and the Fourier basis.
    frequency : excitation frequency [Hz]; required unless ``quasi_static`` (then it only
        scales time; default 1 Hz).
    quasi_static : drop inertia and damping.
    options : :class:`~fretwear.wear.options.WearOptions` (the case-file keys of a wear
        analysis; defaults: adaptive linearly implicit steps, tolerance 1e-2): ``law``
        (``"archard"`` or ``"energy"``) and ``energy_coefficient``; ``scheme``,
        ``adaptive``, ``tolerance``, ``initial_jump``, ``max_jump``, ``min_jump`` [cycles];
        the stops ``max_cycles``, ``max_depth`` [m], ``plateau_rate``, ``max_steps``; the
        balance of a step ``solve`` (:class:`~fretwear.hb.options.SolveOptions`),
        ``max_iter_coupled``, ``max_iter_implicit``, ``implicit_newton``, ``max_retries``;
        the time-domain fallback ``time_domain_rescue`` (True), ``time_domain_settle``,
        ``time_domain_average`` [periods], ``time_domain_steps``; ``checkpoint_every_s``.
    wear0 : (nc,) initial wear [m] (default 0).
    balance : :class:`~fretwear.wear.simulate.BalanceSetup`: ``reduced`` (a condensation to
        reuse), ``eps`` (the DLFT penalty: ``"auto"`` default, ``"static"`` or [N/m]),
        ``anchor`` (nc, d-1) stick anchors [m], ``U0`` the start of the first solve.
    run : :class:`~fretwear.wear.simulate.RunControl`: ``checkpoint`` (``.npz``),
        ``resume``, ``progress``, ``callback(step, record)``.
    time_domain : the time-domain fallback of the steps whose balance fails (whether it is
        used is ``options.time_domain_rescue``, default true, as in case files).
    condenser : the condenser of the model, as every driver takes it (it becomes the
        ``condenser`` of ``balance``; giving both is an error).
    progress : True draws a progress bar of the run's steps (``run.progress``).

    Returns
    -------
    :class:`~fretwear.wear.history.WearResult`: ``success`` (False when a solve failed even
    with smaller jumps), ``message`` (why and when it stopped), ``stop_reason``, ``history``
    (one row per slow step: cycles, wear depth [m], pressure [Pa], slip [m], ...),
    ``final_wear`` [m], ``initial`` and ``final`` periodic solutions (None where the rate came
    from a time integration).
    """
    _basis(basis)
    _nothing_wears(model, options.law if isinstance(options, _wear.WearOptions)
                   else None if options is not None else "archard", 6)
    if condenser is not None:
        balance = balance or _wear.BalanceSetup()
        if balance.condenser is not None:
            raise InputError("simulate_wear: condenser given twice (condenser= and "
                             "balance.condenser); give one")
        balance = dataclasses.replace(balance, condenser=condenser)
    return _wear.simulate_wear(model, basis, **_frequency(frequency, quasi_static),
                               quasi_static=quasi_static, options=options, wear0=wear0,
                               balance=balance, run=_wear_run(run, progress),
                               time_domain=_fallback(time_domain))


@model_argument
@limited
def worn_state(model, basis, frequency: float | None = None, *, quasi_static: bool = False,
               wear0=None, time_domain: bool = True, condenser=None, **kwargs):
    """The worn state directly: where fretting wear stops (the wear depths at which the wear
    rate of eq. 29 vanishes), by pseudo-transient continuation on the slow equation with the
    DLFT balance inside (docs/theory.md, "The worn state directly").

    Parameters
    ----------
    model, basis : the structure and the Fourier basis.
    frequency : excitation frequency [Hz]; required unless ``quasi_static``.
    quasi_static, wear0, time_domain, condenser : as :func:`simulate_wear`.
    **kwargs : the other keywords of :func:`fretwear.wear.worn_state.worn_state`:
        ``options`` (:class:`~fretwear.wear.worn_state.WornStateOptions`: the wear options,
        the tolerances of the null-wear-rate residual and of the last correction, the steps
        allowed), ``balance``, ``run`` (checkpoint and resume, callback).

    Returns
    -------
    :class:`~fretwear.wear.worn_state.WornStateResult`: ``success`` (False, with the
    ``residual``, when not reached), ``kind`` (``"null_wear_rate"``, ``"steady_wear"``,
    ``"not_reached"``, ``"no_wear"``), ``wear`` [m], ``rate`` [m/cycle], ``cycles_to_1pc``
    (an estimate), ``history`` of the pseudo-time steps, ``initial`` and ``final``
    periodic solutions.
    """
    _public_names("worn_state", kwargs)
    _basis(basis)
    opts = kwargs.get("options")
    _nothing_wears(model, opts.wear.law if isinstance(opts, _WornStateOptions)
                   else None if opts is not None else "archard", 5)
    if condenser is not None:
        balance = kwargs.pop("balance", None) or _wear.BalanceSetup()
        if balance.condenser is not None:
            raise InputError("worn_state: condenser given twice (condenser= and "
                             "balance.condenser); give one")
        kwargs["balance"] = dataclasses.replace(balance, condenser=condenser)
    return _worn_state(model, basis, **_frequency(frequency, quasi_static),
                       quasi_static=quasi_static, wear0=wear0,
                       time_domain=_fallback(time_domain), **kwargs)


@model_argument
@limited
def frf_worn(model, basis, wear, f_min: float, f_max: float, n_points: int, *,
             time_domain: bool = True, progress=False, **kwargs) -> _sweep.SweepResult:
    """Nonlinear FRF with the worn gap ``gap + wear`` (paper Fig. 24) from ``f_min`` to
    ``f_max`` [Hz] on ``n_points`` grid frequencies, as :func:`sweep`.

    Parameters
    ----------
    model, basis : the structure and the Fourier basis.
    wear : (nc,) wear depths [m] (e.g. ``result.final_wear``, or 0).
    f_min, f_max, n_points : the frequency band [Hz] and its number of grid frequencies.
    time_domain : at points whose balance still fails, integrate in time from the neighbour
        (the key ``time_domain`` of a wear analysis's ``frf_before_after``).
    progress : as :func:`sweep`.
    **kwargs : the other keywords of :func:`fretwear.wear.worn_frf.frf_worn`: ``anchor``,
        ``options`` (:class:`~fretwear.hb.options.SweepOptions`, default
        :data:`~fretwear.wear.worn_frf.WORN_FRF`: a sweep's on a linear grid), ``condenser``.

    Returns
    -------
    :class:`~fretwear.hb.sweep.SweepResult` (``success``, ``message``, as :func:`sweep`).
    """
    _public_names("frf_worn", kwargs)
    _basis(basis)
    reals(wear, "wear", low=0.0)
    _band(f_min, f_max, n_points)
    options = sweep_options(kwargs.pop("options", None), WORN_FRF)
    with _sweep_progress(progress, options, n_points) as options:
        return _wear.frf_worn(model, basis, wear, f_min, f_max, n_points,
                              options=options.replace(time_domain=_fallback(time_domain)),
                              **kwargs)


#: linear interfaces a nonlinear mode may be chosen on (:func:`nonlinear_mode`)
MODE_INTERFACES = ("stuck", "sliding")


def mode_target(model, mode: int = 1, interface: str = "stuck", dyn=None) -> float:
    """The circular frequency [rad/s] that picks the linear mode a nonlinear mode starts from:
    mode number ``mode`` (from 1, by increasing frequency) of the structure with its contact
    points held (``interface = "stuck"``: the EPMC's own start, contact springs included), or
    of the frictionless structure (``"sliding"``: :func:`fretwear.linear.modes`), whose
    nearest stuck mode is then followed. ``dyn``: the model's
    :func:`fretwear.hb.dynamics.structure_dynamics` if already made."""
    if isinstance(mode, bool) or not isinstance(mode, int) or mode < 1:
        raise InputError(f"mode = {mode!r}: expected a mode number >= 1")
    if interface not in MODE_INTERFACES:
        raise InputError(f"interface = {interface!r}: expected one of "
                         f"{', '.join(MODE_INTERFACES)}")
    if interface == "stuck":
        held = _modes.mode_system(model, None, dyn=dyn).omega_held
        if mode > held.size:
            raise InputError(f"mode = {mode}: the structure with its contact points held has "
                             f"{held.size} modes")
        return float(held[mode - 1])
    r = _linear.modes(model, mode, interface="sliding")
    if mode > len(r.frequency_hz):
        raise InputError(f"mode = {mode}: the structure with a sliding interface has "
                         f"{len(r.frequency_hz)} modes")
    return float(2.0 * math.pi * r.frequency_hz[mode - 1])


@model_argument
@limited
def nonlinear_mode(model, basis, amplitudes, *, mode: int = 1, interface: str = "stuck",
                   **kwargs) -> _modes.Backbone:
    """Nonlinear mode of ``model`` over the modal ``amplitudes`` by the Extended Periodic
    Motion Concept (:func:`fretwear.hb.nonlinear_modes.nonlinear_mode`): natural frequency
    [Hz] and damping ratio against amplitude, from the stuck to the sliding interface.

    Parameters
    ----------
    model, basis : the structure and the Fourier basis (the fundamental kept).
    amplitudes : (k,) increasing modal amplitudes [m sqrt(kg)]: the mass norm of the
        fundamental harmonic of the whole structure's motion.
    mode, interface : which linear mode the branch starts from (:func:`mode_target`):
        number ``mode`` from 1 of the structure with its interface ``"stuck"`` (contact points
        held) or ``"sliding"`` (frictionless).
    **kwargs : the other keywords of :func:`fretwear.hb.nonlinear_modes.nonlinear_mode`,
        with its defaults: ``masters``, ``eps`` (a rule or [N/m]), ``options``
        (:class:`~fretwear.hb.options.SolveOptions`), ``dyn``, ``wear0`` (wear depths [m]:
        the mode of the worn interface, gap ``gap + wear0``); or ``condenser`` (a modal
        condenser for a large model: the structure's matrices are then its projection).

    Returns
    -------
    :class:`~fretwear.hb.nonlinear_modes.Backbone`: ``success``, ``message``, ``points``
    (each with ``amplitude``, ``frequency`` [Hz], ``damping_ratio``, ``energy`` [J],
    ``state``, ``observed``), ``array(name)``.
    """
    _public_names("nonlinear_mode", kwargs)
    _basis(basis)
    reals(amplitudes, "amplitudes", low=0.0, open_low=True)
    if "omega_target" in kwargs:
        raise TypeError("nonlinear_mode() takes mode and interface, not omega_target")
    dyn = kwargs.pop("dyn", None)
    if dyn is None:
        dyn = structure_dynamics(model, kwargs.pop("condenser", None))
    target = mode_target(model, mode, interface, dyn=dyn)
    return _modes.nonlinear_mode(model, basis, amplitudes, omega_target=target, dyn=dyn,
                                 **kwargs)


@model_argument
@limited
def mode_frf(model, backbone: _modes.Backbone, *, damping: str = "viscous", condenser=None,
             dyn=None):
    """Forced response of ``model`` (its loads) synthesised from one nonlinear mode
    (:mod:`fretwear.hb.mode_synthesis`; single-nonlinear-mode theory): at every point of
    ``backbone`` (:func:`nonlinear_mode` of the same model) the two excitation frequencies
    at which the forced response reaches that amplitude.

    Parameters
    ----------
    damping : ``"viscous"`` (the EPMC's reading: the compensated damping acts as ``xi W``)
        or ``"hysteretic"`` (``xi w``, rate-independent: exact for a single-DOF joint).
    condenser, dyn : the condenser (or structure) the backbone was computed with.

    Returns
    -------
    :class:`~fretwear.hb.mode_synthesis.ModalFRF`: ``amplitude``, ``modal_force``,
    ``omega_lo``, ``omega_hi`` [rad/s], ``observed``, ``peak``, ``curve()``.
    """
    instance(backbone, _modes.Backbone, "backbone", "the Backbone of fretwear.nonlinear_mode")
    if dyn is None:
        dyn = structure_dynamics(model, condenser)
    return _synth.synthesize(backbone, _synth.modal_forces(model, backbone, dyn=dyn),
                             damping=damping)


@model_argument
@limited
def integrate(model, frequency: float, **kwargs):
    """Integrate the forced response at ``frequency`` [Hz] in time with exact contact and
    friction.

    Parameters
    ----------
    model : the structure.
    frequency : forcing frequency [Hz].
    **kwargs : the keywords of :func:`fretwear.timedomain.integrate.integrate`, with its
        defaults: ``n_periods`` (required), ``options`` (an
        :class:`~fretwear.timedomain.options.IntegrationOptions`: ``steps_per_period``,
        ``gamma``, ``hf_damping``, ``modal_cutoff`` [Hz], ``n_modes``, ``contact_tol``),
        ``start`` (an :class:`~fretwear.timedomain.options.InitialState`: ``U0`` [m], ``V0``
        [m/s], ``wear`` (nc,) [m], ``anchor`` (nc, d-1) [m], the tangential positions from
        which the first step's slip is measured), ``record``, ``keep_poincare``,
        ``progress``.

    Returns
    -------
    :class:`~fretwear.timedomain.results.TransientResult`: ``success``, ``message``, the
    recorded samples and the final state ``U, V`` to continue the run.
    """
    _public_names("integrate", kwargs, _IN_START)
    number(frequency, "frequency", low=0.0, open_low=True, unit="Hz")
    return _integrate.integrate(model, frequency, **kwargs)


@model_argument
@limited
def steady_state(model, frequency: float, **kwargs):
    """Integrate at ``frequency`` [Hz] until the response is periodic (or classified
    otherwise).

    Parameters
    ----------
    model : the structure.
    frequency : forcing frequency [Hz].
    **kwargs : the keywords of :func:`fretwear.timedomain.steady.steady_state`, with its
        defaults: ``options`` (a :class:`~fretwear.timedomain.options.SteadyStateOptions`:
        ``max_periods``, ``tol``, ``harmonics``, ``check_every``, ``window``,
        ``min_periods``), ``integration`` (an
        :class:`~fretwear.timedomain.options.IntegrationOptions`), ``start`` (an
        :class:`~fretwear.timedomain.options.InitialState`, with the stick ``anchor``),
        ``progress``.

    Returns
    -------
    :class:`~fretwear.timedomain.results.SteadyStateResult`: ``success``, ``message``,
    ``classification``, the harmonics of the last period.
    """
    _public_names("steady_state", kwargs, _IN_START)
    number(frequency, "frequency", low=0.0, open_low=True, unit="Hz")
    return _steady.steady_state(model, frequency, **kwargs)


@model_argument
@limited
def incremental_wear(model, *, wear_coefficient: float | None = None, wear0=None, **kwargs):
    """Quasi-static fretting wear by load steps (in the spirit of Stromberg 1997).

    Parameters
    ----------
    model : the structure (inertia and damping are ignored).
    wear_coefficient : Archard coefficient [1/Pa]; default ``model.contact.wear_coefficient``
        (plus the partners' at node-to-node pairs).
    wear0 : (nc,) initial wear [m].
    **kwargs : the other keywords of
        :func:`fretwear.timedomain.quasistatic.incremental_wear`, with its defaults:
        ``n_cycles``, ``options`` (an
        :class:`~fretwear.timedomain.options.IncrementalWearOptions`: ``steps_per_cycle``,
        ``cycle_jump``, ``record_every``, ``contact_tol``), ``progress``,
        ``raise_on_failure``, ``condenser``.

    Returns
    -------
    :class:`~fretwear.timedomain.results.IncrementalWearResult`: ``success``, ``message``,
    wear [m] per recorded cycle.
    """
    _public_names("incremental_wear", kwargs)
    if wear_coefficient is not None:
        number(wear_coefficient, "wear_coefficient", low=0.0, high=1.0, unit="1/Pa")
    return _quasistatic.incremental_wear(model, wear_coefficient=wear_coefficient, wear0=wear0,
                                         **kwargs)
