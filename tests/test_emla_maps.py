"""EMLA efficiency maps and the ``hiab-sim emla-map`` command."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure

from hiab_sim.cli import main
from hiab_sim.emla import load_emla_set, operating_point
from hiab_sim.emla.maps import efficiency_map, plot_efficiency_map, save_csv, save_npz
from hiab_sim.errors import InvalidInputError

EMLAS = load_emla_set("paper")


def test_map_covers_all_four_quadrants_with_the_envelope_inside_the_grid() -> None:
    """The grid spans +-force and +-velocity; its border lies outside the envelope, its centre inside."""
    emap = efficiency_map(EMLAS.lift, n_force=41, n_velocity=31)
    assert emap.efficiency.shape == (41, 31) and emap.margins.shape == (3, 41, 31)
    assert emap.force.min() < 0 < emap.force.max() and emap.velocity.min() < 0 < emap.velocity.max()
    assert not emap.within_envelope[[0, -1], :].any() and not emap.within_envelope[:, [0, -1]].any()
    assert emap.within_envelope[20, 15]
    inside = emap.within_envelope & ~np.isnan(emap.efficiency)
    motoring = inside & (emap.mechanical_power > 0)
    generating = inside & (emap.mechanical_power < 0) & (emap.electrical_power < 0)
    assert motoring.sum() > 100 and generating.sum() > 100
    assert np.all(emap.efficiency[inside] <= 1.0)
    assert 0.9 < np.nanmax(emap.efficiency[motoring]) < 1.0


def test_map_overlays_operating_points_and_saves_a_png(tmp_path: Path) -> None:
    """plot_efficiency_map draws given (f_x, v_x) points on the map and returns an Agg figure."""
    emap = efficiency_map(EMLAS.tilt, n_force=31, n_velocity=31)
    t = np.linspace(0, 6, 50)
    points = (40e3 * np.sin(t), 0.1 * np.cos(t))
    fig = plot_efficiency_map(emap, operating_points=points)
    assert isinstance(fig, Figure)
    line = next(ln for ln in fig.axes[0].get_lines() if ln.get_label() == "operating points")
    np.testing.assert_allclose(line.get_ydata(), points[0] / 1e3)
    fig.savefig(tmp_path / "map.png")
    assert (tmp_path / "map.png").stat().st_size > 10_000
    with pytest.raises(InvalidInputError, match="operating_points"):
        plot_efficiency_map(emap, operating_points=(np.zeros(3), np.zeros(4)))


def test_csv_and_npz_hold_the_same_numbers_as_the_model(tmp_path: Path) -> None:
    """Every CSV row is the model's power at its (f_x, v_x); the NPZ keeps the grid arrays."""
    emap = efficiency_map(EMLAS.telescope, n_force=11, n_velocity=9)
    save_csv(emap, tmp_path / "m.csv")
    save_npz(emap, tmp_path / "m.npz")
    table = np.loadtxt(tmp_path / "m.csv", delimiter=",", skiprows=1)
    assert table.shape == (99, 9)
    p = operating_point(EMLAS.telescope, table[:, 0], table[:, 1], 0.0).electrical_power
    np.testing.assert_allclose(table[:, 3], p, rtol=1e-9)
    with np.load(tmp_path / "m.npz") as data:
        for name, value in vars(emap).items():  # every field that has a value comes back as it was
            if value is not None:
                np.testing.assert_array_equal(data[name], value, err_msg=name)
        assert list(data["margin_names"]) == ["peak_torque", "rated_speed", "voltage"]


def test_emla_map_command_writes_figure_csv_and_npz(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``hiab-sim emla-map --actuator telescope -o .. --csv .. --npz ..`` exits 0 and writes all three."""
    out = tmp_path / "t.png"
    status = main(
        ["emla-map", "--actuator", "telescope", "-o", str(out), "--csv", str(tmp_path / "t.csv"),
         "--npz", str(tmp_path / "t.npz"), "--resolution", "41"]
    )  # fmt: skip
    assert status == 0
    assert out.exists() and (tmp_path / "t.csv").exists() and (tmp_path / "t.npz").exists()
    # the shipped set pays its 0.87 forward transmission efficiency: 2 pi 2 x 0.87 (42 - 0.2) N m / 10 mm = 45.7 kN
    assert "peak force 45.7 kN (hydraulic 37.3 kN)" in capsys.readouterr().out


def test_emla_map_command_rejects_a_missing_output_folder(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """An output path in a folder that does not exist exits 2 with a message, not a traceback."""
    status = main(["emla-map", "-o", str(tmp_path / "nowhere" / "x.png"), "--resolution", "11"])
    assert status == 2
    assert "folder must exist" in capsys.readouterr().err


def test_design_overlays_use_one_colour_and_line_style_per_design_apart_from_the_hydraulic_lines() -> None:
    """Each design's path carries its style colour and its own line style; no design shares the hydraulic colour."""
    from matplotlib.colors import to_hex

    from hiab_sim.style import COLOURS

    emap = efficiency_map(EMLAS.lift, n_force=21, n_velocity=21)
    t = np.linspace(0, 6, 40)
    designs = {"initial": (30e3 * np.sin(t), 0.1 * np.cos(t)), "optimal": (25e3 * np.sin(t), 0.08 * np.cos(t))}
    fig = plot_efficiency_map(emap, designs=designs)
    lines = {ln.get_label(): ln for ln in fig.axes[0].get_lines()}
    styles = set()
    for name, (force, _) in designs.items():
        line = lines[f"{name} design: operating points over the motion"]
        assert to_hex(line.get_color()) == COLOURS[name].lower()
        styles.add(line.get_linestyle())
        np.testing.assert_allclose(line.get_ydata(), force / 1e3)
    assert len(styles) == 2 and "--" not in styles  # dashed is the hydraulic lines' style
    hydraulic = {to_hex(ln.get_color()) for ln in fig.axes[0].get_lines() if ln.get_linestyle() == "--"}
    assert hydraulic == {COLOURS["hydraulic"].lower()}
    assert len({COLOURS[n] for n in ("initial", "optimal", "rounded", "hydraulic")}) == 4
