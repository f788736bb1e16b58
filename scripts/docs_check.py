"""Check the built documentation in a real browser (headless Chromium through chromedriver).

    python scripts/docs_check.py [docs/_build/html]

Every page is opened from disk; the check fails on an image that did not load, an internal link
to a missing page or a missing anchor, or an error in the browser's console (a script that failed
or did not load). Screenshots of the entry page and two demo pages go to
``output/docs-check/``. Needs Debian's chromium, chromium-driver and python3-selenium.
"""
from __future__ import annotations

import os
import sys
import time
from pathlib import Path
from urllib.parse import unquote, urlparse

ROOT = Path(__file__).resolve().parents[1]
SHOTS = Path(os.environ.get("DC_OUTPUT_DIR", ROOT / "output")) / "docs-check"
CHROMEDRIVER = "/usr/bin/chromedriver"


def browser():
    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service

    options = webdriver.ChromeOptions()
    for arg in ("--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage",
                "--window-size=1280,900", "--allow-file-access-from-files"):
        options.add_argument(arg)
    options.set_capability("goog:loggingPrefs", {"browser": "ALL"})
    return webdriver.Chrome(service=Service(CHROMEDRIVER), options=options)


PAGE_STATE = """
const bad = [...document.images].filter(i => !i.complete || i.naturalWidth === 0).map(i => i.src);
const links = [...document.querySelectorAll('a[href]')].map(a => a.href).filter(h => h.startsWith('file:'));
const ids = [...document.querySelectorAll('[id]')].map(e => e.id);
return {bad: bad, links: links, ids: ids};
"""


def main() -> int:
    site = Path(sys.argv[1] if len(sys.argv) > 1 else ROOT / "docs" / "_build" / "html").resolve()
    if not (site / "index.html").exists():
        print(f"docs-check: no site at {site} (run make docs)")
        return 2
    pages = sorted(site.rglob("*.html"))
    SHOTS.mkdir(parents=True, exist_ok=True)
    driver = browser()
    problems: list[str] = []
    anchors: dict[Path, set] = {}
    links: list[tuple[Path, str]] = []
    start = time.perf_counter()
    try:
        for page in pages:
            driver.get(page.as_uri())
            for _ in range(50):  # scripts (MathJax) may still be loading
                if driver.execute_script("return document.readyState") == "complete":
                    break
                time.sleep(0.1)
            state = driver.execute_script(PAGE_STATE)
            anchors[page] = set(state["ids"])
            rel = page.relative_to(site)
            problems += [f"{rel}: image did not load: {src}" for src in state["bad"]]
            links += [(page, href) for href in state["links"]]
            for entry in driver.get_log("browser"):
                if entry.get("level") == "SEVERE":
                    problems.append(f"{rel}: console error: {entry.get('message')}")
        for page, href in links:
            url = urlparse(href)
            target = Path(unquote(url.path))
            rel = page.relative_to(site)
            if not target.exists():
                problems.append(f"{rel}: broken link to {href}")
            elif url.fragment and target.suffix == ".html" and target in anchors and \
                    unquote(url.fragment) not in anchors[target]:
                problems.append(f"{rel}: link to a missing anchor: {href}")
        demos = sorted((site / "gallery").glob("*.html"))
        demos = [d for d in demos if d.name != "index.html"][:2]
        for page in [site / "index.html"] + demos:
            driver.get(page.as_uri())
            time.sleep(1.0)  # MathJax typesets
            height = driver.execute_script("return document.body.scrollHeight")
            driver.set_window_size(1280, min(max(int(height), 900), 6000))
            driver.save_screenshot(str(SHOTS / f"{page.stem}.png"))
            driver.set_window_size(1280, 900)
    finally:
        driver.quit()
    for p in problems:
        print("docs-check:", p)
    print(f"docs-check: {len(pages)} pages, {len(links)} internal links, {len(problems)} problems, "
          f"{time.perf_counter() - start:.1f} s; screenshots in {SHOTS}")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
