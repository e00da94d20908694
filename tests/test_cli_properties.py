"""Property: whatever a user types, every command answers with exit status 0, 1 or 2, never a
traceback, one line on stderr when it refuses, and changes nothing outside its output folder.

Hypothesis draws each command's options from values a user might type (good, bad and odd) and
runs ``davis_ag.cli.main`` in this process. Commands that grow plants (generate, demo, reproduce,
preview) always get an unwritable --out last, so that however the other arguments fall, nothing
long starts; train and evaluate start from a few steps and episodes on a tiny dataset, so their
successful runs take a second.
"""

from __future__ import annotations

import itertools
import os
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st

from davis_ag import cli
from layout_factory import write_tiny_dataset

#: Values any option may get: numbers, signs, lists, names, paths of every kind.
ANY = st.sampled_from(
    [
        "0",
        "1",
        "2",
        "-1",
        "-5",
        "x",
        "",
        ",",
        " 3",
        "1.5",
        "²",
        "1e3",
        "99999999999",
        "4294967296",
        "1,2",
        "0,1",
        "640x360",
        "16x16",
        "0x0",
        "sp",
        "mp",
        "strawberry",
        "tomato",
        "vine",
        "banana",
        "LRD",
        "LRD,Oracle",
        "a2c",
        "Oracle,,UDD",
        "auto",
        "cpu",
        "nature",
        "pooled",
        "all",
        "train",
        "test",
        "mini",
        "paper",
        "/proc/x",
        "a-file",
        "a-file/sub",
        "data",
        "empty",
        "missing",
        "~nosuchuser/x",
        "../escape",
        "-",
    ]
)
#: Where the commands that grow plants write: nowhere they can.
UNWRITABLE = st.sampled_from(["/proc/x", "a-file", "a-file/sub", "data/Single-Strawberry/000/annotations.json/x"])
#: Renderer and look names, good and bad.
RENDER = st.sampled_from(["opengl", "helios", "default", "x", ""])
_counter = itertools.count()


@pytest.fixture(scope="module")
def world(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A working folder with a tiny dataset (caches built), an empty folder and a plain file."""
    from davis_ag.benchmark import TVMEnv

    root = tmp_path_factory.mktemp("world")
    write_tiny_dataset(root / "data", "sp", "strawberry", scenes=2)
    TVMEnv(root / "data", "sp", "all")  # the observation caches, so a run only reads them
    (root / "empty").mkdir()
    (root / "a-file").write_text("not a folder")
    return root


def snapshot(root: Path) -> dict[str, tuple[int, int]]:
    """Every path under ``root`` but the output folders, files with size and modification time.

    A folder's own modification time is left out: proving a folder writable creates and removes a
    temporary file in it, which changes nothing in it but that time.
    """
    found = {}
    for path in root.rglob("*"):
        rel = path.relative_to(root).as_posix()
        if not rel.startswith("out-"):
            stat = path.lstat()
            found[rel] = (stat.st_size, stat.st_mtime_ns) if path.is_file() else (0, 0)
    return found


def options(pools: dict[str, st.SearchStrategy[str]]) -> st.SearchStrategy[list[str]]:
    """A list of options, each with a value from its pool ('' pools are flags), in any order."""
    pairs = st.sampled_from(sorted(pools)).flatmap(
        lambda name: st.just([name]) if pools[name] is FLAG else pools[name].map(lambda v: [name, v])
    )
    return st.lists(pairs, max_size=5).map(lambda items: [token for item in items for token in item])


FLAG = st.just("")


def pools_for(command: str, out: str) -> tuple[list[str], dict[str, st.SearchStrategy[str]], list[str]]:
    """Arguments first given, option pools hypothesis draws from, and arguments forced last."""
    small = st.sampled_from(["0", "1", "2", "-1", "x", "99999999999"])
    out_or_bad = st.sampled_from([out, "/proc/x", "a-file/sub", "data"])
    cache = st.sampled_from([f"{out}/cache", "/proc/x", "a-file/sub", "a-file"])
    if command == "generate":
        return (
            [],
            {
                "--config": st.sampled_from(["mini", "paper", "nope", "a-file", "data"]),
                "--crop": ANY,
                "--scenario": ANY,
                "--scenes": ANY,
                "--first": ANY,
                "--seed": ANY,
                "--size": ANY,
                "--only": ANY,
                "--workers": ANY,
                "--executor": ANY,
                "--address": ANY,
                "--cpus-per-scene": ANY,
                "--max-retries": ANY,
                "--quiet": FLAG,
                "--renderer": RENDER,
                "--look": RENDER,
                "--antialiasing": ANY,
                "--no-depth": FLAG,
                "--strawberry-altitudes": st.sampled_from(["table1", "readme", "x"]),
            },
            ["--out"],
        )
    if command == "demo":
        return [], {"--scenes": ANY, "--size": ANY, "--seed": ANY, "--episodes": ANY, "--sessions": ANY}, ["--out"]
    if command == "reproduce":
        return (
            [],
            {
                "--results": st.sampled_from([f"{out}/r.md", "/proc/x/r.md", "data"]),
                "--config": ANY,
                "--sp-scenes": ANY,
                "--mp-scenes": ANY,
                "--sp-timesteps": ANY,
                "--mp-timesteps": ANY,
                "--only": ANY,
                "--learners": ANY,
            },
            ["--out"],
        )
    if command == "preview":
        return (
            [],
            {
                "--crop": ANY,
                "--scenario": ANY,
                "--seed": ANY,
                "--index": ANY,
                "--views": ANY,
                "--size": ANY,
                "--renderer": RENDER,
                "--look": RENDER,
                "--antialiasing": ANY,
            },
            ["--out"],
        )
    if command == "train":
        first = [
            "--dataset",
            "data",
            "--scenario",
            "sp",
            "--out",
            f"{out}/m.zip",
            "--timesteps",
            "8",
            "--n-envs",
            "2",
            "--arch",
            "pooled",
            "--verbose",
            "0",
            "--device",
            "cpu",
        ]
        return (
            first,
            {
                "--dataset": ANY,
                "--scenario": ANY,
                "--crop": ANY,
                "--timesteps": small,
                "--seed": ANY,
                "--n-envs": small,
                "--arch": ANY,
                "--device": ANY,
                "--cache-dir": cache,
                "--out": out_or_bad,
                "--verbose": ANY,
                "--robot": st.sampled_from(["ur7", "missing.yaml", "a-file"]),
                "--task": st.sampled_from(["tvm", "mapping", "x"]),
                "--budget": small,
                "--seen-fraction": st.sampled_from(["0.5", "0", "nan", "1.5", "x"]),
            },
            [],
        )
    if command == "evaluate":
        first = [
            "--dataset",
            "data",
            "--scenario",
            "sp",
            "--out",
            f"{out}/r.json",
            "--episodes",
            "2",
            "--sessions",
            "1",
        ]
        return (
            first,
            {
                "--dataset": ANY,
                "--scenario": ANY,
                "--crop": ANY,
                "--split": ANY,
                "--model": st.sampled_from(["missing.zip", "a-file", "data", f"{out}/none.zip"]),
                "--policy": st.sampled_from(
                    ["missing.zip", "a-file", "nope.py:act", "json:loads", "os:path", "a-file:x", "data"]
                ),
                "--name": ANY,
                "--policies": ANY,
                "--deterministic": FLAG,
                "--robot": st.sampled_from(["ur7", "missing.yaml", "a-file"]),
                "--env": st.sampled_from(["grid", "continuous", "x"]),
                "--task": st.sampled_from(["tvm", "mapping", "x"]),
                "--budget": small,
                "--seen-fraction": st.sampled_from(["0.5", "0", "nan", "1.5", "x"]),
                "--budget-s": st.sampled_from(["10", "0", "nan", "x"]),
                "--episodes": small,
                "--sessions": small,
                "--seed": ANY,
                "--cache-dir": cache,
                "--out": out_or_bad,
                "--plot": st.sampled_from([f"{out}/p.png", "/proc/x/p.png", "data", f"{out}/r.json"]),
            },
            [],
        )
    if command == "compare":
        return [], {"--out": st.sampled_from([f"{out}/b.md", "/proc/x/b.md", "data", "a-file/sub"])}, []
    if command == "validate":
        return [], {"--quick": FLAG, "--box-tolerance": ANY}, []
    if command == "stats":
        return (
            [],
            {"--out": st.sampled_from([f"{out}/s.json", "/proc/x/s.json", "data", "a-file/sub"]), "--no-oer": FLAG},
            [],
        )
    if command == "plot":
        return (
            [],
            {
                "--scene": ANY,
                "--results": st.sampled_from(["missing.json", "a-file", "data"]),
                "--policy": ANY,
                "--episode": ANY,
                "--start": ANY,
                "--actions": ANY,
                "--target": ANY,
                "--formats": st.sampled_from(["png", "png,svg", "gif", "", ","]),
                "--out": st.sampled_from([f"{out}/fig", "/proc/x/fig", "a-file/sub"]),
            },
            [],
        )
    if command == "view":  # a valid run serves until stopped: the folder given is never a dataset
        return [], {"--port": ANY, "--scene": ANY}, []
    if command == "export":
        return (
            [],
            {"--split": ANY, "--task": st.sampled_from(["detect", "segment", "x"]), "--appearance-shift": ANY},
            [],
        )
    if command == "bench":  # measures for minutes: the --out given last is never writable
        return (
            [],
            {
                "--crops": ANY,
                "--repeats": ANY,
                "--antialiasing": ANY,
                "--only": st.sampled_from(["all", "continuous", "x"]),
                "--doc": st.sampled_from(["missing", "a-file", "/proc/x"]),
            },
            ["--out"],
        )
    if command == "scene-stats":  # grows plants: no folder given is a docs folder, so it always refuses
        return (
            [],
            {
                "--count": ANY,
                "--size": ANY,
                "--crops": ANY,
                "--generators": ANY,
                "--step": ANY,
                "--docs": st.sampled_from(["data", "empty", "missing", "a-file", "/proc/x"]),
            },
            [],
        )
    if command == "transfer":  # trains detectors: the --out given last is never writable
        paths = st.sampled_from(["data", "empty", "missing", "a-file", "/proc/x"])
        return (
            [],
            {
                "--pretrain": paths,
                "--real": paths,
                "--real-images": paths,
                "--splits": small,
                "--train-size": small,
                "--test-size": small,
                "--seed": ANY,
                "--epochs": small,
                "--pretrain-epochs": small,
                "--imgsz": ANY,
                "--batch": small,
                "--device": ANY,
                "--workers": small,
                "--results": st.sampled_from([f"{out}/t.md", "/proc/x/t.md"]),
            },
            ["--out"],
        )
    if command == "robots":  # a robot that does not load: every built-in one would take seconds each
        return [], {"--doc": st.sampled_from(["missing.md", "a-file", "/proc/x"])}, []
    if command == "reach":  # solves every view: only robots that do not load, so it never starts
        robots = st.sampled_from(["ur7", "missing.yaml", "a-file", "data"])
        return (
            ["data", "--robot", "ur7", "--out", f"{out}/reach"],
            {
                "--robot": robots,
                "--out": out_or_bad,
                "--scenario": ANY,
                "--crop": ANY,
                "--cache-dir": cache,
                "--doc": st.sampled_from(["missing.md", "a-file", "/proc/x"]),
                "--force": FLAG,
            },
            [],
        )
    if command == "verify":
        return [], {"--keep": st.sampled_from([f"{out}/again", "/proc/x", "a-file", "a-file/sub", "data/again"])}, []
    raise AssertionError(command)


#: The commands the property drives; a new command must be added here (and to pools_for).
COVERED = (
    "generate",
    "demo",
    "reproduce",
    "preview",
    "train",
    "evaluate",
    "compare",
    "validate",
    "verify",
    "stats",
    "plot",
    "view",
    "export",
    "transfer",
    "bench",
    "scene-stats",
    "robots",
    "reach",
)


def test_every_command_is_covered() -> None:
    assert sorted(cli.COMMANDS) == sorted(COVERED), "add the new command's options to pools_for"


@pytest.mark.parametrize("command", COVERED)
@settings(
    max_examples=25,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_no_traceback_and_nothing_outside_the_output_changes(
    command: str, data: st.DataObject, world: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.chdir(world)
    out = f"out-{next(_counter)}"
    monkeypatch.setenv("XDG_CACHE_HOME", str(world / f"{out}-rescued"))  # where a rescued result would go
    first, pools, last = pools_for(command, out)
    argv = [command, *first, *data.draw(options(pools), label="options")]
    if command in ("validate", "stats"):
        argv.insert(
            1,
            data.draw(
                st.sampled_from(
                    [
                        "data",
                        "data/Single-Strawberry",
                        "empty",
                        "missing",
                        "a-file",
                        "/proc/x",
                        "data/Single-Strawberry/000",
                    ]
                ),
                label="dir",
            ),
        )
    elif command == "verify":
        argv[1:1] = data.draw(
            st.lists(
                st.sampled_from(["data/Single-Strawberry/000", "data/Single-Strawberry", "data", "missing", "a-file"]),
                min_size=1,
                max_size=2,
            ),
            label="scenes",
        )
    elif command == "robots":
        argv.insert(1, data.draw(st.sampled_from(["ur7", "missing.yaml", "a-file", "data"]), label="robot"))
    elif command == "plot":
        argv[1:1] = [
            data.draw(
                st.sampled_from(["visibility", "altitude", "oer", "actions", "episode", "phenotypes", "bogus"]),
                label="kind",
            ),
            data.draw(st.sampled_from(["data", "empty", "missing", "a-file"]), label="dir"),
        ]
    elif command == "compare":
        argv[1:1] = data.draw(
            st.lists(st.sampled_from(["missing.json", "a-file", "data", "empty", "/proc/x"]), min_size=1, max_size=2),
            label="results",
        )
    elif command == "view":
        argv.insert(1, data.draw(st.sampled_from(["empty", "missing", "a-file", "/proc/x"]), label="dir"))
    elif command == "export":
        argv[1:1] = [
            data.draw(st.sampled_from(["coco", "yolo", "bogus"]), label="format"),
            data.draw(st.sampled_from(["data", "data/Single-Strawberry", "empty", "missing", "a-file"]), label="dir"),
            data.draw(st.sampled_from([f"{out}/export", "/proc/x", "a-file", "data", "a-file/sub"]), label="out"),
        ]
    if last:
        argv += [*last, data.draw(UNWRITABLE, label="unwritable out")]
    before = snapshot(world)
    try:
        code = cli.main(argv)
    except SystemExit as exit_:  # argparse: a bad value (2) or --help (0)
        code = int(exit_.code or 0)
    printed, err = capsys.readouterr()
    event(f"exit {code}")  # --hypothesis-show-statistics shows how often each outcome came up
    assert "Traceback" not in printed + err, argv
    assert code in (0, 1, 2), (argv, code, err)
    if code == 2:
        lines = [line for line in err.splitlines() if line.strip()]
        assert len(lines) == 1 and lines[0].startswith("davis-ag"), (argv, err)
    if last:
        assert code == 2, (argv, printed, err)  # nothing can be written, so nothing may have run
    assert snapshot(world) == before, argv
    assert os.getcwd() == str(world)


def test_an_unknown_command_is_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    with pytest.raises(SystemExit) as exit_:
        cli.main(["bogus"])
    assert exit_.value.code == 2 and len(capsys.readouterr().err.strip().splitlines()) == 1
