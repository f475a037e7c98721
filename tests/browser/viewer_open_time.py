"""How long the viewer of a 10,000-frame run of 50 objects takes to open in Chromium, and its size.

    python tests/browser/viewer_open_time.py [--model paper|exact] [--repeat 5]

Runs `paper_fifty_boxes` for 10,000 ticks with `--viewer` into a temporary folder, then opens
viewer.html REPEAT times in a fresh page of the system Chromium (Playwright, as the browser tests)
and prints the file's size and the median and largest time from the start of navigation until the
viewer has inflated its data and drawn its first frame (`body[data-ready]`), measured by the page's
own clock (`performance.now()`).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
from pathlib import Path

from playwright.sync_api import sync_playwright

from collide2d.runner.command import main as cli

ROOT = Path(__file__).resolve().parents[2]
CHROMIUM = "/usr/bin/chromium"


def main() -> int:
    ap = argparse.ArgumentParser()
    ap.add_argument("--model", default="paper")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        scenario = ROOT / "scenarios" / "paper_fifty_boxes.yaml"
        argv = ["run", str(scenario), "--ticks", "10000", "--model", args.model, "--out", tmp]
        argv += ["--viewer", "--no-gif", "--no-png", "--no-events", "--quiet"]
        if cli.main(argv) != 0:
            return 1
        page_path = Path(tmp) / "paper_fifty_boxes" / "viewer.html"
        times = []
        with sync_playwright() as p:
            browser = p.chromium.launch(executable_path=CHROMIUM)
            for _ in range(args.repeat):
                page = browser.new_page()
                page.add_init_script(
                    "new MutationObserver(function () {"
                    " if (document.body && document.body.dataset.ready && !window.__ready)"
                    " window.__ready = performance.now(); })"
                    ".observe(document, {attributes: true, subtree: true});"
                )
                page.goto(page_path.as_uri())
                page.wait_for_selector("body[data-ready='1']")
                times.append(page.evaluate("window.__ready"))
                page.close()
            browser.close()
        size = page_path.stat().st_size
    print(
        f"{args.model}: viewer.html {size / 1e6:.2f} MB; ready after median "
        f"{statistics.median(times):.0f} ms, max {max(times):.0f} ms over {len(times)} opens"
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
