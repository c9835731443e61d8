"""Open an HTML report in headless Chromium and list everything that did not load.

Used by the tests (and by anyone who wants to check a report): drives Debian's
``chromium`` through ``chromedriver`` with Selenium, with an explicit driver path so
Selenium never tries to download a browser or driver. Checks:

* every ``<img>`` finished loading with ``naturalWidth > 0`` (a broken or blocked image has 0);
* every inline ``<svg>`` has a non-zero rendered size;
* no browser console message of level SEVERE (this includes Content-Security-Policy
  violations, i.e. any attempt to load a network resource);
* no failed request (DevTools ``Network.loadingFailed``, HTTP status >= 400) and no request
  for anything but the report itself and ``data:`` URLs.

Needs the optional test dependency ``selenium`` and the Debian packages ``chromium`` and
``chromium-driver`` (listed in ``.ci/apt-packages``).
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from robobore.errors import RoboboreError

CHROMIUM = os.environ.get("ROBOBORE_CHROMIUM", "/usr/bin/chromium")
CHROMEDRIVER = os.environ.get("ROBOBORE_CHROMEDRIVER", "/usr/bin/chromedriver")

#: Flags that work as root in a container without a display or GPU.
CHROMIUM_FLAGS = (
    "--headless", "--no-sandbox", "--disable-gpu", "--disable-quic", "--no-first-run",
    "--disable-background-networking", "--disable-component-update", "--disable-sync",
    "--disable-dev-shm-usage", "--window-size=1280,900",
)


class BrowserUnavailable(RoboboreError):
    """Chromium, chromedriver or selenium is not installed."""


@dataclass(frozen=True)
class BrowserCheck:
    """What the browser saw: counts and the list of problems (empty = all loaded)."""

    url: str
    title: str
    images: int
    svgs: int
    problems: tuple[str, ...] = field(default_factory=tuple)
    console: tuple[dict[str, Any], ...] = field(default_factory=tuple)

    @property
    def ok(self) -> bool:
        return not self.problems


def browser_available() -> str | None:
    """``None`` when the browser check can run, else the reason it cannot."""
    for p in (CHROMIUM, CHROMEDRIVER):
        if not Path(p).exists():
            return f"{p} not found (Debian packages chromium and chromium-driver)"
    try:
        import selenium  # noqa: F401
    except ImportError:
        return "python package selenium is not installed (test dependency)"
    return None


_JS_IMAGES = """
return Array.from(document.images).map(i => [i.complete, i.naturalWidth, i.naturalHeight,
    (i.alt || '').slice(0, 60), (i.getAttribute('src') || '').slice(0, 40)]);
"""
_JS_SVGS = """
return Array.from(document.querySelectorAll('svg')).filter(s => !s.parentElement.closest('svg'))
    .map(s => { const r = s.getBoundingClientRect(); return [r.width, r.height,
    s.getAttribute('aria-label') || '']; });
"""


def check_html_in_browser(path: str | Path, timeout_s: float = 60.0) -> BrowserCheck:
    """Open ``path`` in headless Chromium and return what failed to load (see module doc)."""
    return check_html_files_in_browser([path], timeout_s)[0]


def check_html_files_in_browser(paths: list[str | Path], timeout_s: float = 60.0
                                ) -> list[BrowserCheck]:
    """Like :func:`check_html_in_browser` for several files, one browser for all."""
    why = browser_available()
    if why:
        raise BrowserUnavailable(why)
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    files = [Path(p).resolve() for p in paths]
    for p in files:
        if not p.is_file():
            raise RoboboreError(f"report not found: {p}")
    profile = tempfile.mkdtemp(prefix="robobore-chromium-")
    opts = webdriver.ChromeOptions()
    opts.binary_location = CHROMIUM
    for f in CHROMIUM_FLAGS:
        opts.add_argument(f)
    opts.add_argument(f"--user-data-dir={profile}")
    opts.set_capability("goog:loggingPrefs", {"browser": "ALL", "performance": "ALL"})
    driver = None
    try:
        driver = webdriver.Chrome(service=Service(executable_path=CHROMEDRIVER), options=opts)
        driver.set_page_load_timeout(timeout_s)
        driver.set_script_timeout(timeout_s)
        return [_check_page(driver, p.as_uri(), timeout_s) for p in files]
    finally:
        if driver is not None:
            driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


def _check_page(driver: Any, url: str, timeout_s: float) -> BrowserCheck:
    from selenium.webdriver.support.ui import WebDriverWait

    driver.get_log("performance")  # drop earlier events (browser start-up, previous page)
    driver.get_log("browser")
    driver.get(url)
    WebDriverWait(driver, timeout_s).until(
        lambda d: d.execute_script("return document.readyState") == "complete")
    # images decode asynchronously: wait until every one reports complete
    WebDriverWait(driver, timeout_s).until(
        lambda d: all(c for c, *_ in d.execute_script(_JS_IMAGES)))
    images = driver.execute_script(_JS_IMAGES)
    svgs = driver.execute_script(_JS_SVGS)
    title = driver.title
    console = driver.get_log("browser")
    perf = driver.get_log("performance")

    problems: list[str] = []
    for i, (complete, w, h, alt, src) in enumerate(images):
        if not complete or not w or not h:
            problems.append(f"image {i + 1} ({alt or src!r}) did not load "
                            f"(naturalWidth={w}, naturalHeight={h})")
    for i, (w, h, label) in enumerate(svgs):
        if not w or not h:
            problems.append(f"inline svg {i + 1} ({label!r}) has no size ({w} x {h})")
    for e in console:
        if e.get("level") == "SEVERE":
            problems.append(f"console error: {e.get('message', '')[:300]}")
    # DevTools network events of the report's page only: requests whose document is the
    # report (the browser's own start-up pages are not the report's business)
    events = []
    for e in perf:
        try:
            events.append(json.loads(e["message"])["message"])
        except (KeyError, ValueError, TypeError):
            continue
    ours: set[str] = set()
    for msg in events:
        if msg.get("method") == "Network.requestWillBeSent":
            prm = msg.get("params", {})
            u = prm.get("request", {}).get("url", "")
            if prm.get("documentURL", "").split("#")[0] == url or u.split("#")[0] == url:
                ours.add(prm.get("requestId"))
                if not (u.startswith("data:") or u.split("#")[0] == url):
                    problems.append(f"request for something outside the report: {u[:200]}")
    for msg in events:
        method, prm = msg.get("method", ""), msg.get("params", {})
        if prm.get("requestId") not in ours:
            continue
        if method == "Network.loadingFailed":
            problems.append(f"request failed: {prm.get('errorText')} "
                            f"{prm.get('blockedReason') or ''}".strip())
        elif method == "Network.responseReceived":
            st = prm.get("response", {}).get("status", 200)
            if isinstance(st, int | float) and st >= 400:
                problems.append(f"HTTP {st} for {prm.get('response', {}).get('url', '')[:200]}")
    return BrowserCheck(url=url, title=title, images=len(images), svgs=len(svgs),
                        problems=tuple(problems), console=tuple(console))


__all__ = ["BrowserCheck", "BrowserUnavailable", "browser_available", "check_html_in_browser",
           "check_html_files_in_browser", "CHROMIUM_FLAGS"]
