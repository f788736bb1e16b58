"""Every demo as a Jupyter notebook, executed top to bottom.

    python scripts/notebooks.py [--only NAME ...] [--no-run]

Each ``demos/<name>.py`` (a jupytext percent script) becomes ``output/notebooks/<name>.ipynb``
(narration as markdown cells, code as code cells), executed in a fresh kernel in its shortened
form (``CI=true``) with the demos folder as working directory (demos import their neighbours);
the executed notebook, with its printed output, is what is written. A cell that raises fails
the command, naming the demo and the cell.
"""
from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

from docs import demo_names  # noqa: E402  (scripts/ is the script's folder)

ROOT = Path(__file__).resolve().parents[1]
DEMOS = ROOT / "demos"
OUT = Path(os.environ.get("DC_OUTPUT_DIR", ROOT / "output")) / "notebooks"


def main() -> int:
    import jupytext
    import nbformat
    from nbclient import NotebookClient
    from nbclient.exceptions import CellExecutionError

    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", nargs="*", help="these demos only")
    parser.add_argument("--no-run", action="store_true", help="convert only")
    args = parser.parse_args()
    names = demo_names(args.only)
    OUT.mkdir(parents=True, exist_ok=True)
    os.environ.update(CI="true", DC_OUTPUT_DIR=str(OUT / "outputs"), DC_PROGRESS="off")
    failed = []
    for name in names:
        notebook = jupytext.read(DEMOS / f"{name}.py", fmt="py:percent")
        notebook.metadata["kernelspec"] = {"name": "python3", "display_name": "Python 3", "language": "python"}
        start = time.perf_counter()
        if not args.no_run:
            client = NotebookClient(notebook, timeout=1800, kernel_name="python3",
                                    resources={"metadata": {"path": str(DEMOS)}})
            try:
                client.execute()
            except CellExecutionError as err:
                failed.append(name)
                print(f"notebooks: {name} failed:\n{str(err)[-2000:]}", flush=True)
        nbformat.write(notebook, OUT / f"{name}.ipynb")
        print(f"notebooks: {name}.ipynb ({len(notebook.cells)} cells"
              + ("" if args.no_run else f", executed in {time.perf_counter() - start:.1f} s") + ")", flush=True)
    if failed:
        print(f"notebooks: {len(failed)} failed: {', '.join(failed)}")
        return 1
    print(f"notebooks: {len(names)} notebooks in {OUT}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
