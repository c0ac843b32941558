"""Units of a run's results: abstract quantities made into UDUNITS strings.

Problems posed in consistent units (a shell's lengths in the units of its point cloud, its
forces in those of its loads) write their results' ``units`` as abstract quantities
(``"length"``, ``"energy / length^2"``, ``"force"``). When the results are written these
become UDUNITS strings of the run's ``units_system`` (CF conventions require parseable
units), and the abstract expression stays in the variable's ``quantity`` attr:

============== ===== ===== ===== ===== ===== ============
system         length force energy time  mass  viscosity
============== ===== ===== ===== ===== ===== ============
SI             m     N     J     s     kg    Pa s
mm_N_s         mm    N     mJ    s     t     MPa s
nondimensional 1     1     1     1     1     1
============== ===== ===== ===== ===== ===== ============

``nondimensional`` is for problems scaled to be free of units (every quantity then has
units ``1``). Expressions: quantities and numbers joined by ``*``, ``/`` or spaces, with
powers ``^n`` or superscripts (``²``, ``³``); ``"1 / time"`` and ``"energy/length²"`` work.
"""
from __future__ import annotations

import re

#: base quantities the results may name, and their symbol in each units system
UNIT_SYSTEMS: dict[str, dict[str, str]] = {
    "SI": {"length": "m", "force": "N", "energy": "J", "time": "s", "mass": "kg",
           "viscosity": "Pa s", "pressure": "Pa", "stress": "Pa"},
    "mm_N_s": {"length": "mm", "force": "N", "energy": "mJ", "time": "s", "mass": "t",
               "viscosity": "MPa s", "pressure": "MPa", "stress": "MPa"},
    "nondimensional": {},
}
QUANTITIES = frozenset(UNIT_SYSTEMS["SI"])
_SUPERSCRIPT = str.maketrans("⁰¹²³⁴⁵⁶⁷⁸⁹⁻", "0123456789-")
_TOKEN = re.compile(r"\s*(?:(?P<name>[A-Za-z_]+)(?:\^(?P<pow>-?\d+)|(?P<sup>[⁰¹²³⁴⁵⁶⁷⁸⁹⁻]+))?"
                    r"|(?P<one>1)|(?P<op>[*/]))")


def parse_quantity(expression: str) -> dict[str, int] | None:
    """``{"energy": 1, "length": -2}`` for ``"energy / length^2"``; None when the expression
    is not made of the abstract quantities (then it is taken as a UDUNITS string already)."""
    text, pos, sign, powers = str(expression).strip(), 0, 1, {}
    if not text:
        return None
    while pos < len(text):
        match = _TOKEN.match(text, pos)
        if match is None or match.end() == pos:
            return None
        pos = match.end()
        if match["op"]:
            sign = -1 if match["op"] == "/" else sign
            continue
        if match["one"]:
            continue
        name = match["name"]
        if name not in QUANTITIES:
            return None
        power = int(match["pow"] or (match["sup"] or "1").translate(_SUPERSCRIPT))
        powers[name] = powers.get(name, 0) + sign * power
    return {k: v for k, v in powers.items() if v} or None


def to_udunits(expression: str, system: str) -> str:
    """The UDUNITS string of an abstract ``expression`` in ``system`` (see the module doc);
    an expression that is not abstract is returned unchanged."""
    if system not in UNIT_SYSTEMS:
        raise ValueError(f"units_system {system!r} is unknown: use one of "
                         f"{', '.join(UNIT_SYSTEMS)}")
    powers = parse_quantity(expression)
    if powers is None:
        return expression
    symbols = UNIT_SYSTEMS[system]
    if not symbols:
        return "1"
    parts = []
    for name, power in powers.items():
        for symbol in symbols[name].split():
            parts.append(symbol if power == 1 else f"{symbol}{power}")
    return " ".join(parts)


def convert_units(ds, system: str):
    """``ds`` with every abstract ``units`` attr made a UDUNITS string of ``system`` (in
    place; the abstract expression kept as ``quantity``) and ``units_system`` set."""
    for name in list(ds.variables):
        attrs = ds[name].attrs
        units = attrs.get("units")
        if isinstance(units, str) and parse_quantity(units) is not None:
            attrs["quantity"] = units
            attrs["units"] = to_udunits(units, system)
    ds.attrs["units_system"] = system
    return ds


__all__ = ["UNIT_SYSTEMS", "parse_quantity", "to_udunits", "convert_units"]
