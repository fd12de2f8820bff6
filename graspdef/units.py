"""Quantities with units at I/O: ``"2.5 mm"`` -> 0.0025, ``"80 kPa"`` -> 80000.0; SI inside.

A quantity is written as a number, a space (optional) and a unit of the table below, e.g.
``"2.5 mm"``, ``"1 MPa"``, ``"0.76 N"``, ``"1100 kg/m^3"``; a vector as ``"[47.97, 4.19, -41.65] mm"``.
Every value is converted to SI by multiplying with the unit's factor (``2.5 * 1e-3``), so a value
read here is the same float as the one the hand-written ``* 1e-3`` of earlier readers gave.  Each
reader states the dimension it expects, and a value of another dimension is an error naming the
key, the dimension found and the one expected (a thickness given in Pa is refused).  A plain number
is accepted only where the reader says which unit it implies (a key like ``E_MPa``, or a problem
file's declared ``[units]``).

Errors are :class:`~graspdef.errors.ConfigError` (a ProblemError), one line, prefixed with the
``what`` the caller passes (file, table, key).
"""
from __future__ import annotations

import math
import re
from collections.abc import Mapping
from types import MappingProxyType

from .errors import ConfigError

#: Length of one unit in metres.
LENGTH_UNITS: Mapping[str, float] = MappingProxyType({"m": 1.0, "mm": 1e-3, "cm": 1e-2, "um": 1e-6, "in": 0.0254})
#: Force of one unit in newtons.
FORCE_UNITS: Mapping[str, float] = MappingProxyType({"N": 1.0, "kN": 1e3, "mN": 1e-3})
#: Pressure (stress, elastic modulus) of one unit in pascals; psi = 1 lbf/in^2 (NIST SP 811).
PRESSURE_UNITS: Mapping[str, float] = MappingProxyType(
    {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "GPa": 1e9, "psi": 6894.757293168361})
#: Mass of one unit in kilograms.
MASS_UNITS: Mapping[str, float] = MappingProxyType({"kg": 1.0, "g": 1e-3})
#: Density of one unit in kg/m^3.
DENSITY_UNITS: Mapping[str, float] = MappingProxyType({"kg/m^3": 1.0, "g/cm^3": 1e3})

#: dimension -> its unit table (the first unit is the SI one)
DIMENSIONS: Mapping[str, Mapping[str, float]] = MappingProxyType({
    "length": LENGTH_UNITS, "force": FORCE_UNITS, "pressure": PRESSURE_UNITS, "mass": MASS_UNITS,
    "density": DENSITY_UNITS})
#: unit -> (dimension, factor to SI)
UNITS: Mapping[str, tuple[str, float]] = MappingProxyType(
    {u: (dim, f) for dim, table in DIMENSIONS.items() for u, f in table.items()})

_NUMBER = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"
_SCALAR = re.compile(rf"^\s*({_NUMBER})\s*([A-Za-z][A-Za-z0-9/^]*)?\s*$")
_VECTOR = re.compile(r"^\s*\[([^\]]*)\]\s*([A-Za-z][A-Za-z0-9/^]*)?\s*$")


def _at(what: str) -> str:
    """``what`` as the subject of a message (``"f.toml: [shell] thickness must be ..."``)."""
    return f"{what} " if what else ""


def _example(dimension: str) -> str:
    return f"\"2.5 {next(iter(_dimension(dimension)))}\""


def _dimension(dimension: str) -> Mapping[str, float]:
    try:
        return DIMENSIONS[dimension]
    except KeyError:
        raise ValueError(f"unknown dimension {dimension!r} (known: {', '.join(DIMENSIONS)})") from None


def unit_factor(unit: str, dimension: str, what: str = "") -> float:
    """SI value of one ``unit`` of ``dimension`` (``unit_factor("mm", "length") == 1e-3``).

    Raises
    ------
    ConfigError
        If ``unit`` is not a unit of ``dimension``; the message lists the accepted ones (and says
        which dimension the unit has, if it is one of another dimension).
    """
    table = _dimension(dimension)
    if isinstance(unit, str) and unit in table:
        return table[unit]
    other = f" ({unit!r} is a {UNITS[unit][0]} unit)" if isinstance(unit, str) and unit in UNITS else ""
    raise ConfigError(f"{what + ': ' if what else ''}unknown {dimension} unit {unit!r}{other}; "
                      f"accepted: {', '.join(table)}")


def length_scale(units: str) -> float:
    """Length of one ``units`` in metres (``length_scale("mm") == 1e-3``)."""
    return unit_factor(units, "length")


def _finite(x: float, text, what: str) -> float:
    if not math.isfinite(x):
        raise ConfigError(f"{_at(what)}must be finite, got {text!r}")
    return x


def _with_unit(number: float, unit: str | None, dimension: str, implied, text, what: str) -> float:
    """``number`` in ``unit`` (or, with no unit, as ``implied`` says) in SI."""
    if unit is None:
        if implied is None:
            raise ConfigError(f"{_at(what)}needs a unit: {text!r} is a plain number; write e.g. \"{number:g} "
                              f"{next(iter(_dimension(dimension)))}\" (a {dimension}: {', '.join(_dimension(dimension))})")
        if callable(implied):
            return implied(number)
        if isinstance(implied, str):
            return number * unit_factor(implied, dimension, what)
        return number * float(implied)
    if unit not in UNITS:
        raise ConfigError(f"{_at(what)}{text!r} has an unknown unit {unit!r}; a {dimension} takes one of: "
                          f"{', '.join(_dimension(dimension))}")
    dim, factor = UNITS[unit]
    if dim != dimension:
        raise ConfigError(f"{_at(what)}{text!r} is a {dim}; expected a {dimension} "
                          f"({', '.join(_dimension(dimension))})")
    return number * factor


def quantity(value, dimension: str, implied=None, what: str = "") -> float:
    """A scalar quantity in SI.

    Parameters
    ----------
    value : str or number
        ``"2.5 mm"`` (number and unit, the space optional) or a plain number (TOML int or float,
        or a string holding only a number) when ``implied`` says its unit.
    dimension : str
        One of :data:`DIMENSIONS` (``"length"``, ``"force"``, ``"pressure"``, ``"mass"``,
        ``"density"``).
    implied : str, float or callable, optional
        The unit a plain number is in: a unit name, the SI value of that unit (a problem file's
        N/mm^2 = 1e6), or a function taking the number to SI.  Without it a plain number is an
        error.
    what : str
        Where the value comes from (file, table, key), prefixed to every error.

    Raises
    ------
    ConfigError
        Not a number with a unit, a non-finite number, an unknown unit, or a unit of another
        dimension.
    """
    _dimension(dimension)
    if isinstance(value, bool) or not isinstance(value, (int, float, str)):
        raise ConfigError(f"{_at(what)}must be a {dimension} such as {_example(dimension)}, got {value!r}")
    if not isinstance(value, str):
        return _finite(_with_unit(_finite(float(value), value, what), None, dimension, implied, value, what),
                       value, what)
    m = _SCALAR.match(value)
    if m is None:
        if value.strip().lower().lstrip("+-").startswith(("nan", "inf")):
            raise ConfigError(f"{_at(what)}must be finite, got {value!r}")
        raise ConfigError(f"{_at(what)}{value!r} is not a number with a unit (e.g. {_example(dimension)})")
    return _finite(_with_unit(float(m.group(1)), m.group(2), dimension, implied, value, what), value, what)


def quantity_vector(value, dimension: str, n: int | None = 3, implied=None, what: str = "") -> tuple[float, ...]:
    """A vector quantity in SI: ``"[47.97, 4.19, -41.65] mm"``, or a list of ``n`` plain numbers
    when ``implied`` gives their unit, or a list of ``n`` scalar quantities (``["1 mm", ...]``).
    ``n = None`` accepts any length >= 1."""
    if isinstance(value, str):
        m = _VECTOR.match(value)
        if m is None:
            raise ConfigError(f"{_at(what)}{value!r} is not a vector with a unit (e.g. \"[1.0, 2.0, 3.0] "
                              f"{next(iter(_dimension(dimension)))}\")")
        try:
            numbers = [float(p) for p in m.group(1).split(",")]
        except ValueError:
            raise ConfigError(f"{_at(what)}{value!r}: the entries must be numbers") from None
        out = tuple(_finite(_with_unit(x, m.group(2), dimension, implied, value, what), value, what) for x in numbers)
    elif isinstance(value, list):
        out = tuple(quantity(x, dimension, implied, what) for x in value)
    else:
        raise ConfigError(f"{_at(what)}must be a vector such as \"[1.0, 2.0, 3.0] "
                          f"{next(iter(_dimension(dimension)))}\", got {value!r}")
    if (n is not None and len(out) != n) or not out:
        raise ConfigError(f"{_at(what)}must have {n if n is not None else 'at least 1'} entries, got {len(out)}")
    return out


def format_quantity(value: float, unit: str, dimension: str) -> str:
    """``value`` [SI] written in ``unit``: ``format_quantity(0.0025, "mm", "length") == "2.5 mm"``."""
    return f"{value / unit_factor(unit, dimension):g} {unit}"
