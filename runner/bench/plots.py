"""The plots of `collide2d bench`, when matplotlib is installed (the `plot` extra): scaling.png
(steps/s against N, per model and peer) and runtime_vs_error.png (one panel per benchmark scenario,
the Pareto front drawn as a step line).
"""

from __future__ import annotations

import math
from pathlib import Path


def plots(rows: list[dict], folder: Path) -> list[str]:
    """scaling.png and runtime_vs_error.png when matplotlib is installed; the names written."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        from matplotlib import ticker
    except ImportError:
        return []
    from collide2d.runner.outputs import atomic_path

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
        scenes = list(dict.fromkeys(r["scene"] for r in err))
        cols = 2
        rows_ = math.ceil(len(scenes) / cols)
        fig, axes = plt.subplots(rows_, cols, figsize=(10, 4 * rows_), squeeze=False)
        for ax, scene in zip(axes.ravel(), scenes, strict=False):
            mine = [r for r in err if r["scene"] == scene]
            for name in dict.fromkeys(r["model"] for r in mine):
                pts = [r for r in mine if r["model"] == name]
                ax.scatter(
                    [1e3 * r["run_time_s"] for r in pts],
                    [r["position_error_px"] + 1e-3 for r in pts],
                    label=name,
                )
            front = sorted(
                (1e3 * r["run_time_s"], r["position_error_px"] + 1e-3)
                for r in mine
                if r["pareto"] == "yes"
            )
            if front:
                ax.step(*zip(*front, strict=True), where="post", color="grey", linewidth=0.8)
            ax.set(xscale="log", yscale="log", xlabel="run time (ms)")
            for axis in (ax.xaxis, ax.yaxis):
                axis.set_major_formatter(ticker.FormatStrFormatter("%g"))
                axis.set_minor_formatter(ticker.NullFormatter())
            ax.set(ylabel="position error at the horizon (px, +0.001)", title=scene)
            ax.legend(fontsize="small")
        for ax in axes.ravel()[len(scenes) :]:
            ax.axis("off")
        fig.tight_layout()
        with atomic_path(folder / "runtime_vs_error.png") as tmp:
            fig.savefig(tmp, format="png")
        plt.close(fig)
        written.append("runtime_vs_error.png")
    return written
