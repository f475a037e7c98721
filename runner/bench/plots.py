"""The plots of `collide2d bench`, when matplotlib is installed (the `plot` extra): scaling.png
(steps/s against N, per model and peer), gravity_runtime_vs_error.png (the gravity part's
closed forms: run time against error of the stepped model and pymunk at each rate) and
runtime_vs_error.png, the Pareto chart: one panel per
benchmark scenario, run time against the error at the long horizon, every point labelled with its
settings ("60" fps, "60x16" fps x substeps), min-max bars on the run time, the Pareto front drawn
as a step line through its points, and the scene's own floor (the sensitivity row) as a dotted
line. Errors below ERROR_FLOOR_PX (float rounding) are drawn on the floor's line.
"""

from __future__ import annotations

import math
from pathlib import Path


def plots(rows: list[dict], folder: Path) -> list[str]:
    """scaling.png, runtime_vs_error.png and gravity_runtime_vs_error.png (of the rows there
    are) when matplotlib is installed; the names written."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib import ticker
    except ImportError:
        return []
    from collide2d.runner.output.files import atomic_path

    written = []
    scale = [r for r in rows if r["part"] in ("scaling", "peers")]
    if scale:
        fig, ax = plt.subplots(figsize=(6, 4))
        for name in dict.fromkeys(r["model"] for r in scale):
            pts = sorted((r["n"], r["steps_per_s"]) for r in scale if r["model"] == name)
            ax.plot(*zip(*pts, strict=True), marker="o", label=name)
        ax.set(xscale="log", yscale="log", xlabel="N boxes", ylabel="steps/s")
        ax.set_title("standard scene")
        ax.legend()
        fig.tight_layout()
        with atomic_path(folder / "scaling.png") as tmp:
            fig.savefig(tmp, format="png")
        plt.close(fig)
        written.append("scaling.png")
    err = [r for r in rows if r["part"] == "error"]
    if err:
        sens = [r for r in rows if r["part"] == "sensitivity"]
        _pareto_figure(plt, ticker, err, sens, folder, atomic_path)
        written.append("runtime_vs_error.png")
    closed = [r for r in rows if r["part"] == "gravity" and r.get("fps")]
    if closed:
        _gravity_figure(plt, closed, folder, atomic_path)
        written.append("gravity_runtime_vs_error.png")
    return written


# Errors below this are drawn at it (a bounce instant exact to round-off has an error of 0).
GRAVITY_ERROR_FLOOR = 1e-16
GRAVITY_PANELS = {"bounce": "error of the first 3 bounce instants (s)",
                  "slide": "relative error of the slide distance"}  # fmt: skip


def _gravity_figure(plt, closed, folder, atomic_path) -> None:
    """gravity_runtime_vs_error.png: the gravity part's closed-form scenes, one panel each, run
    time against error of each model at each rate (labelled with its fps, or fps x substeps)."""
    fig, axes = plt.subplots(1, len(GRAVITY_PANELS), figsize=(6 * len(GRAVITY_PANELS), 4.5))
    for ax, (scene, ylabel) in zip(axes, GRAVITY_PANELS.items(), strict=True):
        mine = [r for r in closed if r["scene"] == scene]
        for name in dict.fromkeys(_gravity_series(r) for r in mine):
            pts = sorted(
                (r["run_time_s"], max(r["value"], GRAVITY_ERROR_FLOOR), _gravity_label(r))
                for r in mine
                if _gravity_series(r) == name and math.isfinite(r["value"])  # inf: not found
            )
            colour = MODEL_COLOURS.get(name, "tab:purple" if name == "pymunk" else "tab:cyan")
            ax.plot([p[0] for p in pts], [p[1] for p in pts], marker="o", ms=4, label=name,
                    color=colour)  # fmt: skip
            for x, y, text in pts:
                ax.annotate(text, (x, y), textcoords="offset points", xytext=(3, 3),
                            fontsize=6, color=colour)  # fmt: skip
        ax.set(xscale="log", yscale="log", title=scene, ylabel=ylabel)
        ax.set_xlabel("run time of 2 simulated seconds (s)")
        ax.legend(fontsize="x-small", loc="best")
    fig.suptitle(
        "Under gravity: run time against error of the closed forms (labels: fps, or fps x substeps)"
    )
    fig.tight_layout()
    with atomic_path(folder / "gravity_runtime_vs_error.png") as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)


MODEL_COLOURS = {"paper": "tab:orange", "stepped": "tab:blue", "exact": "tab:green"}


def _gravity_series(r) -> str:
    """A gravity row's line in the chart: its model, or the stepped model's ladder of substeps."""
    return r["model"] if r.get("substeps", 1) == 1 else f"{r['model']}, substeps at {r['fps']} fps"


def _gravity_label(r) -> str:
    """A gravity row's point label: its fps, or fps x substeps."""
    k = r.get("substeps", 1)
    return f"{r['fps']}x{k}" if k > 1 else str(r["fps"])


def _label(r) -> str:
    """A point's settings: its own label (a sweep's swept values), else fps or fps x substeps."""
    if "label" in r:
        return r["label"]
    return f"{r['fps']}x{r['substeps']}" if r["substeps"] > 1 else f"{r['fps']}"


def _pareto_figure(plt, ticker, err, sens, folder, atomic_path) -> None:
    from collide2d.runner.bench.error import ERROR_FLOOR_PX

    scenes = list(dict.fromkeys(r["scene"] for r in err))
    cols = 2 if len(scenes) > 1 else 1
    nrows = math.ceil(len(scenes) / cols)
    fig, axes = plt.subplots(nrows, cols, figsize=(7 * cols, 5.5 * nrows), squeeze=False)
    long_s = err[0].get("long_s")  # None: each point at its own run's end (a sweep)
    for ax, scene in zip(axes.ravel(), scenes, strict=False):
        mine = [r for r in err if r["scene"] == scene]
        for name in dict.fromkeys(r["model"] for r in mine):
            pts = [r for r in mine if r["model"] == name]
            x = [r["run_time_s"] for r in pts]
            y = [max(r["error_long_px"], ERROR_FLOOR_PX) for r in pts]
            lo = [r["run_time_s"] - r.get("run_time_min_s", r["run_time_s"]) for r in pts]
            hi = [r.get("run_time_max_s", r["run_time_s"]) - r["run_time_s"] for r in pts]
            ax.errorbar(x, y, xerr=[lo, hi], fmt="o", ms=4, capsize=2, label=name,
                        color=MODEL_COLOURS.get(name))  # fmt: skip
            for r, xi, yi in zip(pts, x, y, strict=True):
                ax.annotate(_label(r), (xi, yi), textcoords="offset points", xytext=(3, 3),
                            fontsize=6, color=MODEL_COLOURS.get(name))  # fmt: skip
        front = sorted(
            (r["run_time_s"], max(r["error_long_px"], ERROR_FLOOR_PX))
            for r in mine
            if r.get("pareto") == "yes"
        )
        if front:
            ax.step(*zip(*front, strict=True), where="post", color="black", linewidth=1.0,
                    label="Pareto front")  # fmt: skip
        ax.axhline(ERROR_FLOOR_PX, color="grey", linewidth=0.6, linestyle=":")
        for r in sens:
            if r["scene"] == scene:
                ax.axhline(max(r["error_long_px"], ERROR_FLOOR_PX), color="red", linewidth=0.8,
                           linestyle=":", label="exact, velocities nudged 1e-9 px/s")  # fmt: skip
        ys = [max(r["error_long_px"], ERROR_FLOOR_PX) for r in mine]
        if max(ys) == min(ys) and not any(r["scene"] == scene for r in sens):
            # every point at one error (say all at the floor): a decade either side, not
            # matplotlib's warning about a range of zero height
            ax.set_ylim(ys[0] / 10, ys[0] * 10)
        ax.set(xscale="log", yscale="log", title=scene)
        span = f"{long_s:g} s" if long_s is not None else "the run's end"
        ax.set_xlabel(f"run time to {span} of simulation (s)")
        ax.set_ylabel(f"mean position error at {span} vs exact (px)")
        ax.yaxis.set_major_locator(ticker.LogLocator(numticks=12))
        ax.legend(fontsize="x-small", loc="best")
    for ax in axes.ravel()[len(scenes) :]:
        ax.axis("off")
    fig.suptitle("Run time against error (labels: fps, or fps x substeps; floor: 1e-9 px)")
    fig.tight_layout()
    with atomic_path(folder / "runtime_vs_error.png") as tmp:
        fig.savefig(tmp, format="png", dpi=110)
    plt.close(fig)
