"""Build the documentation site's generated pages from the demos and their outputs.

    python scripts/docs.py [--run] [--only NAME ...]

For every demo (``demos/*.py``, jupytext percent scripts) a MyST page ``docs/gallery/<name>.md``:
its narration and code cell by cell, then its results read from ``output/<name>/`` — the PyVista
pictures and plots it wrote, its verification table (``verification.json``: every check, its
value, bound or expected value and the reference it names) and its run facts. A demo whose
outputs are missing or older than its source is run first in its shortened form (``CI=true``);
``--run`` runs every demo again. Also written: the gallery's index (a picture per demo), the
accuracy-versus-time page (every demo's work-precision data, ``work_precision.json``, in one
plot) and the hard-cases page (the stability tests' records, ``output/hard_cases/*.json``).

The pages go to ``docs/gallery/``, ``docs/accuracy.md`` and ``docs/hard-cases.md`` (generated,
not kept in git); ``make docs`` then builds the site with Sphinx, warnings as errors.
"""
from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
DEMOS = ROOT / "demos"
DOCS = ROOT / "docs"
GALLERY = DOCS / "gallery"
OUTPUT = Path(os.environ.get("DC_OUTPUT_DIR", ROOT / "output"))


def demo_names(only=None) -> list[str]:
    """The demos (``demos/*.py`` stems), or those of ``only``; an unknown name stops with the list."""
    names = sorted(p.stem for p in DEMOS.glob("*.py"))
    if not only:
        return names
    unknown = sorted(set(only) - set(names))
    if unknown:
        raise SystemExit(f"no demo named {', '.join(unknown)}; the demos: {', '.join(names)}")
    return [n for n in names if n in only]


def cells(source: str) -> list[tuple[str, str]]:
    """(kind, text) of the percent-format cells of a demo: 'markdown' (comment marks removed) or
    'code'; the jupytext header is dropped."""
    lines = source.splitlines()
    if lines and lines[0].startswith("# ---"):
        end = next(i for i in range(1, len(lines)) if lines[i].startswith("# ---"))
        lines = lines[end + 1:]
    out: list[tuple[str, list[str]]] = []
    for line in lines:
        if line.startswith("# %%"):
            out.append(("markdown" if "[markdown]" in line else "code", []))
        elif out:
            out[-1][1].append(line)
        elif line.strip():
            out.append(("code", [line]))
    result = []
    for kind, body in out:
        if kind == "markdown":
            text = "\n".join(re.sub(r"^# ?", "", b) for b in body).strip()
        else:
            text = "\n".join(body).strip("\n")
        if text.strip():
            result.append((kind, text))
    return result


def title_of(source: str, name: str) -> str:
    for kind, text in cells(source):
        if kind == "markdown":
            m = re.search(r"^# (.+)$", text, re.M)
            if m:
                return m.group(1).strip()
    return name


def fresh(name: str) -> bool:
    report = OUTPUT / name / "verification.json"
    return report.exists() and report.stat().st_mtime >= (DEMOS / f"{name}.py").stat().st_mtime


def run_demo(name: str) -> float:
    env = dict(os.environ, CI="true", DC_OUTPUT_DIR=str(OUTPUT), DC_PROGRESS="off")
    start = time.perf_counter()
    proc = subprocess.run([sys.executable, str(DEMOS / f"{name}.py")], cwd=ROOT, env=env, capture_output=True,
                          text=True)
    if proc.returncode != 0:
        raise SystemExit(f"docs: demo {name} failed:\n{proc.stdout[-2000:]}\n{proc.stderr[-2000:]}")
    return time.perf_counter() - start


def _number(value) -> str:
    if isinstance(value, list):
        flat = value if len(value) <= 4 else value[:3] + ["…"]
        return "[" + ", ".join(_number(v) for v in flat) + "]"
    if isinstance(value, float):
        return f"{value:.4g}"
    return "—" if value is None else str(value)


def verification_table(report: dict) -> list[str]:
    rows = ["| check | value | expected or bound | reference | |", "|---|---|---|---|---|"]
    for c in report["checks"]:
        if c.get("expected") is not None:
            want = f"{_number(c['expected'])} (rtol {c.get('rtol', 0):g}, atol {c.get('atol', 0):g})"
        else:
            low, high = c["bound"]
            want = (f"≤ {_number(high)}" if low is None else f"≥ {_number(low)}" if high is None
                    else f"{_number(low)} … {_number(high)}")
        cell = lambda s: str(s).replace("|", "\\|").replace("\n", " ")  # noqa: E731
        rows.append(f"| {cell(c['label'])} | {cell(_number(c['value']))} | {cell(want)} | {cell(c['reference'])} | "
                    f"{'✓' if c['passed'] else '✗'} |")
    return rows


def demo_page(name: str) -> dict:
    """Write docs/gallery/<name>.md and copy the demo's pictures; returns its index entry."""
    source = (DEMOS / f"{name}.py").read_text()
    report = json.loads((OUTPUT / name / "verification.json").read_text())
    folder = GALLERY / name
    if folder.exists():
        shutil.rmtree(folder)
    folder.mkdir(parents=True)
    pictures = list(report.get("pictures", []))
    plots = sorted(p.name for p in (OUTPUT / name).glob("*.png") if p.name not in pictures)
    for png in pictures + plots:
        shutil.copy2(OUTPUT / name / png, folder / png)
    lines = []
    for kind, text in cells(source):
        if kind == "markdown":
            lines += [text, ""]
        else:
            lines += ["```python", text, "```", ""]
    lines += ["## Results of the shortened run", "",
              f"Computed by `CI=true python demos/{name}.py` on {report.get('ranks', 1)} rank(s); the full run "
              "(without `CI`) refines further. Every number below is asserted by the demo against the "
              "reference it names.", ""]
    for png in pictures:
        lines += [f"![{name}: {png}]({name}/{png})", ""]
    for png in plots:
        lines += [f"![{name}: {png}]({name}/{png})", ""]
    lines += ["### Verification", ""] + verification_table(report) + [""]
    (GALLERY / f"{name}.md").write_text("\n".join(lines))
    return {"name": name, "title": title_of(source, name), "picture": (pictures + plots)[0] if pictures + plots
            else None, "checks": len(report["checks"]), "pyvista": bool(pictures)}


def gallery_index(entries: list[dict]) -> None:
    lines = ["# Demo gallery", "",
             "Every demo is a narrated script that verifies itself against a named reference (a closed "
             "form, a published value, or a converged solution with its convergence shown); the test "
             "suite runs each one serially and on two ranks. The pictures are the demos' own, drawn with "
             "`dolfinx_corot.plot`.", "", "```{toctree}", ":hidden:", ""]
    lines += [e["name"] for e in entries] + ["```", ""]
    for e in entries:
        lines += [f"## [{e['title']}]({e['name']}.md)", ""]
        if e["picture"]:
            alt = e["title"].replace(":", " -")  # a colon would start a directive option
            lines += ["```{image} " + f"{e['name']}/{e['picture']}", f":alt: {alt}", ":width: 420px", "```", ""]
        lines += [f"`demos/{e['name']}.py` · {e['checks']} verified numbers", ""]
    (GALLERY / "index.md").write_text("\n".join(lines) + "\n")


def accuracy_page(names: list[str]) -> None:
    """Every demo's work-precision data (``work_precision.json``) in one plot, and per demo."""
    from matplotlib.figure import Figure

    series = []
    for name in names:
        path = OUTPUT / name / "work_precision.json"
        if path.exists():
            data = json.loads(path.read_text())
            for part in data.get("series", [data]):  # one curve, or one per element family
                series.append((f"{name} ({part['series']})" if "series" in part else name, part))
    lines = ["# Accuracy against time", "",
             "What accuracy costs: each demo that refines its mesh reports the error of its verified "
             "quantity against the wall time of the run, mesh by mesh (shortened runs, one core; the "
             "machine's load shifts the times, not the errors).", ""]
    if series:
        fig = Figure(figsize=(11, 5.5))
        ax = fig.subplots()
        colours = [f"C{k % 10}" for k in range(len(series))]
        markers = "os^vDP*Xhp<>"
        for k, (name, data) in enumerate(series):  # a colour and a marker each: more demos than colours
            ax.loglog(data["time"], data["error"], "-", marker=markers[k % len(markers)], color=colours[k], ms=5,
                      label=f"{name}: {data['quantity']}")
        ax.set_xlabel("wall time [s]")
        ax.set_ylabel("relative error")
        ax.grid(True, which="both", lw=0.3)
        ax.legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.02, 1.0))
        fig.tight_layout()
        fig.savefig(GALLERY / "accuracy_vs_time.png", dpi=110)
        lines += ["![every demo's error against wall time](gallery/accuracy_vs_time.png)", ""]
        lines += ["| demo | quantity | reference | meshes | errors | wall times [s] |", "|---|---|---|---|---|---|"]
        for name, data in series:
            errs = ", ".join(f"{e:.2g}" for e in data["error"])
            times = ", ".join(f"{t:.2g}" for t in data["time"])
            meshes = ", ".join(str(m) for m in data["resolution"])
            lines.append(f"| [{name}](gallery/{name.split(' ')[0]}) | {data['quantity']} | {data['reference']} | {meshes} | "
                         f"{errs} | {times} |")
    else:
        lines += ["No demo has written work-precision data yet."]
    (DOCS / "accuracy.md").write_text("\n".join(lines) + "\n")


def hard_cases_page() -> None:
    """The stability tests' records (``output/hard_cases/*.json``, written by the test suite)."""
    records = sorted((OUTPUT / "hard_cases").glob("*.json")) if (OUTPUT / "hard_cases").exists() else []
    lines = ["# Hard cases", "",
             "The tests that push the solvers where analyses break: what each one stresses and what it "
             "measured in the last run of the test suite (`make test`).", ""]
    if not records:
        lines += ["No record yet: run the test suite (`make test`) before `make docs`."]
    for path in records:
        rec = json.loads(path.read_text())
        lines += [f"## {rec['title']}", "", rec["stresses"], "", f"Test: `{rec['test']}`", ""]
        lines += ["| measured | value |", "|---|---|"]
        lines += [f"| {k} | {_number(v)} |" for k, v in rec["measured"].items()] + [""]
        for png in rec.get("pictures", []):
            src = path.parent / png
            if src.exists():
                shutil.copy2(src, GALLERY / png)
                lines += [f"![{rec['title']}](gallery/{png})", ""]
    (DOCS / "hard-cases.md").write_text("\n".join(lines) + "\n")


MATHJAX = Path("/usr/share/javascript/mathjax")  # Debian's libjs-mathjax (MathJax 2.7)
MATHJAX_PARTS = ["MathJax.js", "jax/input/TeX", "jax/output/CommonHTML", "jax/element",
                 "extensions", "fonts/HTML-CSS/TeX/woff"]


def copy_mathjax() -> None:
    """The parts of MathJax that TeX input and CommonHTML output load, into docs/_static/mathjax."""
    target = DOCS / "_static" / "mathjax"
    if (target / "MathJax.js").exists():
        return
    if not MATHJAX.exists():
        raise SystemExit(f"docs: MathJax not found at {MATHJAX} (Debian: apt install libjs-mathjax)")
    for part in MATHJAX_PARTS:
        src, dst = MATHJAX / part, target / part
        dst.parent.mkdir(parents=True, exist_ok=True)
        if src.is_dir():
            shutil.copytree(src, dst, dirs_exist_ok=True)
        else:
            shutil.copy2(src, dst)


def record_hard_cases() -> None:
    """Run the tests that record hard cases (``pytest -m hard_case``) when their records are missing or
    older than the tests."""
    folder = OUTPUT / "hard_cases"
    records = list(folder.glob("*.json")) if folder.exists() else []
    newest_test = max(p.stat().st_mtime for p in (ROOT / "tests").glob("test_*.py"))
    if records and min(p.stat().st_mtime for p in records) >= newest_test:
        return
    print("docs: running the hard-case tests (pytest -m hard_case) ...", flush=True)
    env = dict(os.environ, DC_HARD_CASES=str(folder), DC_PROGRESS="off")
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-m", "hard_case", "-p", "no:cacheprovider",
                           "tests"], cwd=ROOT, env=env, capture_output=True, text=True)
    if proc.returncode != 0:
        raise SystemExit(f"docs: the hard-case tests failed:\n{proc.stdout[-3000:]}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--run", action="store_true", help="run every demo again (shortened form)")
    parser.add_argument("--only", nargs="*", help="these demos only")
    args = parser.parse_args()
    names = demo_names(args.only)
    GALLERY.mkdir(parents=True, exist_ok=True)
    copy_mathjax()
    for name in names:
        if args.run or not fresh(name):
            print(f"docs: running demos/{name}.py (CI=true) ...", flush=True)
            print(f"docs: {name}: {run_demo(name):.1f} s", flush=True)
    record_hard_cases()
    entries = [demo_page(n) for n in names]
    gallery_index(entries)
    accuracy_page(names)
    hard_cases_page()
    print(f"docs: {len(entries)} demo pages, {sum(e['pyvista'] for e in entries)} with PyVista pictures")


if __name__ == "__main__":
    main()
