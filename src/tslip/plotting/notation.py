"""How the report and the figures write numbers, units and the thesis's formulas.

Units are stored in plain notation, as :data:`tslip.model.units.UNIT` writes
them (``"g^1/2 L^-1/2"``, ``"MgL^-1"``, ``"rad"``, ``"-"``), and a claim's
number key ends with its unit in brackets (``"push limit [g^1/2 L^1/2]"``).
Here they are typeset: carets become superscripts, in HTML
(:func:`unit_html`, :func:`key_html`) and in matplotlib's mathtext
(:func:`unit_tex`, :func:`axis_label`), the one notation of every figure.
:func:`tex_html` renders the small LaTeX subset of the thesis sentences the
claims quote (``$-0.73 \\text{ g}^{1/2} \\text{ L}^{1/2}$``) as HTML.
:func:`number` and :func:`value` print a claim's numbers: ``-0`` as ``0``,
a range with as few digits as keep its ends apart.
"""

from __future__ import annotations

import html
import math
import re
from collections.abc import Mapping
from typing import Any

__all__ = ["GREEK", "axis_label", "key_html", "number", "split_unit", "tex_html", "unit_html",
           "unit_tex", "value"]

#: A unit's exponent in plain notation: ``^1/2``, ``^-1``, ``^2``.
_EXP = re.compile(r"\^(-?[0-9]+(?:/[0-9]+)?)")
#: A trailing `` [unit]`` of a number key.
_UNIT_SUFFIX = re.compile(r"^(.*?)\s*\[([^\[\]]+)\]$")


def split_unit(key: str) -> tuple[str, str | None]:
    """``"push limit [g^1/2 L^1/2]"`` -> ``("push limit", "g^1/2 L^1/2")``; no unit: None."""
    m = _UNIT_SUFFIX.match(key)
    return (m.group(1), m.group(2)) if m else (key, None)


def unit_html(unit: str) -> str:
    """A plain-notation unit as HTML: ``g^1/2 L^-1/2`` -> ``g<sup>1/2</sup> L<sup>-1/2</sup>``."""
    return _EXP.sub(lambda m: f"<sup>{m.group(1)}</sup>", html.escape(unit))


def unit_tex(unit: str) -> str:
    """A plain-notation unit in mathtext: ``g^1/2 L^-1/2`` -> ``g$^{1/2}$ L$^{-1/2}$``."""
    return _EXP.sub(lambda m: f"$^{{{m.group(1)}}}$", unit)


def axis_label(quantity: str, unit: str) -> str:
    """An axis label: the quantity (text or mathtext) and its unit in brackets, typeset."""
    return f"{quantity} [{unit_tex(unit)}]"


#: A unit in brackets anywhere in a key: ``"[g^1/2 L^1/2]"``.
_UNIT_ANY = re.compile(r"\[([^\[\]]+)\]")


def key_html(key: str) -> str:
    """A number key with its units typeset (the rest escaped).

    Every bracketed unit is typeset, the trailing one and any inside the key
    (``"median [g^1/2 L^1/2]: passive"``), so no plain ``^`` reaches the page.
    """
    out, at = [], 0
    for m in _UNIT_ANY.finditer(key):
        out += [html.escape(key[at:m.start()]), f"[{unit_html(m.group(1))}]"]
        at = m.end()
    return "".join(out) + html.escape(key[at:])


def number(x: float, digits: int = 4) -> str:
    """``x`` to ``digits`` significant digits; ``-0`` (or a value rounding to it) as ``0``."""
    if not math.isfinite(x):
        return "–" if math.isnan(x) else ("∞" if x > 0 else "-∞")
    s = f"{x:.{digits}g}"
    return s[1:] if re.fullmatch(r"-0(\.0*)?", s) else s


def _range(a: float, b: float) -> str:
    """``[a, b]`` with the fewest significant digits, from 2 to 4, that print distinct ends
    differently (so a range is never ``[0.2, 0.2]`` unless its ends are equal)."""
    for d in (2, 3, 4):
        lo, hi = number(a, d), number(b, d)
        if lo != hi or a == b:
            break
    return f"[{lo}, {hi}]"


def _is_number(x: Any) -> bool:
    return isinstance(x, int | float) and not isinstance(x, bool)


def value(v: Any, key: str = "") -> str:
    """A claim's number as text (plain, not escaped): a float to 4 significant digits,
    a list in brackets, a mapping as ``k: v; ...``. A pair of numbers whose ``key``
    names a range (contains "range") prints as a range (:func:`_range`)."""
    if isinstance(v, float):
        return number(v)
    if isinstance(v, list | tuple):
        if "range" in key.lower() and len(v) == 2 and all(_is_number(x) for x in v):
            return _range(float(v[0]), float(v[1]))
        return "[" + ", ".join(value(x) for x in v) + "]"
    if isinstance(v, Mapping):
        return "; ".join(f"{k}: {value(x, str(k))}" for k, x in v.items())
    return str(v)


#: LaTeX Greek letters and symbols the thesis's sentences use, as Unicode.
GREEK: dict[str, str] = {
    "alpha": "α", "beta": "β", "gamma": "γ", "delta": "δ", "epsilon": "ε", "varepsilon": "ε",
    "zeta": "ζ", "eta": "η", "theta": "θ", "vartheta": "ϑ", "kappa": "κ", "lambda": "λ",
    "mu": "μ", "nu": "ν", "xi": "ξ", "pi": "π", "rho": "ρ", "sigma": "σ", "tau": "τ",
    "phi": "φ", "varphi": "φ", "chi": "χ", "psi": "ψ", "omega": "ω", "Gamma": "Γ",
    "Delta": "Δ", "Theta": "Θ", "Lambda": "Λ", "Pi": "Π", "Sigma": "Σ", "Phi": "Φ",
    "Psi": "Ψ", "Omega": "Ω", "pm": "±", "mp": "∓", "times": "×", "cdot": "·",
    "leq": "≤", "le": "≤", "geq": "≥", "ge": "≥", "approx": "≈", "sim": "∼", "neq": "≠",
    "infty": "∞", "circ": "°", "degree": "°", "rightarrow": "→", "to": "→", "%": "%",
}
#: Spacing commands: ``\,`` ``\;`` ``\:`` ``\!`` ``\ `` ``\\`` ``\quad``.
_SPACES = {",": " ", ";": " ", ":": " ", "!": "", " ": " ", "\\": " ", "quad": " ",
           "qquad": " "}
#: Accents: ``\dot{x}`` -> x with a combining dot above.
_ACCENTS = {"dot": "\u0307", "ddot": "\u0308", "bar": "\u0304", "hat": "\u0302",
            "tilde": "\u0303", "vec": "\u20d7"}
#: Commands whose braced argument is kept as is.
_KEEP = ("text", "mathrm", "textrm", "mathit", "mathbf", "operatorname", "mathsf")


def _group(s: str, i: int) -> tuple[str, int]:
    """The argument at ``s[i]``: a braced group (its inside) or one character; and the end."""
    while i < len(s) and s[i] == " ":
        i += 1
    if i >= len(s):
        return "", i
    if s[i] != "{":
        if s[i] == "\\":  # a command as the argument: \dot\phi
            m = re.match(r"\\([A-Za-z]+|.)", s[i:])
            assert m is not None
            return m.group(0), i + len(m.group(0))
        return s[i], i + 1
    depth = 0
    for j in range(i, len(s)):
        depth += {"{": 1, "}": -1}.get(s[j], 0)
        if depth == 0:
            return s[i + 1:j], j + 1
    return s[i + 1:], len(s)  # unbalanced: take the rest


def _math(s: str) -> str:
    """The inside of ``$...$`` as HTML (``s`` already HTML-escaped)."""
    out: list[str] = []
    i = 0
    while i < len(s):
        ch = s[i]
        if ch in "^_":
            arg, i = _group(s, i + 1)
            tag = "sup" if ch == "^" else "sub"
            out.append(f"<{tag}>{_math(arg)}</{tag}>")
        elif ch == "\\":
            m = re.match(r"\\([A-Za-z]+|.)", s[i:])
            name = m.group(1) if m else ""
            i += 1 + len(name)
            if name in _KEEP:
                arg, i = _group(s, i)
                out.append(_math(arg))
            elif name in _ACCENTS:
                arg, i = _group(s, i)
                out.append(_math(arg) + _ACCENTS[name])
            elif name in _SPACES:
                out.append(_SPACES[name])
            elif name in ("{", "}"):
                out.append(name)
            else:
                out.append(GREEK.get(name, name))
        elif ch in "{}":
            i += 1
        else:
            out.append(ch)
            i += 1
    return "".join(out)


def tex_html(text: str) -> str:
    """``text`` as HTML, escaped, its ``$...$`` formulas typeset with ``<sup>``/``<sub>``.

    Handles the subset the thesis's sentences use: ``\\text{}`` (and ``\\mathrm``),
    ``^{...}``, ``_{...}``, accents (``\\dot``), Greek letters, ``\\Delta``, ``\\pm``
    and spacing. An unpaired ``$`` stays as written.
    """
    parts = html.escape(text, quote=False).split("$")
    if len(parts) % 2 == 0:  # an odd number of $: the last one is literal
        parts[-2:] = [parts[-2] + "$" + parts[-1]]
    return "".join(re.sub(" {2,}", " ", _math(p)) if k % 2 else p for k, p in enumerate(parts))
