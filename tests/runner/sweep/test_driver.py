"""Sweeps on a real (in-process) Dask cluster: every row's figures are the run's own, rows come
out in parameter order whatever the worker count, the position error is measured against the
exact run of the same seed, and Ctrl-C keeps the rows finished so far, marked incomplete."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np
import pytest

from collide2d.runner.output.progress import Progress
from collide2d.runner.run import drive
from collide2d.runner.sweep import driver, plan, results
from collide2d.runner.sweep.driver import batch_size
from collide2d.runner.sweep.matrix import parse_set
from collide2d.runner.sweep.worker import mark_outside, run_batch, run_one

from .planned import expand

distributed = pytest.importorskip("distributed")

SCENARIOS = Path(__file__).resolve().parents[3] / "scenarios"
FIFTY = str(SCENARIOS / "paper_fifty_boxes.yaml")
AXES = [parse_set("model=paper,exact"), parse_set("ticks=60")]
SEEDS = (3, 1, 2)


def _without_wall_time(text: str) -> str:
    return "\n".join(line.rsplit(",", 1)[0] for line in text.splitlines())


@pytest.fixture(scope="module")
def checked():
    return plan.check([FIFTY], AXES, tuple(sorted(SEEDS)))


@pytest.fixture(scope="module")
def runs():
    return expand([FIFTY], AXES, tuple(sorted(SEEDS)))


def _csv(table) -> str:
    buf = io.StringIO()
    results.write_csv(buf, table.plan.columns, table.rows())
    return buf.getvalue()


def test_rows_hold_each_runs_own_figures(client, checked, runs):
    table, complete = driver.run_sweep(client, checked)
    assert complete and table.done == 6
    rows = list(table.rows())
    assert [(r["seed"], r["model"]) for r in rows] == [
        (s, m) for s in ("1", "2", "3") for m in ("exact", "paper")
    ]
    positions = {}
    for run, row in zip(runs, rows, strict=True):
        model, summary = drive(run.scenario)
        assert row["status"] == "ok", row["note"]
        assert (row["wall_events"], row["pair_events"]) == (
            summary["events"]["wall"],
            summary["events"]["pair"],
        )
        assert row["objects"] == 50 and row["left_world"] == 0
        positions[run.params["seed"], run.params["model"]] = model.positions()
    for exact, paper in zip(rows[::2], rows[1::2], strict=True):
        # the exact model keeps energy; it is its own reference; paper is measured against it
        assert abs(exact["energy_drift"]) < 1e-12 and exact["position_error_px"] == 0.0
        assert exact["worst_overlap_px"] < 1e-9 and paper["worst_overlap_px"] >= 0.0
        ref = positions[exact["seed"], "exact"]
        mine = positions[paper["seed"], "paper"]
        want = float(np.mean(np.hypot(*(mine - ref).T)))
        assert paper["position_error_px"] == pytest.approx(want, rel=1e-12)
        assert paper["position_error_px"] > 1.0


def test_the_table_is_the_same_bytes_on_one_worker_or_two(client, checked, tmp_path):
    two = _csv(driver.run_sweep(client, checked)[0])
    with (
        distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, processes=False, dashboard_address=":0"
        ) as one_cluster,
        distributed.Client(one_cluster) as one,
    ):
        one_text = _csv(driver.run_sweep(one, checked)[0])
    assert _without_wall_time(one_text) == _without_wall_time(two)
    assert one_text.splitlines()[0].endswith(",note,run_time_s")
    assert len(one_text.splitlines()) == 7


def test_ctrl_c_keeps_the_finished_rows_marked_incomplete(client, checked, tmp_path):
    seen = []

    def interrupt(run, row):
        seen.append(run.index)
        if len(seen) == 2:
            raise KeyboardInterrupt

    table, complete = driver.run_sweep(client, checked, on_row=interrupt)
    assert not complete
    assert table.done == 2 and len(seen) == 2
    assert sorted(r.index for r in checked.runs() if table.row(r) is not None) == sorted(seen)
    (tmp_path / "sweep").mkdir()
    written = results.write(tmp_path / "sweep", table, False)
    assert "results.csv" in written
    status = json.loads((tmp_path / "sweep" / "sweep.json").read_text())
    assert status == {"runs": 6, "done": 2, "complete": False}
    rows = list(csv.DictReader(io.StringIO((tmp_path / "sweep" / "results.csv").read_text())))
    assert len(rows) == 2
    assert (
        "**Incomplete**: cancelled with 2 of 6 runs done"
        in (tmp_path / "sweep" / "results.md").read_text()
    )


def test_ctrl_c_before_any_run_is_sent_is_a_cancelled_sweep_of_no_rows(checked, tmp_path):
    class Busy:  # a cluster asked for its threads when Ctrl-C comes
        def nthreads(self):
            raise KeyboardInterrupt

    table, complete = driver.run_sweep(Busy(), checked)
    assert not complete and table.done == 0
    (tmp_path / "sweep").mkdir()
    results.write(tmp_path / "sweep", table, False)
    status = json.loads((tmp_path / "sweep" / "sweep.json").read_text())
    assert status == {"runs": 6, "done": 0, "complete": False}


def test_a_run_the_model_stops_is_a_row_with_its_message():
    runaway = expand([FIFTY], [parse_set("model=exact"), parse_set("ticks=5")], None)[0]
    figures, pos = run_one(runaway.scenario)
    assert figures["status"] == "ok" and pos.shape == (50, 2)
    from collide2d.runner.scenario.load import loads

    jam = loads(
        "version: 1\nworld: {width: 20, height: 20, fps: 10}\n"
        "model: {kind: exact, max_events_per_tick: 5}\nticks: 3\n"
        "objects:\n"
        "  - {shape: box, size: [10, 10], position: [0, 0], velocity: [10, 0]}\n"
        "  - {shape: box, size: [10, 10], position: [10, 0], velocity: [-10, 0]}\n"
    )
    figures, pos = run_one(jam)
    assert figures["status"] == "stopped" and pos is None
    assert "max_events_per_tick" in figures["note"] or "events" in figures["note"]


def test_boxes_out_of_the_world_are_marked_once_each():
    pos = np.array([[0.0, 0.0], [-0.5, 3.0], [15.0, 15.0], [5.0, 11.0]])
    size = np.full((4, 2), 10.0)
    left = np.zeros(4, np.bool_)
    mark_outside(pos, size, 20.0, 20.0, 1e-9, left)
    assert left.tolist() == [False, True, True, True]
    mark_outside(np.zeros((4, 2)), size, 20.0, 20.0, 1e-9, left)
    assert left.tolist() == [False, True, True, True]


def test_progress_counts_runs_and_gives_an_eta():
    bar = Progress(200, "sweep", io.StringIO(), unit=" runs")
    bar.update(50)
    shown = str(bar.bar)  # the line tqdm draws: done/total, time so far<time left, rate
    bar.close()
    assert shown.startswith("sweep:") and "50/200" in shown and "runs/s" in shown
    assert "<" in shown  # an estimate of the time left


def test_runs_in_batches_give_the_same_rows(client, checked):
    assert [batch_size(n, t) for n, t in ((200, 2), (8, 2), (6, 2), (10**6, 4))] == [13, 1, 1, 32]
    one, _ = driver.run_sweep(client, checked, batch=1)
    four, complete = driver.run_sweep(client, checked, batch=4)
    assert complete and four.done == 6
    strip = [{k: v for k, v in r.items() if k != "run_time_s"} for r in one.rows()]
    assert strip == [{k: v for k, v in r.items() if k != "run_time_s"} for r in four.rows()]


def test_a_run_that_raises_is_an_error_row_and_its_batch_goes_on(runs):
    done = run_batch([(runs[0].scenario, None), (None, None), (runs[1].scenario, None)])
    assert [row["status"] for row, _pos in done] == ["ok", "error", "ok"]
    assert done[1][0]["note"].startswith("AttributeError: ") and done[1][1] is None
