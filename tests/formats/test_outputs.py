"""The output rule (issue 33 cases 1, 5 and 7): nothing written inside a dataset, nothing replaced
without --force, one run per output, temporaries of a killed run cleaned by the next."""

from __future__ import annotations

import hashlib
import subprocess
import sys
from pathlib import Path

import pytest

from davis_ag import cli
from davis_ag.errors import UserError
from davis_ag.formats.outputs import (
    LOCK_FILE,
    claim_output,
    dataset_holding,
    file_lock_path,
)
from layout_factory import write_tiny_dataset


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    """``davis-ag ARGV`` in this process: exit status, stdout, stderr (never a traceback)."""
    try:
        code = cli.main(list(argv))
    except SystemExit as exit_:
        code = int(exit_.code or 0)
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def one_line(capsys: pytest.CaptureFixture[str], *argv: str, status: int = 2) -> str:
    code, out, err = run(capsys, *argv)
    assert code == status and len(err.splitlines()) == 1, (code, out, err)
    return err.strip()


def digest(root: Path) -> str:
    """One hash over every file of a folder, names and bytes (a dataset left exactly as it was)."""
    sha = hashlib.sha256()
    for path in sorted(p for p in root.rglob("*") if p.is_file()):
        sha.update(str(path.relative_to(root)).encode() + path.read_bytes())
    return sha.hexdigest()


@pytest.fixture()
def data(tmp_path: Path) -> Path:
    return write_tiny_dataset(tmp_path / "DATA", "sp", "strawberry", scenes=2, size=(64, 48))


def test_the_dataset_and_its_scenes_are_recognised(data: Path, tmp_path: Path) -> None:
    scene = data / "Single-Strawberry" / "000"
    assert dataset_holding(scene / "annotations.json") == scene
    assert dataset_holding(scene / "images" / "0001_seg.png") == scene
    assert dataset_holding(data / "splits.json") == data
    assert dataset_holding(data / "results" / "r.json") == data
    assert dataset_holding(tmp_path / "results" / "r.json") is None
    # Through a folder not made yet and back up: the file system cannot follow `new/..` while `new`
    # is missing, but the folders a command makes would put the output in the dataset.
    assert dataset_holding(data.parent / "new" / ".." / data.name / "results" / "r.json") == data
    (tmp_path / "link").symlink_to(data)  # and through a link to it
    assert dataset_holding(tmp_path / "link" / "results" / "r.json") is not None


@pytest.mark.parametrize(
    "where",
    [
        ("Single-Strawberry/000/annotations.json", "--out"),
        ("splits.json", "--out"),
        ("Single-Strawberry/000/images/0001_seg.png", "--plot"),
    ],
)
def test_evaluate_never_writes_into_a_dataset(
    where: tuple[str, str], data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Case 1: evaluate --out DATA/.../annotations.json replaced a scene's labels with results."""
    before = digest(data)
    path, flag = where
    target = str(data / path)
    argv = [
        "evaluate",
        "--dataset",
        str(data),
        "--scenario",
        "sp",
        "--episodes",
        "2",
        "--sessions",
        "1",
        "--policies",
        "LRD",
        "--out",
        target if flag == "--out" else str(tmp_path / "r.json"),
    ]
    if flag == "--plot":
        argv += ["--plot", target]
    line = one_line(capsys, *argv)
    assert f"{flag} {target} lies in" in line and "only davis-ag generate writes there" in line
    assert digest(data) == before


def test_an_existing_result_is_replaced_only_with_force(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Case 5: a second evaluate to an existing --out replaced the earlier results without a word."""
    out = tmp_path / "r.json"
    argv = [
        "evaluate",
        "--dataset",
        str(data),
        "--scenario",
        "sp",
        "--episodes",
        "2",
        "--sessions",
        "1",
        "--policies",
        "LRD",
        "--out",
        str(out),
    ]
    assert run(capsys, *argv)[0] == 0
    first = out.read_bytes()
    (tmp_path / ".r.png.tmp").write_bytes(b"")  # case 7: what a killed run leaves
    line = one_line(capsys, *argv, "--seed", "7")
    assert f"--out {out} already exists: give --force" in line
    assert out.read_bytes() == first and not (tmp_path / ".r.png.tmp").exists()
    assert run(capsys, *argv, "--seed", "7", "--force")[0] == 0 and out.read_bytes() != first
    assert not list(tmp_path.glob(".*"))  # no lock, no temporary left behind


def test_a_second_run_on_one_output_is_refused(tmp_path: Path, data: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """Case 5: two train or export runs on one output raced on one temporary file."""
    model, export = tmp_path / "m.zip", tmp_path / "coco"
    export.mkdir()
    holder = subprocess.Popen(
        [
            sys.executable,
            "-c",
            (
                "import sys, time\n"
                "from pathlib import Path\n"
                "from davis_ag.formats.outputs import claim_output\n"
                f"with claim_output(Path({str(model)!r})), claim_output(Path({str(export)!r}), folder=True):\n"
                "    print('claimed', flush=True); time.sleep(3600)\n"  # killed below
            ),
        ],
        stdout=subprocess.PIPE,
        text=True,
    )
    try:
        assert holder.stdout.readline().strip() == "claimed"
        line = one_line(
            capsys,
            "train",
            "--dataset",
            str(data),
            "--scenario",
            "sp",
            "--timesteps",
            "8",
            "--n-envs",
            "2",
            "--arch",
            "pooled",
            "--device",
            "cpu",
            "--out",
            str(model),
        )
        assert f"{model} is being written by another davis-ag run (PID {holder.pid})" in line
        line = one_line(capsys, "export", "coco", str(data), str(export))
        assert f"{export} is being written by another davis-ag run (PID {holder.pid})" in line
    finally:
        holder.kill()
        holder.wait()
    assert not model.exists() and sorted(p.name for p in export.iterdir()) == [LOCK_FILE]
    with claim_output(model) as claimed:  # the kernel dropped the dead holder's lock
        assert claimed == model and file_lock_path(model).exists()
    assert not file_lock_path(model).exists()


def test_a_claim_refuses_before_creating_anything(data: Path, tmp_path: Path) -> None:
    with pytest.raises(UserError, match="which is a scene folder"):
        with claim_output(data / "Single-Strawberry" / "001" / "model.zip"):
            pass
    (tmp_path / "old.json").write_text("mine")
    with pytest.raises(UserError, match="already exists"):
        with claim_output(tmp_path / "old.json"):
            pass
    assert (tmp_path / "old.json").read_text() == "mine"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["DATA", "old.json"]


def test_every_command_that_writes_keeps_the_rule(
    data: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """stats, plot, compare, reproduce and transfer wrote over splits.json, a scene's
    annotations.json, their own inputs or a run's state.json without a word."""
    before = digest(data)
    splits, annotations = data / "splits.json", data / "Single-Strawberry" / "000" / "annotations.json"
    for argv, flag, target in [
        (["stats", "--no-oer", str(data), "--out", str(splits)], "--out", splits),
        (["stats", "--no-oer", str(data), "--out", str(annotations)], "--out", annotations),
        (["plot", "visibility", str(data), "--out", str(data / "splits")], "--out", data / "splits.png"),
        (
            ["transfer", "--real", str(tmp_path / "r.yaml"), "--pretrain", str(data), "--out", str(data / "tf")],
            "--out",
            data / "tf",
        ),
    ]:
        line = one_line(capsys, *argv)
        assert f"{flag} {target} lies in" in line and "only davis-ag generate writes there" in line, line
    assert digest(data) == before

    stats = tmp_path / "stats.json"
    assert run(capsys, "stats", "--no-oer", str(data), "--out", str(stats))[0] == 0
    assert "--out" in one_line(capsys, "stats", "--no-oer", str(data), "--out", str(stats))
    assert run(capsys, "stats", "--no-oer", str(data), "--out", str(stats), "--force")[0] == 0

    results = tmp_path / "r.json"
    evaluate = ["evaluate", "--dataset", str(data), "--scenario", "sp", "--episodes", "2", "--sessions", "1"]
    assert run(capsys, *evaluate, "--policies", "LRD", "--out", str(results))[0] == 0
    kept = results.read_bytes()
    # An output that is an input, however spelt, is refused even with --force.
    elsewhere = f"{tmp_path}/not-made-yet/../r.json"
    for argv in (
        ["compare", str(results), "--out", str(results)],
        ["compare", str(results), "--out", elsewhere, "--force"],
        [*evaluate, "--policies", "LRD", "--policy", str(results), "--out", str(results), "--force"],
    ):
        line = one_line(capsys, *argv)
        assert "which this run reads" in line, line
    line = one_line(capsys, "plot", "actions", "--results", str(results), "--out", str(tmp_path / "r"), "--force")
    assert f"--out {tmp_path / 'r.json'} is --results {results}, which this run reads" in line
    line = one_line(capsys, *evaluate, "--out", str(tmp_path / "e.png"), "--plot", f"{tmp_path}/x/../e.png")
    assert "name the same file" in line and not (tmp_path / "e.png").exists()
    assert "--plot" in one_line(capsys, *evaluate, "--out", str(tmp_path / "e.json"), "--plot", str(tmp_path / "c.txt"))
    assert not (tmp_path / "e.json").exists()
    page = tmp_path / "board.md"
    assert run(capsys, "compare", str(results), "--out", str(page))[0] == 0
    assert "already exists: give --force" in one_line(capsys, "compare", str(results), "--out", str(page))
    assert results.read_bytes() == kept

    run_dir = tmp_path / "run"
    run_dir.mkdir()
    (run_dir / "state.json").write_text('{"config": {}}')
    line = one_line(
        capsys, "reproduce", "--out", str(run_dir), "--rewrite-results", "--results", str(run_dir / "state.json")
    )
    assert "would replace the run's own records" in line and (run_dir / "state.json").read_text() == '{"config": {}}'
    (tmp_path / "runlink").symlink_to(run_dir)
    for spelt in (f"{run_dir}/x/../state.json", str(tmp_path / "runlink" / "state.json")):
        line = one_line(capsys, "reproduce", "--out", str(run_dir), "--rewrite-results", "--results", spelt)
        assert "would replace the run's own records" in line, spelt
    assert (run_dir / "state.json").read_text() == '{"config": {}}'
    line = one_line(capsys, "reproduce", "--out", str(run_dir), "--results", str(splits))
    assert "--results" in line and "only davis-ag generate writes there" in line


@pytest.mark.parametrize("text", ["[1, 2]", "{not json", '{"config": "small"}', '{"config": {"a": 1}}'])
def test_a_damaged_state_file_is_named_not_taken_for_no_run(
    text: str, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A run that read a damaged state.json as "no run yet" would start its records afresh over it."""
    (tmp_path / "state.json").write_text(text)
    for extra in (["--status"], ["--rewrite-results", "--results", str(tmp_path.parent / "page.md")]):
        line = one_line(capsys, "reproduce", "--out", str(tmp_path), *extra)
        assert f"{tmp_path / 'state.json'}:" in line and ("damaged" in line or "not a reproduce state" in line), line
    assert (tmp_path / "state.json").read_text() == text
