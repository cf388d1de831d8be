"""The 3-D result objects save, load, tabulate, print and plot as the planar ones.

Bit-for-bit round trips through .json and .parquet, a unit for every column, a one-line
repr, ``.plot`` drawing on the axes it is given (Agg), a tampered file refused in one
line; the tables checked against the objects' own fields and independent computations
(the eigenvalues of the Jacobian, the gait's energy).
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from matplotlib.figure import Figure

import tslip
from _result_checks import check_frozen, check_plot, check_repr, check_round_trip, check_units
from tslip.spatial import Multipliers, SpatialApex, floquet, preset, symmetric_gaits
from tslip.spatial.lateral import (
    TABLE21_3D_SECTION,
    LateralTable,
    lateral_multipliers,
    markdown,
    table21_params,
)
from tslip.spatial.trunk import TrunkStatus, TrunkTouchdown, trunk_step
from tslip.spatial.trunk_robustness import lateral_limit
from tslip.spatial.trunk_run import trunk_run
from tslip.spatial.trunk_section import from_section

P3 = table21_params()


_td = from_section(P3, TABLE21_3D_SECTION)
# thrown down hard enough to find no touch-down after its first stance (no next state)
_pushed = TrunkTouchdown(_td.y - np.eye(13)[4] * 3.0, _td.foot, _td.side)


@pytest.fixture(scope="module")
def objects():
    p = preset("slip3d")
    gait = symmetric_gaits(p, energy=2.2)[0]
    by_r = LateralTable([lateral_multipliers(table21_params(r=r), TABLE21_3D_SECTION)
                         for r in (0.3, 0.35)])
    grid = LateralTable([lateral_multipliers(table21_params(k_splay=a, k_trail=b),
                                             TABLE21_3D_SECTION)
                         for a in (0.0, 0.5) for b in (0.0, 0.5, 1.0)])
    return {
        "SpatialApex": SpatialApex(1.2, 1.5, -0.07, x=0.3, z=0.1, side=-1),
        "SymmetricGait": gait,
        "Multipliers": floquet(gait),
        "Multipliers, fd": floquet(gait, method="fd"),
        "LateralPoint": by_r[0],
        "LateralTable, r": by_r,
        "LateralTable, gains": grid,
        "LateralLimit": lateral_limit(P3, TABLE21_3D_SECTION, "yaw_rate", n_steps=4,
                                      h=0.02, max_magnitude=0.5),
        "TrunkRun": trunk_run(P3, from_section(P3, TABLE21_3D_SECTION), 3),
        "TrunkTouchdown": _td,
        "TrunkStep": trunk_step(P3, _td),
        "TrunkStep, fall": trunk_step(P3, _pushed),
    }


NAMES = ["SpatialApex", "SymmetricGait", "Multipliers", "Multipliers, fd", "LateralPoint",
         "LateralTable, r", "LateralTable, gains", "LateralLimit", "TrunkRun", "TrunkTouchdown",
         "TrunkStep", "TrunkStep, fall"]
NO_PLOT = {"SpatialApex", "SymmetricGait", "LateralLimit", "TrunkTouchdown", "TrunkStep",
           "TrunkStep, fall"}


@pytest.mark.parametrize("name", NAMES)
def test_is_a_frozen_result_dataclass(objects, name):
    check_frozen(objects[name])


@pytest.mark.parametrize("suffix", [".json", ".parquet"])
@pytest.mark.parametrize("name", NAMES)
def test_round_trip_is_bit_for_bit(objects, name, suffix, tmp_path):
    check_round_trip(objects[name], tmp_path / f"r{suffix}")


def test_run_round_trips_through_csv(objects, tmp_path):
    check_round_trip(objects["TrunkRun"], tmp_path / "r.csv")


@pytest.mark.parametrize("name", NAMES)
def test_table_has_a_unit_for_every_column(objects, name):
    check_units(objects[name])


@pytest.mark.parametrize("name", NAMES)
def test_repr_is_one_short_line(objects, name):
    check_repr(objects[name])


@pytest.mark.parametrize("name", sorted(set(NAMES) - NO_PLOT))
def test_plot_draws_on_the_given_axes(objects, name):
    check_plot(objects[name])


@pytest.mark.parametrize("name", sorted(NO_PLOT))
def test_results_without_a_figure_have_no_plot(objects, name):
    assert not hasattr(objects[name], "plot")


def test_the_public_constructors_are_unchanged():
    """Positional and keyword construction as before the classes became Results."""
    a = SpatialApex(1.0, 2.0)
    assert (a.vz, a.x, a.z, a.side) == (0.0, 0.0, 0.0, 1)
    assert np.array_equal(a.as_array(), [1.0, 2.0, 0.0, 0.0, 0.0, 1.0])
    with pytest.raises(ValueError, match="SpatialApex.side"):
        SpatialApex(1.0, 2.0, side=0)


def test_apex_and_gait_tables_hold_their_fields_and_units(objects):
    g = objects["SymmetricGait"]
    df = g.to_dataframe()
    assert df.attrs["units"] == {"y": "L", "vx": "g^1/2 L^1/2", "vz": "g^1/2 L^1/2", "x": "L",
                                 "z": "L", "side": "-", "energy": "MgL", "residual": "-"}
    a, p = g.apex, g.params
    assert df.loc[0, "y"] == a.y and df.loc[0, "vz"] == a.vz and df.loc[0, "side"] == 1
    # the energy column is the apex's energy, computed here from its definition
    assert abs(df.loc[0, "energy"] - p.m * (0.5 * (a.vx**2 + a.vz**2) + p.g * a.y)) < 1e-12


def test_multiplier_table_is_the_eigenvalues_of_the_jacobian(objects):
    m = objects["Multipliers"]
    df = m.to_dataframe()
    ev = np.linalg.eigvals(m.jacobian)  # independent: the full spectrum of the 3 x 3 matrix
    z = df["real"].to_numpy() + 1j * df["imag"].to_numpy()
    assert len(z) == 3 and df["trivial"].sum() == 1
    for lam in ev:
        assert np.min(np.abs(z - lam)) < 1e-6
    assert np.allclose(df["modulus"], np.abs(z))
    assert df["modulus"][~df["trivial"]].max() == pytest.approx(m.largest)
    assert abs(z[df["trivial"].to_numpy()][0] - 1.0) < 1e-6  # the energy's multiplier
    pair = Multipliers(np.array([0.3 + 0.4j, 0.3 - 0.4j, 1.0]), np.array([0.3 + 0.4j,
                       0.3 - 0.4j]), np.array([1.0 + 0j]), np.eye(3), "fd")
    assert pair.to_dataframe()["modulus"].tolist() == pytest.approx([0.5, 0.5, 1.0])


def test_multiplier_plot_puts_the_points_at_the_multipliers(objects):
    m = objects["Multipliers"]
    fig = m.plot()
    ax = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax.lines}
    assert np.allclose(lines["multiplier"].get_xdata(), m.nontrivial.real)
    assert np.allclose(lines["multiplier"].get_ydata(), m.nontrivial.imag)
    circle = lines["unit circle"]
    assert np.allclose(np.hypot(circle.get_xdata(), circle.get_ydata()), 1.0)


def test_lateral_table_is_a_sequence_of_its_points(objects):
    t = objects["LateralTable, r"]
    assert len(t) == 2 and list(t) == list(t.points) and t[1] is t.points[1]
    assert markdown(t) == markdown(list(t.points))
    df = t.to_dataframe()
    assert df["r"].tolist() == [0.3, 0.35] and df.attrs["units"]["r"] == "L"
    assert df["largest"].tolist() == [pt.largest for pt in t]
    assert df.attrs["units"]["lateral_speed"] == "g^1/2 L^1/2"
    with pytest.raises(TypeError, match=r"LateralTable.points\[0\]"):
        LateralTable([1.0])


def test_lateral_table_plot_over_r_and_over_the_gain_grid(objects):
    by_r = objects["LateralTable, r"].plot()
    (line,) = [ln for ln in by_r.axes[0].lines if ln.get_marker() == "o"]
    assert line.get_xdata().tolist() == [0.3, 0.35]
    grid = objects["LateralTable, gains"]
    fig = grid.plot()
    img = np.asarray(fig.axes[0].collections[0].get_array()).reshape(2, 3)
    assert img.shape == (2, 3)  # k_splay rows x k_trail columns
    for pt in grid:
        i, j = [0.0, 0.5].index(pt.params.k_splay), [0.0, 0.5, 1.0].index(pt.params.k_trail)
        assert img[i, j] == pt.largest


def test_lateral_point_trivial_are_the_three_nearest_one(objects):
    pt = objects["LateralPoint"]
    assert len(pt.trivial) == 3 and np.max(np.abs(pt.trivial - 1.0)) == pt.trivial_error
    rest = sorted(np.abs(pt.nontrivial))
    assert sorted(np.abs(np.setdiff1d(pt.multipliers, pt.trivial))) == pytest.approx(rest)


def test_lateral_limit_table(objects):
    lim = objects["LateralLimit"]
    row = lim.to_dataframe().iloc[0]
    assert row["kind"] == "yaw_rate" and row["unit"] == "rad g^1/2 L^-1/2"
    assert row["limit"] == lim.limit and row["status"] == lim.status.name


@pytest.mark.parametrize("name, field, value, why", [
    ("SpatialApex", "side", 0, "SpatialApex.side"),
    ("SymmetricGait", "params", None, "SpatialParams.k"),
    ("LateralPoint", "params", None, "TrunkParams.splay"),
    ("TrunkTouchdown", "side", 0, "TrunkTouchdown.side"),
    ("TrunkTouchdown", "y", [1.0, 2.0], "TrunkTouchdown.y"),
    ("TrunkTouchdown", "y", [0.0, 1.0, 0.0, 3.0, 0.0, 0.0, 2.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0],
     "not a unit quaternion"),
])
def test_a_tampered_file_is_refused_in_one_line(objects, tmp_path, name, field, value, why):
    path = objects[name].save(tmp_path / "r.json")
    rec = json.loads(path.read_text())
    fields = rec["result"]["fields"]
    if field == "params":  # a parameter out of its range
        key = "k" if name == "SymmetricGait" else "splay"
        fields["params"]["fields"][key] = -1.0 if key == "k" else 5.0
    else:
        fields[field] = value
    path.write_text(json.dumps(rec))
    with pytest.raises(ValueError, match=why) as err:
        tslip.load(path)
    assert "\n" not in str(err.value) and str(path) in str(err.value)


def test_a_file_naming_a_function_is_refused(objects, tmp_path):
    path = objects["TrunkRun"].save(tmp_path / "r.parquet")
    rec_path = path.with_suffix(".json")
    rec = json.loads(rec_path.read_text())
    rec["result"]["__type__"] = "tslip._io:write_json"
    rec_path.write_text(json.dumps(rec))
    with pytest.raises(ValueError, match="not a class") as err:
        tslip.load(path)
    assert "\n" not in str(err.value)


def test_run_record_names_the_3d_parameters(objects, tmp_path):
    path = objects["TrunkRun"].save(tmp_path / "r.json")
    run = json.loads(path.read_text())["run"]
    assert run["params"]["splay"] == 0.05 and run["params"]["controller"] == {"type": "passive"}
    assert isinstance(objects["TrunkRun"].plot(), Figure)


def test_every_spatial_result_class_is_covered(objects):
    """Each Result subclass of tslip.spatial is in the table above."""
    from tslip._results import Result

    def subclasses(cls):
        for sub in cls.__subclasses__():
            yield sub
            yield from subclasses(sub)

    classes = {c.__name__ for c in subclasses(Result) if c.__module__.startswith("tslip.spatial")}
    assert classes and classes <= {type(o).__name__ for o in objects.values()}


def test_touchdown_and_stride_tables_hold_their_fields(objects):
    td, st, fall = objects["TrunkTouchdown"], objects["TrunkStep"], objects["TrunkStep, fall"]
    row = td.to_dataframe().iloc[0]
    assert [row[k] for k in ("x", "y", "z", "qw", "w_pitch")] == [td.y[0], td.y[1], td.y[2],
                                                                 td.y[6], td.y[12]]
    assert row["foot_x"] == td.foot[0] and row["side"] == td.side
    assert td.to_dataframe().attrs["units"]["vz"] == "g^1/2 L^1/2"
    srow = st.to_dataframe().iloc[0]
    assert srow["status"] == "OK" and srow["stance_time"] == st.stance_time
    assert srow["x"] == st.state.y[0] and srow["side"] == -td.side  # the other leg lands
    assert srow["lo_vy"] == st.liftoff[4]
    frow = fall.to_dataframe().iloc[0]
    assert fall.status == TrunkStatus.FALL_NO_TOUCHDOWN and fall.state is None
    assert frow["status"] == "FALL_NO_TOUCHDOWN"
    assert np.isnan(frow["x"]) and np.isnan(frow["foot_z"])


def test_a_touchdown_loads_with_its_stored_bits(tmp_path):
    """A kernel's touch-down keeps its quaternion as computed (a unit quaternion to
    rounding, not renormalised): the file gives it back bit for bit, though the
    constructor would renormalise it."""
    y = _td.y.copy()
    y[6:10] *= 1.0 + 2.0**-50  # a unit quaternion to 1e-15, as a stride leaves it
    td = TrunkTouchdown._unchecked(y, _td.foot.copy(), _td.side)
    assert not np.array_equal(TrunkTouchdown(y, td.foot, td.side).y, y)  # the test's point
    back = tslip.load(td.save(tmp_path / "td.json"))
    assert back.y.tobytes() == y.tobytes() and back.side == td.side
