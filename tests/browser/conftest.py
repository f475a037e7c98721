"""Browser tests: the report page and the run viewer in a real Chromium, driven by Playwright.

Playwright drives the system's Chromium (Debian's `chromium` package, which `.ci/run` installs),
never a browser of its own download: `browser_type_launch_args` points Playwright at it, and every
test here is skipped, saying why, when no such binary exists. `clean_page` is Playwright's `page`
at a device scale of 1 (a CSS pixel is a screen pixel, so screenshots compare with PNG frames) that
fails the test on any console error or uncaught exception. With `COLLIDE2D_SCREENSHOTS=DIR` set,
tests save the docs' screenshots (docs/report.png, docs/viewer.png) into DIR
(`COLLIDE2D_SCREENSHOTS=docs pytest tests/browser`).
"""

from __future__ import annotations

import io
import os
import shutil
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

CHROMIUM_CANDIDATES = ("/usr/bin/chromium", "/usr/bin/chromium-browser")


def chromium_binary() -> str | None:
    """The system Chromium (or the one COLLIDE2D_CHROMIUM names), or None."""
    if "COLLIDE2D_CHROMIUM" in os.environ:
        path = os.environ["COLLIDE2D_CHROMIUM"]
        return path if os.access(path, os.X_OK) else None
    for path in CHROMIUM_CANDIDATES:
        if os.access(path, os.X_OK):
            return path
    found = shutil.which("chromium")
    return found


@pytest.fixture(scope="session")
def browser_type_launch_args(browser_type_launch_args):
    path = chromium_binary()
    if path is None:
        pytest.skip(
            "no Chromium binary (looked for COLLIDE2D_CHROMIUM, /usr/bin/chromium and chromium "
            "on PATH); "
            "install Debian's package: apt-get install -y chromium"
        )
    return {**browser_type_launch_args, "executable_path": path}


@pytest.fixture(scope="session")
def base_url():
    """No base URL: every page here is opened by its file URI. Defined here so that the plugin's
    own `base_url` is never set up: pytest-playwright 0.10 defines it as a session-scoped
    fixture on an instance, which pytest 9 warns of and pytest 10 refuses."""
    return None


@pytest.fixture
def browser_context_args(browser_context_args):
    return {
        **browser_context_args,
        "device_scale_factor": 1,
        "viewport": {"width": 1200, "height": 900},
    }


@pytest.fixture
def clean_page(page):
    """Playwright's page; the test fails on any console error or page error."""
    errors = []
    page.on("console", lambda msg: errors.append(msg.text) if msg.type == "error" else None)
    page.on("pageerror", lambda exc: errors.append(f"uncaught: {exc}"))
    yield page
    assert errors == [], f"console errors: {errors}"


def shot(locator) -> np.ndarray:
    """(H, W, 3) uint8 RGB screenshot of an element."""
    return np.array(Image.open(io.BytesIO(locator.screenshot())).convert("RGB"))


def save_screenshot(target, name: str, **options) -> None:
    """Save a docs screenshot of a page or locator (`screenshot(**options)`) when
    COLLIDE2D_SCREENSHOTS names a folder; a small PNG of at most 64 colours."""
    folder = os.environ.get("COLLIDE2D_SCREENSHOTS")
    if not folder:
        return
    im = Image.open(io.BytesIO(target.screenshot(**options))).convert("RGB")
    im = im.quantize(colors=64, dither=Image.Dither.NONE)
    Path(folder).mkdir(parents=True, exist_ok=True)
    im.save(Path(folder) / name, optimize=True)
