"""report.html in headless Chromium: every figure renders, no console errors, the full comparison table.

Chromium and chromedriver are required (Debian packages ``chromium`` and
``chromium-driver``, installed by .ci/run).  When they are missing these
tests FAIL with a message saying so: a report nobody checked in a browser
is not done.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path

import pytest

from test_report import built_report

CHROMIUM_CANDIDATES = ("/usr/bin/chromium", "chromium", "chromium-browser")
CHROMEDRIVER_CANDIDATES = ("/usr/bin/chromedriver", "chromedriver")
FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-dev-shm-usage",
    "--window-size=1280,1024",
)


def _find(candidates: tuple[str, ...]) -> str | None:
    for name in candidates:
        path = shutil.which(name)
        if path:
            return path
    return None


@pytest.fixture(scope="module")
def report(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return built_report(tmp_path_factory)


@pytest.fixture(scope="module")
def browser():
    chromium, driver_path = _find(CHROMIUM_CANDIDATES), _find(CHROMEDRIVER_CANDIDATES)
    if chromium is None or driver_path is None:
        missing = [n for n, p in (("chromium", chromium), ("chromedriver", driver_path)) if p is None]
        pytest.fail(
            f"headless Chromium is required to check report.html, but {' and '.join(missing)} is not installed: "
            "install the Debian packages chromium and chromium-driver (.ci/run does)",
            pytrace=False,
        )
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    profile = tempfile.mkdtemp(prefix="stickslip-chromium-")
    options = webdriver.ChromeOptions()
    options.binary_location = chromium
    for flag in FLAGS:
        options.add_argument(flag)
    options.add_argument(f"--user-data-dir={profile}")
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    driver = webdriver.Chrome(service=Service(driver_path), options=options)
    try:
        yield driver
    finally:
        driver.quit()
        shutil.rmtree(profile, ignore_errors=True)


@pytest.fixture(scope="module")
def page(report: Path, browser):
    """report.html loaded over file://, with the browser log of the load."""
    from selenium.webdriver.support.ui import WebDriverWait

    browser.get((report / "report.html").resolve().as_uri())
    WebDriverWait(browser, 30).until(
        lambda d: d.execute_script(
            "return document.readyState === 'complete' && Array.from(document.images).every(i => i.complete)"
        )
    )
    return browser, browser.get_log("browser")


def _results(report: Path) -> dict:
    return json.loads((report / "results.json").read_text(encoding="utf-8"))


def test_no_console_errors(page) -> None:
    _, log = page
    severe = [entry for entry in log if entry.get("level") == "SEVERE"]
    assert not severe, f"browser console errors: {severe}"


def test_every_figure_renders_with_nonzero_size(page, report: Path) -> None:
    driver, _ = page
    images = driver.execute_script(
        "return Array.from(document.images).map(i => {"
        " const r = i.getBoundingClientRect();"
        " return {alt: i.alt, natural: i.naturalWidth, naturalHeight: i.naturalHeight,"
        " width: r.width, height: r.height, section: i.closest('section') && i.closest('section').id}; })"
    )
    figures = _results(report)["figures"]
    assert len(images) == len(figures) >= 1
    assert sorted(i["section"] for i in images) == sorted(f["id"] for f in figures)
    for image in images:
        assert image["natural"] > 0 and image["naturalHeight"] > 0, f"figure did not decode: {image}"
        assert image["width"] > 0 and image["height"] > 0, f"figure drawn with zero size: {image}"


def test_comparison_table_has_every_row(page, report: Path) -> None:
    driver, _ = page
    keys = driver.execute_script(
        "return Array.from(document.querySelectorAll('table.comparisons tr[data-key]')).map(r => r.dataset.key)"
    )
    expected = [row["key"] for row in _results(report)["comparisons"]]
    assert keys == expected
    cells = driver.execute_script(
        "return Array.from(document.querySelectorAll('table.comparisons tr[data-key]'))"
        ".map(r => Array.from(r.cells).map(c => c.textContent.trim()))"
    )
    for row in cells:
        quantity, _kind, printed, _source, computed, difference = row[:6]
        assert quantity and printed and computed != "—" and difference != "—", row
    visible = driver.execute_script(
        "const t = document.querySelector('table.comparisons').getBoundingClientRect(); return t.width * t.height"
    )
    assert visible > 0


def test_every_internal_link_has_a_target(page, report: Path) -> None:
    driver, _ = page
    dangling = driver.execute_script(
        "return Array.from(document.querySelectorAll('a[href^=\"#\"]'))"
        ".map(a => a.getAttribute('href').slice(1)).filter(id => !document.getElementById(id))"
    )
    assert dangling == []
    errata_links = driver.execute_script(
        "return Array.from(document.querySelectorAll('table.comparisons a[href^=\"#e\"]')).length"
    )
    assert errata_links == sum("errata" in row for row in _results(report)["comparisons"])


def test_page_loads_nothing_from_outside(page) -> None:
    driver, _ = page
    fetched = driver.execute_script(
        "return performance.getEntriesByType('resource').map(e => e.name).filter(n => !n.startsWith('data:'))"
    )
    assert fetched == []
    counts = driver.execute_script(
        "return [document.scripts.length, document.querySelectorAll('link[rel=stylesheet]').length,"
        " document.styleSheets.length]"
    )
    assert counts == [0, 0, 1]


def test_page_fits_an_800_pixel_window(page) -> None:
    """At 800 px the page itself never scrolls sideways; wide tables scroll inside their own box."""
    driver, _ = page
    _resize(driver, 800, 900)
    try:
        widths = driver.execute_script(
            "return [document.documentElement.scrollWidth, document.documentElement.clientWidth,"
            " document.body.scrollWidth]"
        )
        assert widths[0] <= widths[1] and widths[2] <= widths[1], f"page overflows at 800 px: {widths}"
    finally:
        _resize(driver, 1280, 1024)


#: How long a resize may take to reach the page (seconds); on a loaded machine the next script ran before it did
RESIZE_WAIT = 10.0


def _resize(driver, width: int, height: int) -> None:
    """Resize the window and wait until the page sees the new width: ``set_window_size`` returns before the layout
    follows, and a script run at once read the old window (an 800 px window measured "at 1280 px")."""
    import time

    driver.set_window_size(width, height)
    deadline = time.monotonic() + RESIZE_WAIT
    while driver.execute_script("return window.outerWidth") != width and time.monotonic() < deadline:
        time.sleep(0.05)
    driver.execute_script("return document.documentElement.getBoundingClientRect().width")  # the layout, done


#: Window widths the report is checked at: a small laptop or tablet, a common laptop, a desktop.
WIDTHS = (760, 1280, 1920)
#: The tables that must show every column without scrolling from this window width on (issue 19).
WHOLE_FROM = 1280


def _tables_at(driver, width: int) -> list[dict]:
    _resize(driver, width, 1000)
    try:
        return driver.execute_script(
            "return Array.from(document.querySelectorAll('main table')).map(t => {"
            " const box = t.parentElement, hint = box.querySelector(':scope > .scroll-hint');"
            " return {table: t.className, window: window.innerWidth, scrolls: box.scrollWidth > box.clientWidth + 1,"
            " hint: !!hint && hint.getBoundingClientRect().height > 0"
            " && getComputedStyle(hint).visibility === 'visible',"
            " right: box.getBoundingClientRect().right, page: document.documentElement.clientWidth}; })"
        )
    finally:
        _resize(driver, 1280, 1024)


@pytest.mark.parametrize("width", WIDTHS)
def test_a_table_wider_than_the_window_says_so_and_the_main_ones_fit_on_a_laptop(page, width: int) -> None:
    """A table that scrolls sideways shows the line saying so (and only then); from 1280 px on, Table 1 at a
    glance and the full comparison table show every column, "Computed from" included, without scrolling."""
    driver, _ = page
    tables = _tables_at(driver, width)
    assert tables and {"table1", "comparisons"} <= {t["table"] for t in tables}
    for table in tables:
        assert table["scrolls"] == table["hint"], f"at {width} px: {table}"
        assert table["right"] <= table["page"] + 0.5, f"at {width} px the page itself scrolls: {table}"
        if width >= WHOLE_FROM and table["table"] in ("table1", "comparisons"):
            assert not table["scrolls"], f"at {width} px {table['table']} hides columns behind a scroll: {table}"


def test_every_figure_is_drawn_near_its_own_size_at_760_pixels(page) -> None:
    """Figures are drawn at the report's width (760 px PNGs): shown in a 760 px window they are scaled by no less
    than 0.85, so that their 8-10 pt text stays readable (the Eq 1 figure was 1473 px wide, shown at 0.48)."""
    driver, _ = page
    _resize(driver, 760, 1000)
    try:
        scales = driver.execute_script(
            "return Array.from(document.images).map(i => [i.alt, i.getBoundingClientRect().width / i.naturalWidth])"
        )
    finally:
        _resize(driver, 1280, 1024)
    small = [(alt, round(scale, 2)) for alt, scale in scales if scale < 0.85]
    assert scales and not small, f"figures shrunk below 0.85 of their size at 760 px: {small}"
