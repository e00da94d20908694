"""Dataset config files and presets: what they describe and how bad ones are reported."""

from __future__ import annotations

from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from davis_ag.errors import UserError
from davis_ag.generate.one_scene import scene_seed
from davis_ag.generate.run_config import (
    load_dataset_config,
    parse_dataset_config,
    preset_names,
    single_group_config,
    use_strawberry_altitudes,
)
from davis_ag.scene.specs import CROPS, SCENARIOS

#: Table 3 of the paper: scenes per group.
TABLE_3 = {
    "Single-Strawberry": 86,
    "Single-Tomato": 130,
    "Single-Vine": 182,
    "Multi-Strawberry": 77,
    "Multi-Tomato": 113,
    "Multi-Vine": 44,
}


def test_presets_ship_with_the_package() -> None:
    assert {"paper", "mini"} <= set(preset_names())


def test_paper_preset_has_table_3_counts() -> None:
    config = load_dataset_config("paper")
    assert {g.name: g.scenes for g in config.groups} == TABLE_3
    assert (config.camera.width, config.camera.height) == (1280, 720)
    requests = config.requests()
    assert len(requests) == sum(TABLE_3.values())
    assert len({r.seed for r in requests}) == len(requests)  # every scene its own seed
    # The paper preset uses the paper's grids unchanged.
    assert all(g.scenario.step in (0.25, 0.5) for g in config.groups)


def test_mini_preset_is_small() -> None:
    config = load_dataset_config("mini")
    assert len(config.requests()) <= 3
    assert config.camera.width * config.camera.height <= 640 * 360


def test_config_file_with_grid_override(tmp_path: Path) -> None:
    path = tmp_path / "small.yaml"
    path.write_text(
        "seed: 7\nimage_size: [320, 180]\ngrid: {step: 0.5}\ngroups:\n"
        "  - {scenario: single, crop: tomato, scenes: 2, first: 3}\n"
        "  - {scenario: mp, crop: grape, scenes: 1, grid: {altitude_levels: [0], headings: 4}}\n"
    )
    config = load_dataset_config(path)
    assert config.name == "small" and config.seed == 7
    assert [r.folder for r in config.requests()] == ["Single-Tomato/003", "Single-Tomato/004", "Multi-Vine/000"]
    sp, mp = config.groups
    assert sp.scenario.step == 0.5 and sp.scenario.extent == (3.0, 3.0)
    assert mp.scenario.step == 0.5 and mp.scenario.altitude_levels == (0,) and mp.scenario.headings == 4
    # Seeds depend on names and indices only, not on the grid.
    assert config.requests()[0].seed == scene_seed(7, SCENARIOS["sp"], CROPS["tomato"], 3)


def test_only_picks_scenes_and_groups() -> None:
    config = load_dataset_config("paper")
    picked = config.requests(["single-strawberry/3", "Multi-Vine"])
    assert picked[0].folder == "Single-Strawberry/003"
    assert [r.folder for r in picked[1:]] == [f"Multi-Vine/{i:03d}" for i in range(44)]
    full = {r.folder: r.seed for r in config.requests()}
    assert picked[0].seed == full["Single-Strawberry/003"]  # the same scene as in the full run
    with pytest.raises(UserError, match="not a scene or group"):
        config.requests(["Single-Strawberry/086"])


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("groups: [", "not valid YAML at line"),
        ("- 1\n- 2\n", "must be a mapping"),
        ("seed: 1\n", "groups: missing"),
        ("groups: []\n", "groups: must be a non-empty list"),
        ("sed: 1\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n", "sed: unknown key"),
        (
            "seed: -1\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n",
            "seed: must be a whole number from 0 to 4294967295, not -1",
        ),
        ("seed: 1.5\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n", "seed: must be a whole number"),
        ("image_size: 1280\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n", "image_size: must be WIDTHxHEIGHT"),
        (
            "image_size: 8x8\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n",
            "image_size: 8x8: each side must be from 16 to 8192 pixels",
        ),
        (
            "groups: [{scenario: sp, crop: banana, scenes: 1}]\n",
            "groups.0.crop: unknown crop 'banana': choose one of strawberry, tomato, vine",
        ),
        ("groups: [{scenario: xp, crop: tomato, scenes: 1}]\n", "groups.0.scenario: unknown scenario"),
        ("groups: [{scenario: sp, crop: tomato}]\n", "groups.0.scenes: missing"),
        (
            "groups: [{scenario: sp, crop: tomato, scenes: 0}]\n",
            "groups.0.scenes: must be a whole number from 1 to 1000",
        ),
        ("groups: [{scenario: sp, crop: tomato, scenes: 'many'}]\n", "groups.0.scenes: must be a whole number"),
        ("groups: [{scenario: sp, crop: tomato, scenes: 5, first: 998}]\n", "do not fit 000..999"),
        ("groups: [{scenario: sp, crop: tomato, scenes: 1, sceens: 2}]\n", "groups.0.sceens: unknown key"),
        (
            "groups:\n - {scenario: sp, crop: tomato, scenes: 1}\n - {scenario: single, crop: tomato, scenes: 2}\n",
            "groups.1: Single-Tomato is already groups.0",
        ),
        ("grid: {step: 0}\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n", "grid.step: must be greater than 0"),
        ("grid: {stepp: 1}\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n", "grid.stepp: unknown key"),
        (
            "groups: [{scenario: sp, crop: tomato, scenes: 1, grid: {altitude_levels: [2, 0]}}]\n",
            "groups.0.grid.altitude_levels: must list distinct levels",
        ),
        ("groups: [{scenario: sp, crop: tomato, scenes: 1, grid: {headings: 4}}]\n", "only 1"),
        ("groups: [{scenario: mp, crop: tomato, scenes: 1, grid: {headings: 8}}]\n", "does not work for multi plant"),
        ("groups: [{scenario: sp, crop: tomato, scenes: 1, grid: {extent: [1, 1], step: 2}}]\n", "no position fits"),
        (
            "strawberry_altitudes: fig2\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n",
            "strawberry_altitudes: must be 'table1' or 'readme', not 'fig2'",
        ),
        (
            "image_size: 99999x99999\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n",
            "image_size: 99999x99999: each side must be from 16 to 8192 pixels (the renderer's limit)",
        ),
        (
            "seed: 4294967296\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n",
            "seed: must be a whole number from 0 to",
        ),
        (
            "renderer: vulkan\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n",
            "renderer: must be 'opengl' or 'helios'",
        ),
        # Issue 33 case 2: a step of 1e-9 m grew until the kernel killed the run at 24 GB.
        (
            "grid: {step: 1e-9}\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n",
            "grid: step 1e-09 m over [3.0, 3.0] m gives up to 27,000,000,018,000,000,003 views a scene, more than 10,000",
        ),
        ("grid: {step: 0.01}\ngroups: [{scenario: mp, crop: vine, scenes: 1}]\n", "views a scene, more than 10,000"),
        (
            "groups: [{scenario: sp, crop: tomato, scenes: 1, grid: {step: 0.001}}]\n",
            "groups.0.grid: step 0.001 m over",
        ),
        (
            "grid: {extent: [1000, 3]}\ngroups: [{scenario: sp, crop: tomato, scenes: 1}]\n",
            "grid.extent.0: must be less than or equal to 100",
        ),
    ],
)
def test_bad_configs_name_file_key_and_problem(text: str, message: str) -> None:
    with pytest.raises(UserError) as caught:
        parse_dataset_config(text, "bad.yaml")
    assert str(caught.value).startswith("bad.yaml: ")
    assert message in str(caught.value)
    assert "\n" not in str(caught.value)


def test_missing_config_lists_presets(tmp_path: Path) -> None:
    with pytest.raises(UserError, match=r"no config file 'papr' and no preset of that name.*mini"):
        load_dataset_config("papr")
    with pytest.raises(UserError, match="is a folder"):
        load_dataset_config(tmp_path)
    # Issue 33 case 9: --config /dev/zero was called a folder (and a read would never end).
    with pytest.raises(UserError, match="/dev/zero is not a regular file"):
        load_dataset_config("/dev/zero")


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    st.recursive(
        st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=12),
        lambda inner: (
            st.lists(inner, max_size=4)
            | st.dictionaries(
                st.sampled_from(
                    [
                        "groups",
                        "grid",
                        "step",
                        "extent",
                        "scenes",
                        "crop",
                        "scenario",
                        "seed",
                        "image_size",
                        "headings",
                        "first",
                        "x",
                    ]
                ),
                inner,
                max_size=5,
            )
        ),
        max_leaves=20,
    )
)
def test_any_yaml_value_is_a_config_or_one_line(value: object) -> None:
    """Whatever the file holds, the parser gives a config whose grids respect the bounds, or one line."""
    import yaml

    from davis_ag.formats.models import MAX_VIEWS_PER_SCENE
    from davis_ag.scene.view_grid import lattice_shape

    try:
        config = parse_dataset_config(yaml.safe_dump(value), "fuzz.yaml")
    except UserError as error:
        assert str(error).startswith("fuzz.yaml") and "\n" not in str(error)
        return
    for group in config.groups:
        nx, ny = lattice_shape(group.scenario)
        assert nx * ny * len(group.scenario.altitude_levels) * group.scenario.headings <= MAX_VIEWS_PER_SCENE


def test_single_group_from_flags() -> None:
    config = single_group_config("mp", "vine", 2, 5, 3, (640, 360))
    assert [r.folder for r in config.requests()] == ["Multi-Vine/005", "Multi-Vine/006"]
    with pytest.raises(UserError, match="do not fit"):
        single_group_config("sp", "tomato", 2, 999, 0, (640, 360))


def test_strawberry_altitudes_are_table_1s_unless_the_readmes_are_asked_for() -> None:
    groups = "groups:\n  - {scenario: sp, crop: strawberry, scenes: 1}\n  - {scenario: sp, crop: tomato, scenes: 1}\n"
    table1 = parse_dataset_config(groups, "a.yaml")
    readme = parse_dataset_config("strawberry_altitudes: readme\n" + groups, "b.yaml")
    # Table 1: 25/40/55 cm; the Fig. 2 caption and the dataset's README: 0.50/0.75/1.00 m.
    assert table1.groups[0].crop.altitudes == (0.25, 0.40, 0.55)
    assert readme.groups[0].crop.altitudes == (0.50, 0.75, 1.00)
    assert table1.groups[1].crop == readme.groups[1].crop == CROPS["tomato"]  # strawberry only
    # The --strawberry-altitudes flag's path, on a config from flags.
    flags = use_strawberry_altitudes(single_group_config("mp", "strawberry", 1, 0, 0, (64, 36)), "readme")
    assert flags.groups[0].crop.altitudes == (0.50, 0.75, 1.00)
    with pytest.raises(UserError, match="choose table1 or readme"):
        use_strawberry_altitudes(table1, "high")
    # Scenes of either choice keep their seeds; dataset.json records the altitudes, so a folder
    # never mixes the two.
    from davis_ag.generate.dataset_files import dataset_settings

    assert table1.requests()[0].seed == readme.requests()[0].seed
    grids = [dataset_settings(c.requests())["groups"]["Single-Strawberry"]["grid"] for c in (table1, readme)]
    assert grids[0]["altitudes_m"] == [0.25, 0.40, 0.55] and grids[1]["altitudes_m"] == [0.50, 0.75, 1.00]


def test_generate_flag_takes_the_readme_altitudes(
    capsys: pytest.CaptureFixture, monkeypatch: pytest.MonkeyPatch, tmp_path: Path
) -> None:
    from davis_ag import cli
    from davis_ag.commands import generate

    asked: list = []

    def stop(requests: list, out: Path, options: object) -> None:  # what generate would make
        asked.extend(requests)
        raise UserError("stopped before rendering")

    monkeypatch.setattr(generate, "run_dataset", stop)
    assert cli.main(["generate", "--strawberry-altitudes", "readme", "--out", str(tmp_path)]) == 2
    assert [r.crop.altitudes for r in asked] == [(0.50, 0.75, 1.00)]
    asked.clear()
    assert cli.main(["generate", "--config", "mini", "--out", str(tmp_path)]) == 2
    assert [r.crop.altitudes for r in asked if r.crop.name == "strawberry"] == [(0.25, 0.40, 0.55)]
    with pytest.raises(SystemExit) as stopped:
        cli.main(["generate", "--strawberry-altitudes", "fig2", "--out", str(tmp_path)])
    assert stopped.value.code == 2 and "invalid choice: 'fig2'" in capsys.readouterr().err


def test_a_config_bomb_is_refused_before_anything_is_written(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 33 case 2: ``grid: {step: 1e-9}`` wrote dataset.json, then ate the machine."""
    from davis_ag.cli import main

    bomb = tmp_path / "bomb.yaml"
    bomb.write_text("grid: {step: 1e-9}\ngroups: [{scenario: sp, crop: strawberry, scenes: 2}]\n")
    assert main(["generate", "--config", str(bomb), "--out", str(tmp_path / "data")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "views a scene, more than 10,000" in err
    assert not (tmp_path / "data").exists()


def test_ray_missing_is_refused_before_anything_is_written(
    tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 33 case 9: --executor ray without Ray wrote the out folder and dataset.json first."""
    import sys

    from davis_ag.cli import main

    monkeypatch.setitem(sys.modules, "ray", None)  # as where Ray is not installed
    out = tmp_path / "data"
    assert main(["generate", "--config", "mini", "--executor", "ray", "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--executor ray needs Ray" in err
    assert not out.exists()


def test_structures_are_a_config_key_recorded_per_group_and_a_changed_one_is_refused(tmp_path: Path) -> None:
    import json

    from davis_ag.generate.dataset_files import dataset_settings, reconcile_settings

    groups = "groups:\n  - {scenario: row, crop: vsp-vine, scenes: 1}\n  - {scenario: sp, crop: vsp-vine, scenes: 1}\n"
    default = parse_dataset_config(groups, "test")
    bare = parse_dataset_config("structures: none\n" + groups, "test")
    assert (default.structures, bare.structures) == ("default", "none")
    # A scene gets what it can have: single-plant scenes have nothing to build, and say none.
    assert [r.structures for r in default.requests()] == ["default", "none"]
    assert {r.structures for r in bare.requests()} == {"none"}
    structured, unstructured = (dataset_settings(c.requests())["groups"] for c in (default, bare))
    assert structured["Row-VSPVine"]["structures"] == "default"
    assert "structures" not in structured["Single-VSPVine"]  # as every group recorded before
    assert "structures" not in unstructured["Row-VSPVine"]
    with pytest.raises(UserError, match="structures"):
        parse_dataset_config("structures: trellis\n" + groups, "test")
    # A folder holding bare rows refuses structured ones (and says how to go on).
    root = tmp_path / "data"
    (root / "Row-VSPVine" / "000").mkdir(parents=True)
    (root / "Row-VSPVine" / "000" / "annotations.json").write_text("{}")
    (root / "dataset.json").write_text(json.dumps(dataset_settings(bare.requests())))
    with pytest.raises(UserError, match="made with structures none, not default: use --structures none"):
        reconcile_settings(root, dataset_settings(default.requests()))
    assert reconcile_settings(root, dataset_settings(bare.requests()))["groups"] == unstructured
