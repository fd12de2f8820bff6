"""The one TOML reader: documents, tables with their accepted keys, typed and unit-carrying values.

Every reader of a graspdef configuration file (problem files, object data, sweep specs,
axisymmetric problem files, the scan manifest) goes through :func:`read_toml` / :func:`parse_toml`
and :class:`Table`:

* a TOML syntax error is one line naming the file, the line and the column;
* :meth:`Table.check` rejects an unknown key by name, with a did-you-mean hint and the accepted
  keys listed, and reports every missing required key;
* the typed getters (:meth:`Table.number`, :meth:`~Table.integer`, :meth:`~Table.boolean`,
  :meth:`~Table.string` from a set, :meth:`~Table.vector` of n, :meth:`~Table.list` of numbers,
  integers or strings, :meth:`~Table.quantity` with a dimension via :mod:`graspdef.units`) refuse
  NaN, infinities, booleans where numbers are due and values of the wrong type or dimension with
  an error naming file, table and key.

All errors are :class:`~graspdef.errors.ConfigError` (a ProblemError).
"""
from __future__ import annotations

import difflib
import math
import re
import tomllib
from collections.abc import Iterable, Mapping
from pathlib import Path

from .. import units as _units
from ..errors import ConfigError

#: default marker of the getters: the key is required
REQUIRED = object()

_TOML_AT = re.compile(r"\s*\(at line (\d+), column (\d+)\)\s*$")


def closest(word, choices: Iterable[str]) -> str | None:
    """The choice most like ``word``, or None: a key with a unit suffix whose stem is a choice
    (``thickness_mm`` -> ``thickness``: the spelling before units were written as text), else
    the closest match of difflib."""
    choices = sorted(choices)
    stem = str(word).rsplit("_", 1)[0]
    if "_" in str(word) and stem in choices:
        return stem
    hit = difflib.get_close_matches(str(word), choices, n=1)
    return hit[0] if hit else None


def unknown_name(word, accepted: Iterable[str], noun: str = "key", place: str = "") -> str:
    """The message of an unknown name: ``unknown key 'gass' in [top level] (did you mean 'gas'?);
    accepted: gas, material, ...`` (``place`` e.g. ``" in [grid]"``)."""
    accepted = sorted(accepted)
    hint = closest(word, accepted)
    return (f"unknown {noun} {word!r}{place}" + (f" (did you mean '{hint}'?)" if hint else "")
            + f"; accepted: {', '.join(accepted) if accepted else 'none'}")


def check_names(given: Iterable[str], accepted: Iterable[str], required: Iterable[str] = (), *,
                noun: str = "key", place: str = "", prefix: str = "") -> None:
    """Every name of ``given`` must be ``accepted``; every ``required`` one present.

    Raises
    ------
    ConfigError
        ``{prefix}unknown {noun} 'x'{place} (did you mean 'y'?); accepted: ...`` for the first
        unknown name, else ``{prefix}missing {noun}(s) 'a', 'b'{place}``.
    """
    given = list(given)
    accepted = list(accepted)
    for k in given:
        if k not in accepted:
            raise ConfigError(prefix + unknown_name(k, accepted, noun, place))
    missing = [k for k in required if k not in given]
    if missing:
        many = "s" if len(missing) > 1 else ""
        raise ConfigError(f"{prefix}missing {noun}{many} {', '.join(repr(k) for k in missing)}{place}")


def parse_toml(text: str, source: str = "<text>") -> "Table":
    """Parse TOML text; ``source`` names it in errors (usually the file path)."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        msg = str(exc)
        m = _TOML_AT.search(msg)
        if m:
            raise ConfigError(f"{source}: line {m.group(1)}, column {m.group(2)}: not valid TOML: "
                              f"{msg[:m.start()]}") from None
        raise ConfigError(f"{source}: not valid TOML: {msg}") from None
    return Table(doc, source)


def read_toml(path, kind: str = "file") -> "Table":
    """Read a TOML file as a :class:`Table`; ``kind`` names it when it is missing
    (``"problem file not found: x.toml"``)."""
    p = Path(path)
    if not p.is_file():
        raise ConfigError(f"{kind} not found: {p}")
    try:
        text = p.read_text()
    except (OSError, UnicodeDecodeError) as exc:
        raise ConfigError(f"{p}: cannot read it: {exc}") from None
    return parse_toml(text, str(p))


class Table(Mapping):
    """A TOML table with its place: the file (``source``) and the table's name (``"top level"``,
    ``"material"``, ``"materials.soft"``, ``"supports 2"`` for the second ``[[supports]]``).

    It is a read-only mapping of the raw values; the getters check and convert them.  A getter's
    ``default`` is returned as it is when the key is absent; without one the key is required.
    """

    def __init__(self, data: Mapping, source: str = "<text>", name: str = "top level"):
        if not isinstance(data, Mapping):
            raise ConfigError(f"{source}: [{name}] must be a table, got {data!r}")
        self.data = dict(data)
        self.source = str(source)
        self.name = name

    # -- mapping ----------------------------------------------------------------------------------
    def __getitem__(self, key):
        return self.data[key]

    def __iter__(self):
        return iter(self.data)

    def __len__(self) -> int:
        return len(self.data)

    def __repr__(self) -> str:
        return f"Table({self.source}: [{self.name}], keys={list(self.data)})"

    # -- places and errors ------------------------------------------------------------------------
    def where(self, key: str | None = None) -> str:
        """``file: [table]`` or ``file: [table] key``."""
        return f"{self.source}: [{self.name}]" + ("" if key is None else f" {key}")

    def error(self, message: str, key: str | None = None) -> ConfigError:
        """A ConfigError ``file: [table] key message``."""
        return ConfigError(f"{self.where(key)} {message}")

    def check(self, accepted: Iterable[str], required: Iterable[str] = ()) -> "Table":
        """Refuse keys not in ``accepted`` (did-you-mean hint, accepted keys listed) and report the
        ``required`` ones that are missing.  Returns the table."""
        check_names(self.data, accepted, required, place=f" in [{self.name}]", prefix=f"{self.source}: ")
        return self

    def _raw(self, key: str, default):
        if key in self.data:
            return self.data[key]
        if default is REQUIRED:
            raise ConfigError(f"{self.source}: missing key '{key}' in [{self.name}]")
        return default

    # -- sub-tables -------------------------------------------------------------------------------
    def _child_name(self, key: str) -> str:
        return key if self.name == "top level" else f"{self.name}.{key}"

    def table(self, key: str, required: bool = True) -> "Table":
        """The sub-table ``[key]`` (an empty one if it is absent and not ``required``)."""
        if key not in self.data:
            if required:
                raise ConfigError(f"{self.source}: missing table [{self._child_name(key)}]")
            return Table({}, self.source, self._child_name(key))
        v = self.data[key]
        if not isinstance(v, Mapping):
            raise ConfigError(f"{self.source}: [{self._child_name(key)}] must be a table, got {v!r}")
        return Table(v, self.source, self._child_name(key))

    def tables(self, key: str, required: bool = False, start: int = 1) -> list["Table"]:
        """The array of tables ``[[key]]`` as Tables named ``"key 1"``, ``"key 2"``, ... (numbered
        from ``start``; an empty list if absent and not ``required``; if ``required``, at least one)."""
        v = self.data.get(key)
        if v is None:
            if required:
                raise ConfigError(f"{self.source}: [[{key}]] must list at least one entry")
            return []
        if not isinstance(v, list) or not all(isinstance(t, Mapping) for t in v):
            raise ConfigError(f"{self.source}: [[{key}]] must be an array of tables, got {v!r}")
        if required and not v:
            raise ConfigError(f"{self.source}: [[{key}]] must list at least one entry")
        return [Table(t, self.source, f"{key} {i}") for i, t in enumerate(v, start)]

    def children(self) -> dict[str, "Table"]:
        """A table of tables (``[materials.a]``, ``[materials.b]``) as {name: Table}."""
        out = {}
        for k, v in self.data.items():
            if not isinstance(v, Mapping):
                raise ConfigError(f"{self.source}: [{self._child_name(k)}] must be a table, got {v!r}")
            out[k] = Table(v, self.source, self._child_name(k))
        return out

    # -- typed values -----------------------------------------------------------------------------
    def _number(self, v, key: str, what: str = "must be a number") -> float:
        if isinstance(v, bool) or not isinstance(v, (int, float)):
            raise self.error(f"{what}, got {v!r}", key)
        if not math.isfinite(v):
            raise self.error(f"must be finite, got {v!r}", key)
        return float(v)

    def number(self, key: str, default=REQUIRED, *, positive: bool = False, minimum: float | None = None,
               maximum: float | None = None) -> float:
        """A finite number (TOML integer or float) as float; ``positive``: > 0; ``minimum`` /
        ``maximum``: inclusive bounds."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        x = self._number(v, key, "must be a positive number" if positive else "must be a number")
        if positive and not x > 0:
            raise self.error(f"must be a positive number, got {v!r}", key)
        if minimum is not None and x < minimum:
            raise self.error(f"must be >= {minimum:g}, got {v!r}", key)
        if maximum is not None and x > maximum:
            raise self.error(f"must be <= {maximum:g}, got {v!r}", key)
        return x

    def integer(self, key: str, default=REQUIRED, *, positive: bool = False, minimum: int | None = None) -> int:
        """A TOML integer; ``positive``: >= 1; ``minimum``: inclusive bound."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        if isinstance(v, bool) or not isinstance(v, int):
            raise self.error(f"must be {'a positive' if positive else 'an'} integer, got {v!r}", key)
        if positive and v < 1:
            raise self.error(f"must be a positive integer, got {v!r}", key)
        if minimum is not None and v < minimum:
            raise self.error(f"must be >= {minimum}, got {v!r}", key)
        return v

    def boolean(self, key: str, default=REQUIRED) -> bool:
        """true or false."""
        v = self._raw(key, default)
        if key in self.data and not isinstance(v, bool):
            raise self.error(f"must be true or false, got {v!r}", key)
        return v

    def string(self, key: str, default=REQUIRED, *, choices: Iterable[str] | None = None) -> str:
        """A non-empty string; with ``choices`` one of them (else ``unknown <key> 'x' (did you
        mean 'y'?); accepted: ...``)."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        if not isinstance(v, str) or (not v and choices is None):
            raise self.error(f"must be a non-empty string, got {v!r}", key)
        if choices is not None and v not in choices:
            raise ConfigError(f"{self.where()} " + unknown_name(v, choices, noun=key))
        return v

    def vector(self, key: str, n: int = 3, default=REQUIRED) -> tuple[float, ...]:
        """A list of ``n`` finite numbers."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        if not isinstance(v, list) or len(v) != n:
            raise self.error(f"must be a list of {n} numbers, got {v!r}", key)
        return tuple(self._number(x, key) for x in v)

    def vectors(self, key: str, n: int = 3, default=REQUIRED) -> tuple[tuple[float, ...], ...]:
        """A non-empty list of lists of ``n`` finite numbers."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        if not isinstance(v, list) or not v or not all(isinstance(x, list) and len(x) == n for x in v):
            raise self.error(f"must be a list of {n}-vectors, got {v!r}", key)
        return tuple(tuple(self._number(y, key) for y in x) for x in v)

    def list(self, key: str, kind: str = "number", default=REQUIRED, *, nonempty: bool = True,
             unique: bool = False) -> list:
        """A list of ``kind`` ("number": finite floats, "integer", "string": non-empty strings);
        ``nonempty``: at least one entry; ``unique``: no entry twice."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        if not isinstance(v, list):
            raise self.error(f"must be a list, got {v!r}", key)
        if nonempty and not v:
            raise self.error("is empty", key)
        out = []
        for x in v:
            if kind == "number":
                if isinstance(x, bool) or not isinstance(x, (int, float)) or not math.isfinite(x):
                    raise self.error(f"must hold finite numbers, got {x!r}", key)
                x = float(x)
            elif kind == "integer":
                if isinstance(x, bool) or not isinstance(x, int):
                    raise self.error(f"must hold integers, got {x!r}", key)
            elif kind == "string":
                if not isinstance(x, str) or not x:
                    raise self.error(f"must hold non-empty strings, got {x!r}", key)
            else:
                raise ValueError(f"unknown list kind {kind!r}")
            out.append(x)
        if unique:
            dup = sorted({f"{x:g}" if isinstance(x, float) else str(x) for x in out if out.count(x) > 1})
            if dup:
                raise self.error(f"repeats {', '.join(dup)}", key)
        return out

    def quantity(self, key: str, dimension: str, default=REQUIRED, *, implied=None,
                 positive: bool = False, unitless: str | None = None) -> float:
        """A quantity of ``dimension`` in SI (``"2.5 mm"`` -> 0.0025; see :mod:`graspdef.units`);
        ``implied``: the unit of a plain number (name, SI factor or conversion), which is refused
        without it; ``positive``: > 0; ``unitless``: the reason why this file takes plain numbers
        only (e.g. "the file's units are 'consistent'"), refusing text with a unit."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        if unitless is not None and isinstance(v, str):
            raise self.error(f"has a unit ({v!r}) but {unitless}: give a plain number", key)
        x = _units.quantity(v, dimension, implied, self.where(key))
        if positive and not x > 0:
            raise self.error(f"must be positive, got {v!r}", key)
        return x

    def quantity_vector(self, key: str, dimension: str, n: int | None = 3, default=REQUIRED, *,
                        implied=None) -> tuple[float, ...]:
        """A vector quantity in SI (``"[1.0, 2.0, 3.0] mm"``; see :func:`graspdef.units.quantity_vector`)."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        return _units.quantity_vector(v, dimension, n, implied, self.where(key))

    def quantity_vectors(self, key: str, dimension: str, n: int = 3, default=REQUIRED, *,
                         implied=None) -> tuple[tuple[float, ...], ...]:
        """A list of vector quantities in SI (``["[1.0, 2.0, 3.0] mm", ...]``)."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        if not isinstance(v, list):
            raise self.error(f"must be a list of vectors such as \"[1.0, 2.0, 3.0] mm\", got {v!r}", key)
        return tuple(_units.quantity_vector(x, dimension, n, implied, f"{self.where(key)} entry {i + 1}")
                     for i, x in enumerate(v))

    def unit(self, key: str, dimension: str, default=REQUIRED) -> tuple[str, float]:
        """A unit name of ``dimension`` and its SI factor (``("mm", 1e-3)``)."""
        v = self._raw(key, default)
        if key not in self.data:
            return v
        return v, _units.unit_factor(v, dimension, self.where(key))
