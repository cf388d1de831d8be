"""The report's notation: units typeset, the thesis's formulas rendered, numbers printed.

Expected strings are written out by hand from the rules (docs/reproducing.md):
a caret exponent becomes a superscript, ``-0`` prints as ``0``, a range gets
the fewest significant digits (2 to 4) that print its distinct ends apart.
"""

from __future__ import annotations

import re

import pytest
from matplotlib.figure import Figure

from tslip.model.units import UNIT
from tslip.plotting.notation import (
    axis_label,
    key_html,
    number,
    split_unit,
    tex_html,
    unit_html,
    unit_tex,
    value,
)
from tslip.sweeps.claims import CLAIMS


@pytest.mark.parametrize(("unit", "html", "tex"), [
    ("g^1/2 L^1/2", "g<sup>1/2</sup> L<sup>1/2</sup>", "g$^{1/2}$ L$^{1/2}$"),
    ("rad g^1/2 L^-1/2", "rad g<sup>1/2</sup> L<sup>-1/2</sup>", "rad g$^{1/2}$ L$^{-1/2}$"),
    ("MgL^-1", "MgL<sup>-1</sup>", "MgL$^{-1}$"),
    ("ML^2", "ML<sup>2</sup>", "ML$^{2}$"),
    ("L", "L", "L"), ("rad", "rad", "rad"), ("-", "-", "-"),
])
def test_units_typeset_in_html_and_mathtext(unit, html, tex) -> None:
    assert unit_html(unit) == html
    assert unit_tex(unit) == tex


def test_every_unit_of_the_package_renders_in_mathtext() -> None:
    """matplotlib parses each typeset unit (a bad one raises when drawn), with no caret left."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = Figure()
    ax = fig.add_subplot()
    for unit in UNIT.values():
        label = axis_label("q", unit)
        assert "^" not in label.replace("$^{", "")
        ax.set_xlabel(label)
        FigureCanvasAgg(fig).draw()


def test_number_keys_split_and_typeset_their_unit() -> None:
    assert split_unit("push limit [g^1/2 L^1/2]") == ("push limit", "g^1/2 L^1/2")
    assert split_unit("x_p/dphi") == ("x_p/dphi", None)
    assert key_html("a < b [L^2]") == "a &lt; b [L<sup>2</sup>]"
    assert key_html("ratio") == "ratio"
    # a unit inside the key (a prefixed or suffixed label) is typeset too, not left as "^"
    assert key_html("median [rad g^1/2 L^-1/2]: passive") == (
        "median [rad g<sup>1/2</sup> L<sup>-1/2</sup>]: passive")
    assert key_html("set-up: v0 [g^1/2 L^1/2] at r [L]") == (
        "set-up: v0 [g<sup>1/2</sup> L<sup>1/2</sup>] at r [L]")


@pytest.mark.parametrize(("x", "text"), [
    (-0.0, "0"), (0.0, "0"), (-1e-7, "-1e-07"), (-0.00004, "-4e-05"), (1.23456, "1.235"),
    (-0.725, "-0.725"), (float("nan"), "–"), (float("inf"), "∞"),
])
def test_number_prints_minus_zero_as_zero(x, text) -> None:
    assert number(x) == text


def test_a_value_that_rounds_to_minus_zero_prints_zero() -> None:
    assert number(-0.0004, 1) == "-0.0004"  # significant digits: not zero
    assert number(round(-0.0004, 3)) == "0"


@pytest.mark.parametrize(("pair", "text"), [
    ([0.19987, 0.20041], "[0.1999, 0.2004]"),  # 2 and 3 digits print [0.2, 0.2]
    ([0.2, 0.221], "[0.2, 0.22]"),
    ([13.62, 22.31], "[14, 22]"),
    ([0.2, 0.2], "[0.2, 0.2]"),  # equal ends print equal
    ([0.123456, 0.123457], "[0.1235, 0.1235]"),  # at most 4 digits
    ([-0.0, 1.0], "[0, 1]"),
])
def test_a_range_prints_with_the_fewest_digits_that_part_its_ends(pair, text) -> None:
    assert value(pair, "stance time range [g^-1/2 L^1/2]") == text


def test_a_pair_that_is_not_a_range_keeps_four_digits() -> None:
    assert value([0.19987, 0.20041], "torque at -0.5 / +0.5") == "[0.1999, 0.2004]"
    assert value([0.212, 0.115], "|step-down| ends") == "[0.212, 0.115]"
    assert value({"a [L]": -0.0, "n": 3}) == "a [L]: 0; n: 3"


@pytest.mark.parametrize(("tex", "html"), [
    (r"around $4.0 g^{1/2} L^{1/2}$.", "around 4.0 g<sup>1/2</sup> L<sup>1/2</sup>."),
    (r"is $-0.73 \text{ g}^{1/2} \text{ L}^{1/2}$,", "is -0.73 g<sup>1/2</sup> L<sup>1/2</sup>,"),
    (r"over $0.86L$", "over 0.86L"),
    (r"where $r > 0$", "where r &gt; 0"),
    (r"$\dot{\phi}_{ref} = \Delta\alpha$", "φ\u0307<sub>ref</sub> = Δα"),
    (r"$\dot x$ and $\beta_0 \pm 0.1$", "x\u0307 and β<sub>0</sub> ± 0.1"),
    (r"$C_1 < 10^{-4}$", "C<sub>1</sub> &lt; 10<sup>-4</sup>"),
    ("costs $5", "costs $5"),  # an unpaired dollar is text
])
def test_tex_html_renders_the_thesis_subset(tex, html) -> None:
    assert tex_html(tex) == html


def test_no_raw_latex_is_left_in_any_claim_text() -> None:
    """Every quote, summary, reading and source of the claim list, rendered."""
    seen = 0
    for c in CLAIMS:
        for text in (c.quote, c.text, c.reading, c.source):
            out = tex_html(text)
            assert "$" not in out and "\\" not in out, (c.figure, out)
            assert not re.search(r"[\^{}]", out), (c.figure, out)
            for name in set(re.findall(r"\\([A-Za-z]+)", text)):  # no command name leaks
                plain = re.sub(r"\\[A-Za-z]+", "", text)
                assert out.count(name) <= plain.count(name), (c.figure, name, out)
            seen += "$" in text
    assert seen >= 4  # the list does quote formulas (4.9, 4.16, 4.24, 6.1, 6.2)
