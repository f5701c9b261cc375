#!/usr/bin/env python3
"""Check the built documentation site in a real browser (headless Chromium); exit 1 on any failure.

    python scripts/check-site.py SITE_DIR

Serves SITE_DIR over http on a free local port (the site's search loads its index with fetch, which file://
refuses) and checks, in Debian's chromium through chromedriver:

* every page renders: a heading, no raw Markdown outside code (``## ``, fences, ``](x.md)``, ``:::``, ``$$``),
  no browser errors in the console;
* every link inside the site points to a file of the site;
* the equations page shows MathML, laid out (not raw TeX);
* the API page documents ``run_transient``;
* each notebook page shows its cells with outputs, and at least one figure;
* the report's figures page shows its figures;
* the search box finds "critical velocity".
"""

from __future__ import annotations

import functools
import http.server
import re
import shutil
import sys
import tempfile
import threading
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any
from urllib.parse import unquote, urljoin, urlparse

FLAGS = (
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--disable-dev-shm-usage",
    "--window-size=1280,1024",
)
SEARCH = "critical velocity"
#: Markdown that survived the build, outside code (the article's text with pre/code removed)
RAW = re.compile(r"^#{2,6} \S|^```|^~~~|\]\([^)\s]+\.md\b|^::: |\$\$|\\frac|\\int", re.MULTILINE)
TEXT_OUTSIDE_CODE = """
const article = document.querySelector('article') || document.body;
const copy = article.cloneNode(true);
copy.querySelectorAll('pre, code, math, script, style, .jp-InputArea, .jp-OutputArea').forEach(e => e.remove());
return copy.innerText;
"""


def main(argv: list[str]) -> int:
    if len(argv) != 1 or not (Path(argv[0]) / "index.html").is_file():
        print("usage: check-site.py SITE_DIR (a folder holding index.html)", file=sys.stderr)
        return 2
    site = Path(argv[0]).resolve()
    pages = sorted(p.relative_to(site).as_posix() for p in site.rglob("index.html"))
    failures = _broken_links(site)
    with _served(site) as base, _browser() as driver:
        checks: list[tuple[str, Callable[[], list[str]]]] = [
            ("pages render", lambda: _pages_render(driver, base, pages)),
            ("equations", lambda: _equations(driver, base)),
            ("API reference", lambda: _api(driver, base)),
            ("notebooks", lambda: _notebooks(driver, base, pages)),
            ("report figures", lambda: _report_figures(driver, base)),
            ("search", lambda: _search(driver, base)),
        ]
        for name, check in checks:
            found = check()
            print(f"check-site: {name}: {'ok' if not found else f'{len(found)} problem(s)'}", flush=True)
            failures += found
    for failure in failures:
        print(f"check-site: FAILED: {failure}", file=sys.stderr)
    print(f"check-site: {len(pages)} pages, {len(failures)} problem(s)")
    return 1 if failures else 0


@contextmanager
def _served(site: Path) -> Iterator[str]:
    handler = functools.partial(_QuietHandler, directory=str(site))
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler)  # port 0: a free port
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    try:
        yield f"http://127.0.0.1:{server.server_address[1]}/"
    finally:
        server.shutdown()
        server.server_close()


class _QuietHandler(http.server.SimpleHTTPRequestHandler):
    def log_message(self, format: str, *args: Any) -> None:  # one line per request would bury the results
        pass


@contextmanager
def _browser() -> Iterator[Any]:
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    chromium = shutil.which("chromium") or shutil.which("chromium-browser")
    driver_path = shutil.which("chromedriver")
    if chromium is None or driver_path is None:
        raise SystemExit("check-site: headless Chromium is required: install Debian's chromium and chromium-driver")
    profile = tempfile.mkdtemp(prefix="stickslip-site-chromium-")
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


def _url(base: str, page: str) -> str:
    return urljoin(base, page.removesuffix("index.html"))


def _broken_links(site: Path) -> list[str]:
    """Every href/src inside the site (not external, not an anchor alone) names a file of the site."""
    problems = []
    for path in site.rglob("*.html"):
        if path.name in ("report.html", "404.html"):  # the report has its own tests; 404 links from the site root
            continue
        text = path.read_text(encoding="utf-8")
        for target in set(re.findall(r'(?:href|src)="([^"#?]+)', text)):
            if urlparse(target).scheme or target.startswith("//") or target.startswith("data:"):
                continue
            resolved = (path.parent / unquote(target)).resolve()
            if resolved.is_dir():
                resolved = resolved / "index.html"
            if not resolved.exists():
                problems.append(f"{path.relative_to(site)}: link {target} leads nowhere")
    return problems


def _load(driver: Any, url: str) -> None:
    from selenium.webdriver.support.ui import WebDriverWait

    driver.get(url)
    WebDriverWait(driver, 20).until(lambda d: d.execute_script("return document.readyState") == "complete")


def _console_errors(driver: Any) -> list[str]:
    return [e["message"] for e in driver.get_log("browser") if e["level"] == "SEVERE" and "favicon" not in e["message"]]


def _pages_render(driver: Any, base: str, pages: list[str]) -> list[str]:
    problems = []
    for page in pages:
        if page == "404.html":
            continue
        _load(driver, _url(base, page))
        if not driver.find_elements("css selector", "article h1"):
            problems.append(f"{page}: no heading in the article")
        raw = RAW.search(driver.execute_script(TEXT_OUTSIDE_CODE))
        if raw:
            problems.append(f"{page}: raw Markdown or TeX in the rendered text: {raw.group(0)!r}")
        problems += [f"{page}: browser console: {message}" for message in _console_errors(driver)]
    return problems


def _equations(driver: Any, base: str) -> list[str]:
    _load(driver, _url(base, "equations/"))
    blocks = driver.find_elements("css selector", "div.math > math[display='block']")
    inline = driver.find_elements("css selector", "span.math > math")
    if len(blocks) < 17:
        return [f"equations/: {len(blocks)} displayed MathML equations, expected the paper's 17 at least"]
    if not inline:
        return ["equations/: no inline MathML"]
    # laid out as mathematics: a fraction is taller than a line of text (raw TeX would be one flat line)
    heights = [b.size["height"] for b in blocks]
    if min(heights) < 15 or max(heights) < 35:
        return [f"equations/: MathML boxes {min(heights)}-{max(heights)} px high; is MathML rendered?"]
    return []


def _api(driver: Any, base: str) -> list[str]:
    _load(driver, _url(base, "api/"))
    found = driver.find_elements("css selector", "[id$='run_transient']")
    text = driver.find_element("css selector", "article").text
    documented = found and re.search(r"run_transient\(\s*params", text)
    problems = [] if documented else ["api/: run_transient is not documented (no heading, or no signature)"]
    for name in ("fit_record", "FrictionModel", "steady_state", "critical_point", "simulate", "fit_steady", "sweep"):
        if name not in text:
            problems.append(f"api/: {name} is missing")
    return problems


def _notebooks(driver: Any, base: str, pages: list[str]) -> list[str]:
    notebooks = [p for p in pages if p.startswith("examples/") and p != "examples/index.html"]  # not the list
    if not notebooks:
        return ["no notebook pages under examples/"]
    problems = []
    for page in notebooks:
        _load(driver, _url(base, page))
        cells = driver.find_elements("css selector", ".jp-Cell")
        outputs = driver.find_elements("css selector", ".jp-OutputArea-output")
        images = driver.execute_script(
            "return [...document.querySelectorAll('.jp-OutputArea-output img')].filter(i => i.naturalWidth > 0).length"
        )
        if not cells or not outputs:
            problems.append(f"{page}: {len(cells)} cells, {len(outputs)} outputs (was the notebook executed?)")
        elif not images:
            problems.append(f"{page}: no figure among its {len(outputs)} outputs")
    return problems


def _report_figures(driver: Any, base: str) -> list[str]:
    _load(driver, _url(base, "report-figures/"))
    shown = driver.execute_script(
        "return [...document.querySelectorAll('article figure img')].map(i => i.naturalWidth > 0)"
    )
    if len(shown) < 5 or not all(shown):
        return [f"report-figures/: {sum(shown)} of {len(shown)} figures shown, expected the report's (5 or more)"]
    return []


def _search(driver: Any, base: str) -> list[str]:
    from selenium.common.exceptions import TimeoutException
    from selenium.webdriver.support.ui import WebDriverWait

    _load(driver, base)
    box = driver.find_element("css selector", "input.md-search__input")
    if not box.is_displayed():  # a narrow window hides the box behind the search icon
        driver.find_element("css selector", "label[for='__search']").click()
    box.click()
    box.send_keys(SEARCH)
    try:
        WebDriverWait(driver, 30).until(lambda d: d.find_elements("css selector", ".md-search-result__item"))
    except TimeoutException:
        meta = driver.find_elements("css selector", ".md-search-result__meta")
        return [f"search for {SEARCH!r}: no results ({meta[0].text if meta else 'no search result list'})"]
    count = len(driver.find_elements("css selector", ".md-search-result__item"))
    meta = driver.find_element("css selector", ".md-search-result__meta").text
    print(f"check-site: search for {SEARCH!r}: {count} results listed ({meta})")
    return []


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
