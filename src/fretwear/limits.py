"""The ranges of input values that make physical and numerical sense, in one place.

Physical: the structures fretwear is for (blade roots, joints, dampers, test rigs) have sizes
from micrometres (a contact zone) to tens of metres, materials from soft polymers to diamond,
and vibrate below a few hundred kHz. Numerical: with these bounds the entries of the stiffness
and mass matrices and the dynamic stiffness ``K - (n w)^2 M`` stay between about 1e-60 and
1e60, far inside the range of double precision (1e-308 to 1e308), so no product or
factorisation overflows or underflows. A value outside gets one message naming it, the range
and why; there is no case outside these ranges that fretwear could compute meaningfully.
"""

from __future__ import annotations

import math

from fretwear.errors import InputError

#: kind -> (lowest, highest, unit, what it covers); the magnitude 0 is also accepted for the
#: kinds of ZERO_ALLOWED (a massless model, a static load)
RANGES = {
    "length": (1e-9, 1e5, "m", "from a nanometre to 100 km"),
    "modulus": (1.0, 1e13, "Pa", "from the softest gels to ten times diamond"),
    "density": (1e-3, 1e5, "kg/m^3", "0 for massless, or from a thousandth of air to five "
                "times osmium"),
    "frequency": (1e-6, 1e10, "Hz", "0 for static, or from a period of 11 days to 10 GHz"),
}
ZERO_ALLOWED = ("density", "frequency")

#: the highest hysteretic loss factor eta accepted (``D = eta K``): real materials and joints stay
#: below 2; 10 leaves room for a deliberately over-damped model
LOSS_FACTOR_MAX = 10.0


#: kind -> (lowest, highest, unit, what is usual): legal values outside these are almost surely a
#: unit mistake (a modulus in GPa or MPa given as Pa, a density in kg/mm^3 or g/cm^3); they are
#: run, with a note (:func:`unusual`). 0 (a massless model, no wear) is never unusual.
USUAL = {
    "modulus": (1e5, 2e12, "Pa", "from soft rubbers (1e6 Pa) to diamond (1.1e12 Pa); steel "
                "is 2.1e11 Pa"),
    "density": (10.0, 3e4, "kg/m^3", "from foams to osmium; steel is 7800 kg/m^3"),
    "friction": (0.0, 2.0, "-", "dry metal contacts stay below about 1.5"),
    "wear_coefficient": (0.0, 1e-9, "1/Pa", "Archard coefficients of metals are 1e-17 to "
                         "1e-12 1/Pa"),
    "pressure": (0.0, 1e10, "Pa", "ten times the strength of the hardest steels"),
}


class UnusualValueWarning(UserWarning):
    """A legal value outside :data:`USUAL` (from the Python records; a case run says it as a
    line naming the key instead)."""


def unusual(value, kind: str, what: str) -> str:
    """A note when ``value`` is legal but outside ``USUAL[kind]`` ("" otherwise, and for 0)."""
    lo, hi, unit, why = USUAL[kind]
    try:
        v = abs(float(value))
    except (TypeError, ValueError):
        return ""
    if v == 0.0 or not math.isfinite(v) or lo <= v <= hi:
        return ""
    u = "" if unit == "-" else f" {unit}"
    side = "below" if v < lo else "above"
    return (f"{what} = {float(value):g}{u} is {side} the usual range [{lo:g}, {hi:g}]{u} ({why}):"
            " a unit mistake?")


def check_loss_factor(value, what: str = "loss_factor") -> float:
    """The loss factor ``value`` as a float, after checking it is a number in
    ``[0, LOSS_FACTOR_MAX]``."""
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} = {value!r} is not a number") from None
    if not 0.0 <= v <= LOSS_FACTOR_MAX:  # (NaN fails too)
        raise InputError(f"{what} = {value!r}; expected a value in [0, {LOSS_FACTOR_MAX:g}] "
                         "(real materials stay below 2)")
    return v


def check_range(value: float, kind: str, what: str) -> float:
    """``value`` as a float, after checking it is finite and within ``RANGES[kind]``."""
    lo, hi, unit, why = RANGES[kind]
    try:
        v = float(value)
    except (TypeError, ValueError, OverflowError):
        raise InputError(f"{what} = {value!r} is not a number [{unit}]") from None
    zero_ok = kind in ZERO_ALLOWED
    if not math.isfinite(v) or not lo <= abs(v) <= hi and not (v == 0.0 and zero_ok):
        zero = "0 or " if zero_ok and lo > 0 else ""
        raise InputError(f"{what} = {value!r} {unit}: expected {zero}a magnitude in [{lo:g}, "
                         f"{hi:g}] {unit} ({why}; outside it the matrices would overflow or lose "
                         "all precision)")
    return v
