"""The docs' pictures, made on every build by running the project's own scenarios.

`paper_figures` runs Figure 2's four cases and the 1 fps / 10 fps tunnelling scenes of
`scenarios/` with `collide2d run` and lays the frames the explanation talks about side by side,
cropped to where the boxes are and enlarged; `tutorial_pictures` walks the tutorial in a
temporary folder (`collide2d init`, `run`, `bless`, an edit, `check --report`) and keeps its GIF
and the report's expected / actual / diff frames. Every picture is PNG or GIF bytes, handed to
MkDocs by docgen/hooks.py; nothing is written into docs/.
"""

from __future__ import annotations

import io
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import yaml
from PIL import Image, ImageChops

ROOT = Path(__file__).resolve().parents[1]
GAP = 4  # px between the frames of a strip, in the page's grey
GREY = (96, 96, 96)

# Frames the explanation shows: Figure 2's cases before, at and after the flip (frame 1 shows the
# paper's overlap drawn by the scenario's `overlap` overlay); tunnelling around the crossing.
FIG2_FRAMES = (0, 1, 2)
TUNNEL_FRAMES = {"tunnelling_1fps": (4, 5, 6, 7), "tunnelling_10fps": (49, 50, 51, 52, 53)}


def collide2d(*args, cwd: Path, check: bool = True) -> subprocess.CompletedProcess:
    """`collide2d ARGS` in `cwd`, as a user runs it (CI unset, so that a tutorial can bless)."""
    env = {k: v for k, v in os.environ.items() if k != "CI"}
    proc = subprocess.run(
        [sys.executable, "-m", "collide2d", *map(str, args)],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
    )
    if check and proc.returncode != 0:
        raise RuntimeError(f"collide2d {' '.join(map(str, args))}: {proc.stderr}")
    return proc


def every_frame(scenario: Path, work: Path) -> dict[int, Image.Image]:
    """Every frame of `scenario` as an RGB image, by tick (a copy asks for `frames: all`)."""
    text = yaml.safe_load(scenario.read_text(encoding="utf-8"))
    text.setdefault("name", scenario.stem)
    text.setdefault("output", {})["frames"] = "all"
    copy = work / scenario.name
    copy.write_text(yaml.safe_dump(text), encoding="utf-8")
    out = work / "out"
    collide2d("run", copy, "--out", out, "--png", "--no-gif", "--no-events", "--quiet", cwd=work)
    frames = {}
    for png in sorted((out / text["name"] / "frames").glob("frame_*.png")):
        with Image.open(png) as image:
            frames[int(png.stem.split("_")[1])] = image.convert("RGB")
    return frames


def _ink(frames: list[Image.Image], margin: int) -> tuple[int, int, int, int]:
    """The box around every pixel that is not the background (the top-left pixel's colour)."""
    left, top, right, bottom = None, None, 0, 0
    for frame in frames:
        background = Image.new("RGB", frame.size, frame.getpixel((0, 0)))
        box = ImageChops.difference(frame, background).getbbox()
        if box is None:
            continue
        left = box[0] if left is None else min(left, box[0])
        top = box[1] if top is None else min(top, box[1])
        right, bottom = max(right, box[2]), max(bottom, box[3])
    width, height = frames[0].size
    if left is None:
        return 0, 0, width, height
    return (
        max(0, left - margin),
        max(0, top - margin),
        min(width, right + margin),
        min(height, bottom + margin),
    )


def strip(rows: list[list[Image.Image]], scale: int) -> Image.Image:
    """Rows of equal-sized images, enlarged `scale` times (nearest neighbour), GAP apart."""
    cell_w, cell_h = rows[0][0].size
    cols = max(len(r) for r in rows)
    width = cols * cell_w * scale + (cols - 1) * GAP
    height = len(rows) * cell_h * scale + (len(rows) - 1) * GAP
    sheet = Image.new("RGB", (width, height), GREY)
    for r, row in enumerate(rows):
        for c, image in enumerate(row):
            big = image.resize((cell_w * scale, cell_h * scale), Image.NEAREST)
            sheet.paste(big, (c * (cell_w * scale + GAP), r * (cell_h * scale + GAP)))
    return sheet


def png(image: Image.Image) -> bytes:
    buffer = io.BytesIO()
    image.save(buffer, format="PNG", optimize=True)
    return buffer.getvalue()


def paper_figures() -> dict[str, bytes]:
    """`explanation/fig2.png` (a row per case) and `explanation/tunnelling.png` (1 fps, 10 fps)."""
    pictures = {}
    with tempfile.TemporaryDirectory() as tmp:
        work = Path(tmp)
        cases = [every_frame(ROOT / "scenarios" / f"fig2_case{k}.yaml", work) for k in range(1, 5)]
        rows = []
        for frames in cases:
            chosen = [frames[t] for t in FIG2_FRAMES]
            box = _ink(chosen, 8)
            rows.append([f.crop(box) for f in chosen])
        size = (max(r[0].size[0] for r in rows), max(r[0].size[1] for r in rows))
        rows = [[_pad(f, size) for f in row] for row in rows]
        pictures["explanation/fig2.png"] = png(strip(rows, 6))

        tunnels = {n: every_frame(ROOT / "scenarios" / f"{n}.yaml", work) for n in TUNNEL_FRAMES}
        chosen = [[tunnels[n][t] for t in ticks] for n, ticks in TUNNEL_FRAMES.items()]
        box = _ink([f for row in chosen for f in row], 6)
        rows = [[f.crop(box) for f in row] for row in chosen]
        pictures["explanation/tunnelling.png"] = png(strip(rows, 4))
    return pictures


def _pad(image: Image.Image, size: tuple[int, int]) -> Image.Image:
    """`image` centred on a canvas of `size` in its background colour."""
    canvas = Image.new("RGB", size, image.getpixel((0, 0)))
    canvas.paste(image, ((size[0] - image.size[0]) // 2, (size[1] - image.size[1]) // 2))
    return canvas


# The edit the tutorial makes to its scenario (the crate's velocity), as its page shows it.
TUTORIAL_EDIT = ("velocity: [20, 10]", "velocity: [24, 10]")


def tutorial_pictures() -> dict[str, bytes]:
    """`tutorial/example.gif` (the example, 3x) and `tutorial/diff.png` (a failing frame's
    expected, actual and diff pictures from the report of a check after the tutorial's edit)."""
    pictures = {}
    with tempfile.TemporaryDirectory() as tmp:
        project = Path(tmp)
        collide2d("init", cwd=project)
        collide2d("run", "scenarios/example.yaml", "--scale", "3", "--quiet", cwd=project)
        gif = project / "out" / "example" / "animation.gif"
        pictures["tutorial/example.gif"] = gif.read_bytes()
        collide2d("bless", cwd=project)
        scenario = project / "scenarios" / "example.yaml"
        text = scenario.read_text(encoding="utf-8")
        assert TUTORIAL_EDIT[0] in text, "the tutorial's edit no longer applies to the example"
        scenario.write_text(text.replace(*TUTORIAL_EDIT), encoding="utf-8")
        proc = collide2d("check", "--report", cwd=project, check=False)
        assert proc.returncode == 1, proc.stdout + proc.stderr
        folder = project / "report" / "example"
        last = sorted(folder.glob("frame_*_diff.png"))[-1].name.split("_diff")[0]
        row = []
        for kind in ("expected", "actual", "diff"):
            with Image.open(folder / f"{last}_{kind}.png") as image:
                row.append(image.convert("RGB"))
        pictures["tutorial/diff.png"] = png(strip([row], 3))
    return pictures
