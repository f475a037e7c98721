"""Bad input and hard stops (docs/limits.md#reading-yaml-safely): the safe loader, bounded aliases,
sizes refused before anything is allocated, names that cannot leave the output folder, nothing
written on a refusal, whole files after a killed run, runaways as clear errors, and the same bytes
in another process."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import imageio.v3 as iio
import pytest
from PIL import Image

from collide2d.runner.command.main import main
from collide2d.runner.scenario.load import ScenarioError, load

ROOT = Path(__file__).resolve().parents[2]
DATA = Path(__file__).parent / "data"
# A refusal must cost little: well under a second and a few MB, whatever the file asks for.
REFUSAL_SECONDS = 1.0
REFUSAL_PEAK_BYTES = 8 * 2**20

GOOD = """version: 1
name: {name}
world: {{width: 120, height: 90, fps: 10}}
model: {model}
ticks: {ticks}
objects:
  - {{shape: box, size: 10, position: [10, 10], velocity: [20, 10], color: red}}
  - {{shape: circle, diameter: 8, position: [60, 40], velocity: [-10, 20], color: lime}}
generate:
  - {{count: 12, shape: box, size: 4, speed: 10, seed: 3, color: white}}
output: {{frames: {frames}, gif: true, events: true}}
"""


def scenario(tmp_path: Path, name="hard", model="paper", ticks=20, frames="all", file=None) -> Path:
    """A small scenario file (14 objects) named `name`, written as FILE.yaml (default NAME.yaml)."""
    path = tmp_path / f"{file or name}.yaml"
    path.write_text(GOOD.format(name=name, model=model, ticks=ticks, frames=frames))
    return path


def tree(folder: Path) -> dict[str, bytes | str]:
    """Every entry under folder: files by their bytes, links by their target."""
    out: dict[str, bytes | str] = {}
    for p in sorted(folder.rglob("*")):
        rel = str(p.relative_to(folder))
        if p.is_symlink():
            out[rel] = "-> " + os.readlink(p)
        elif p.is_file():
            out[rel] = p.read_bytes()
        else:
            out[rel] = "dir"
    return out


def refuse_cheaply(argv) -> tuple[int, float, int]:
    """(exit status, seconds, peak bytes allocated) of main(argv), measured on a second call: the
    first pays once per process for loading the compiled kernels, whatever the input."""
    argv = [str(a) for a in argv]
    main(argv)
    tracemalloc.start()
    began = time.perf_counter()
    try:
        status = main(argv)
    finally:
        seconds = time.perf_counter() - began
        peak = tracemalloc.get_traced_memory()[1]
        tracemalloc.stop()
    return status, seconds, peak


def cli(*argv, env=None, timeout=120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "collide2d", *map(str, argv)],
        capture_output=True,
        text=True,
        timeout=timeout,
        cwd=ROOT,
        env=env,
    )


# ----------------------------------------------------------------------------- the safe loader


@pytest.mark.parametrize(
    "value",
    [
        "!!python/object/apply:os.system ['touch {marker}']",
        "!!python/object/new:os.system ['touch {marker}']",
        "!!python/name:os.system",
        "[1, !!python/tuple [1, 2]]",
        "{{a: !!python/object/apply:subprocess.call [['touch', '{marker}']]}}",
    ],
)
def test_python_tags_are_refused_and_never_run(tmp_path, capsys, value):
    marker = tmp_path / "PWNED"
    path = tmp_path / "tag.yaml"
    path.write_text("version: 1\ndescription: " + value.format(marker=marker) + "\n")
    assert main(["run", str(path), "--out", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{path}:2:") and "is not allowed" in err
    assert not marker.exists() and not (tmp_path / "out").exists()


def test_billion_laughs_is_refused_in_well_under_a_second_with_little_memory(capsys):
    status, seconds, peak = refuse_cheaply(["validate", DATA / "billion_laughs.yaml"])
    assert status == 2
    assert seconds < REFUSAL_SECONDS and peak < REFUSAL_PEAK_BYTES
    assert "aliases repeat more than" in capsys.readouterr().err


# ----------------------------------------------------------------------------- sizes first


@pytest.mark.parametrize(
    ("body", "extra", "fragment"),
    [
        ("generate: [{count: 1000000000, shape: box, size: 1}]", [], "past the limit of"),
        (
            "generate: [{count: 1000000000, shape: box, size: 1}]",
            ["--max-objects", "2000000000"],
            "area is more than the world's",
        ),
        ("ticks: 1000000000000", [], "past the limit of 1000000000 ticks"),
        # past int64 too: the limit a user can raise is named, not the largest integer
        ("ticks: 99999999999999999999999", [], "past the limit of 1000000000 ticks; raise it"),
        (
            "ticks: 100000000\noutput: {frames: {every: 1}}",
            [],
            "past the limit of 1,000,000 frames",
        ),
        ("ticks: 100000000\noutput: {frames: all, gif: false}", [], "frames"),
        # a billion ticks: the GIF's frames, and PNG frames of a scenario that names none
        ("ticks: 1000000000", [], "1,000,000,001 GIF frames, past the limit of 1,000,000"),
        ("ticks: 1000000000", ["--no-gif", "--png"], "1,000,000,001 PNG frames, past the limit"),
        (
            "world: {width: 1, height: 1}\nticks: 1000000000",
            ["--max-frames", "2000000000"],
            "on disk, past the output limit of 4,294,967,296 bytes",
        ),
        (
            "world: {width: 1, height: 1}\nticks: 1000000000",
            ["--no-gif", "--png", "--max-frames", "2000000000"],
            "on disk, past the output limit",
        ),
        # a frame too large for memory: 16384 x 16384 x 3^2 x 3 bytes
        (
            "world: {width: 16384, height: 16384}\nticks: 10",
            ["--scale", "3", "--no-gif", "--png"],
            "takes 7,247,757,312 bytes in memory, past the limit of 1,073,741,824",
        ),
        ("world: {width: 100000000000}", [], "past the limit of 16384 px"),
    ],
)
def test_sizes_are_refused_at_once_with_little_memory(tmp_path, capsys, body, extra, fragment):
    path = tmp_path / "big.yaml"
    path.write_text("version: 1\n" + body + "\n")
    out = tmp_path / "out"
    status, seconds, peak = refuse_cheaply(["run", path, "--out", out, "--quiet", *extra])
    err = capsys.readouterr().err
    assert status == 2, err
    assert fragment in err and err.startswith(f"{path}:")
    assert seconds < REFUSAL_SECONDS and peak < REFUSAL_PEAK_BYTES, (seconds, peak)
    assert not out.exists()


@pytest.mark.skipif(not Path("/dev/zero").exists(), reason="needs /dev/zero")
def test_an_endless_file_is_refused_before_it_is_read(capsys):
    """Found by hardening: `validate /dev/zero` read until memory ran out; a device is not a
    regular file, so it is refused before a byte is read."""
    status, seconds, peak = refuse_cheaply(["validate", "/dev/zero", "--max-file-bytes", "100000"])
    assert status == 2 and seconds < REFUSAL_SECONDS and peak < REFUSAL_PEAK_BYTES
    err = capsys.readouterr().err
    assert err.startswith("/dev/zero:1:1: error: cannot read the file: it is a character device")
    assert main(["validate", "/dev/zero"]) == 2  # whatever the limit
    assert "not a regular file" in capsys.readouterr().err


def test_yaml_values_are_counted_before_any_is_built(tmp_path, capsys):
    path = tmp_path / "many.yaml"
    path.write_text("version: 1\ndescription: [" + "1, " * 5000 + "1]\n")
    status, seconds, peak = refuse_cheaply(["validate", path, "--max-yaml-nodes", "1000"])
    assert status == 2 and seconds < REFUSAL_SECONDS and peak < REFUSAL_PEAK_BYTES
    err = capsys.readouterr().err
    assert err.startswith(f"{path}:2:") and "more than 1,000 YAML values" in err
    assert main(["validate", str(path)]) == 2  # within the default bound: refused for its type
    assert "description must be a single value" in capsys.readouterr().err


def test_a_gif_too_wide_for_the_format_is_refused_before_anything_is_written(tmp_path, capsys):
    """Found by hardening: a 16384 px world at --scale 5 reached the GIF writer and crashed."""
    path = tmp_path / "wide.yaml"
    path.write_text("version: 1\nworld: {width: 16384, height: 10}\nticks: 0\n")
    out = tmp_path / "out"
    assert main(["run", str(path), "--out", str(out), "--scale", "5", "--gif"]) == 2
    err = capsys.readouterr().err
    assert "a GIF is at most 65535 px a side" in err and "Traceback" not in err
    assert not out.exists()
    assert main(["run", str(path), "--out", str(out), "--scale", "5", "--no-gif", "--quiet"]) == 0


# ----------------------------------------------------------------------------- names and paths


@pytest.mark.parametrize(
    "name", ["../evil", "/tmp/evil", "..", ".", ".hidden", "a/b", "a\\\\b", "EVIL", "é"]
)
def test_scenario_names_cannot_reach_out_of_the_output_folder(tmp_path, capsys, name):
    base = tmp_path / "base"
    base.mkdir()
    path = base / "named.yaml"
    path.write_text(f'version: 1\nname: "{name}"\n')
    out = base / "out"
    before = tree(tmp_path)
    assert main(["run", str(path), "--out", str(out), "--quiet"]) == 2
    assert "is not a valid scenario name" in capsys.readouterr().err
    assert tree(tmp_path) == before


@pytest.mark.parametrize("stem", [".hidden", "..", "UPPER", "sp ace"])
def test_a_file_stem_that_is_no_name_is_refused(tmp_path, capsys, stem):
    path = tmp_path / f"{stem}.yaml"
    path.write_text("version: 1\n")
    assert main(["validate", str(path)]) == 2
    assert "cannot be the scenario's name" in capsys.readouterr().err


@pytest.mark.parametrize("link", ["hard", "hard/frames"])
def test_a_linked_output_folder_is_refused_and_its_target_untouched(tmp_path, capsys, link):
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "keep.txt").write_text("mine")
    out = tmp_path / "out"
    (out / link).parent.mkdir(parents=True)
    (out / link).symlink_to(outside, target_is_directory=True)
    path = scenario(tmp_path)
    before = tree(tmp_path)
    assert main(["run", str(path), "--out", str(out), "--png", "--quiet"]) == 2
    assert "symbolic link" in capsys.readouterr().err
    assert tree(tmp_path) == before


@pytest.mark.parametrize("under", ["", "/deeper"])
def test_an_output_folder_that_is_a_link_to_nothing_is_named_with_where_it_points(
    tmp_path, capsys, under
):
    link = tmp_path / "outlink"
    link.symlink_to(tmp_path / "nowhere", target_is_directory=True)
    path = scenario(tmp_path)
    before = tree(tmp_path)
    assert main(["run", str(path), "--out", str(link) + under, "--quiet"]) == 2
    err = capsys.readouterr().err
    assert f"{link}: a symbolic link to {tmp_path / 'nowhere'}, which does not exist" in err
    assert tree(tmp_path) == before


def test_a_linked_output_file_is_refused_not_followed(tmp_path, capsys):
    outside = tmp_path / "outside.csv"
    outside.write_text("not yours\n")
    folder = tmp_path / "out" / "hard"
    folder.mkdir(parents=True)
    (folder / "final.csv").symlink_to(outside)
    (folder / "summary.json").symlink_to(tmp_path / "missing.json")
    path = scenario(tmp_path)
    before = tree(tmp_path)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    assert "final.csv is a symbolic link" in capsys.readouterr().err
    assert tree(tmp_path) == before
    assert not (tmp_path / "missing.json").exists()


def test_files_a_run_does_not_write_are_never_replaced(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", str(scenario(tmp_path)), "--out", str(out), "--png", "--quiet"]) == 0
    (out / "hard" / "notes.txt").write_text("mine")
    (out / "hard" / "frames" / "sketch.png").write_bytes(b"mine too")
    before = tree(tmp_path)
    assert main(["run", str(scenario(tmp_path)), "--out", str(out), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert "holds files a run does not write (frames/sketch.png, notes.txt)" in err
    assert tree(tmp_path) == before


# ----------------------------------------------------------------------------- nothing written


REFUSED = {
    "yaml": "version: 1\nworld: {width: 10\n",
    "overlap": "version: 1\nobjects:\n  - {shape: box, size: 10, position: [0, 0]}\n"
    "  - {shape: box, size: 10, position: [5, 5]}\n",
    "paper_velocity": "version: 1\nobjects:\n  - {shape: box, size: 10, position: [0, 0], "
    "velocity: [0.1234567, 0]}\n",
    "limit": "version: 1\nticks: 2000000000\n",
    "output_bytes": "version: 1\nworld: {width: 16384, height: 16384}\nticks: 100\n",
}


@pytest.mark.parametrize("kind", sorted(REFUSED))
def test_a_refused_scenario_changes_nothing_in_an_existing_output_folder(tmp_path, capsys, kind):
    out = tmp_path / "out"
    assert main(["run", str(scenario(tmp_path)), "--out", str(out), "--png", "--quiet"]) == 0
    stray = out / "hard" / ".final.csv.999.0123abcd.tmp"  # as a killed run leaves it
    stray.write_text("half")
    bad = tmp_path / "hard.yaml"  # the same name: it would write into the same folder
    bad.write_text(REFUSED[kind])
    before = tree(tmp_path / "out")
    assert main(["run", str(bad), "--out", str(out), "--png", "--quiet"]) == 2
    assert capsys.readouterr().err.startswith(f"{bad}:")
    assert tree(tmp_path / "out") == before


# ----------------------------------------------------------------------------- runaways


@pytest.mark.parametrize(("model", "fragment"), [("stepped", "use substeps"), ("exact", "events")])
def test_a_runaway_is_a_clear_error_not_a_traceback(tmp_path, capsys, model, fragment):
    path = tmp_path / "runaway.yaml"
    path.write_text(
        f"version: 1\nworld: {{width: 40, height: 40, fps: 1}}\nmodel: {model}\nticks: 3\n"
        "objects:\n  - {shape: box, size: 10, position: [15, 15], velocity: [1000000000, 0]}\n"
    )
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--quiet"]) == 2
    err = capsys.readouterr().err
    assert err.startswith(f"{path}: error: the {model} model stopped the run in tick 1: ")
    assert fragment in err and "Traceback" not in err


def test_an_output_folder_that_is_a_file_is_a_clear_error(tmp_path, capsys):
    blocker = tmp_path / "out"
    blocker.write_text("a file")
    assert main(["run", str(scenario(tmp_path)), "--out", str(blocker), "--quiet"]) == 2
    assert capsys.readouterr().err.startswith(f"collide2d: error: {blocker}: ")
    assert blocker.read_text() == "a file"


# ----------------------------------------------------------------------------- killed mid-write


def whole_outputs(folder: Path, n_objects: int) -> dict[str, int]:
    """Check every output under folder is whole; returns how many frames each kind holds."""
    seen = {}
    for png in sorted((folder / "frames").glob("frame_*.png")):
        with Image.open(png) as im:
            im.load()  # a truncated PNG raises here
            assert im.size == (120, 90)
    seen["png"] = len(list((folder / "frames").glob("frame_*.png")))
    if (folder / "animation.gif").exists():
        seen["gif"] = iio.imread(folder / "animation.gif", index=None).shape[0]
    if (folder / "events.jsonl").exists():
        lines = (folder / "events.jsonl").read_text().splitlines()
        seen["events"] = len([json.loads(line) for line in lines])
    rows = (folder / "final.csv").read_text().splitlines()
    assert rows[0] == "id,x,y,vx,vy" and len(rows) == n_objects + 1
    assert all(len(r.split(",")) == 5 for r in rows)
    seen["ticks"] = json.loads((folder / "summary.json").read_text())["ticks"]
    return seen


def test_a_killed_run_leaves_the_old_run_whole_and_the_next_run_cleans_up(tmp_path):
    out = tmp_path / "out"
    folder = out / "hard"
    short = scenario(tmp_path, ticks=30, file="short")
    assert main(["run", str(short), "--out", str(out), "--png", "--quiet"]) == 0
    old = whole_outputs(folder, 14)
    assert old == {"png": 31, "gif": 31, "events": old["events"], "ticks": 30}
    old_bytes = tree(folder)
    old_files = comparable(folder)

    long = scenario(tmp_path, ticks=20000, file="long")
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "collide2d",
            "run",
            str(long),
            "--out",
            str(out),
            "--png",
            "--quiet",
        ],
        cwd=ROOT,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.DEVNULL,
    )
    try:
        deadline = time.monotonic() + 60
        while not list(out.glob(".hard.*.run.tmp/frames/frame_000200.png")):
            assert proc.poll() is None, "the run ended before it could be killed"
            assert time.monotonic() < deadline
            time.sleep(0.005)
    finally:
        proc.send_signal(signal.SIGKILL)
        proc.wait()
    assert proc.returncode == -signal.SIGKILL

    assert tree(folder) == old_bytes  # the old run, whole, and nothing of the new one
    (stage,) = out.glob(".hard.*.run.tmp")  # the killed run's files, apart
    assert len(list((stage / "frames").glob("frame_*.png"))) > 200

    assert main(["run", str(short), "--out", str(out), "--png", "--quiet"]) == 0
    assert sorted(p.name for p in out.iterdir()) == ["hard"]  # no staging folder, no lock
    assert comparable(folder) == old_files  # the same run again: the same files, and no others


# ----------------------------------------------------------------------------- other processes


def comparable(folder: Path) -> dict[str, bytes]:
    """The folder's files, the summary without how the run went (its time, and the lane and
    compile time: a run after one in the same process may go on compiled, docs/outputs.md)."""
    files = tree(folder)
    summary = json.loads(files.pop("summary.json"))
    assert summary.pop("run_time_s") >= 0
    assert summary.pop("kernels").startswith(("interpreted", "compiled"))
    assert summary.pop("compile_time_s") >= 0
    files["summary.json"] = json.dumps(summary, sort_keys=True).encode()
    return files


@pytest.mark.parametrize("model", ["exact", "stepped"])
def test_the_same_bytes_in_processes_with_other_hash_seeds(tmp_path, model):
    path = scenario(tmp_path, name="seeded", model=model, ticks=40, frames="{every: 8}")
    results = []
    for seed in ("0", "4242"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        out = tmp_path / f"out{seed}"
        proc = cli("run", path, "--out", out, "--png", "--quiet", env=env)
        assert proc.returncode == 0, proc.stderr
        results.append(comparable(out / "seeded"))
    assert results[0].keys() == results[1].keys()
    assert {"animation.gif", "events.jsonl", "final.csv", "frames/frame_000040.png"} <= set(
        results[0]
    )
    for name in results[0]:
        assert results[0][name] == results[1][name], name
    assert load(path).model == model


def test_loader_errors_are_the_same_in_another_process(tmp_path):
    path = tmp_path / "bad.yaml"
    path.write_text("version: 1\nworld: {widht: 10}\n")
    with pytest.raises(ScenarioError) as info:
        load(path)
    for seed in ("1", "77"):
        proc = cli("validate", path, env={**os.environ, "PYTHONHASHSEED": seed})
        assert proc.returncode == 2
        assert proc.stderr.strip() == str(info.value)
