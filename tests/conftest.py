"""Shared fixtures: ``hard_case`` records what a stability test measured, for the documentation's
hard-cases page (``scripts/docs.py`` reads ``output/hard_cases/*.json``)."""
import json
import os
import re
from pathlib import Path

import pytest
from mpi4py import MPI

ROOT = Path(__file__).resolve().parents[1]


def hard_cases_dir() -> Path:
    return Path(os.environ.get("DC_HARD_CASES", ROOT / "output" / "hard_cases"))


@pytest.fixture
def hard_case(request):
    """``hard_case(title, stresses, measured, picture=None)``: write what the test measured
    (``measured``: name → number, text or list) with what it stresses, and optionally a picture
    (``picture=(states or scene, options)`` for :func:`dolfinx_corot.plot.picture`), to
    ``output/hard_cases/<test>.json``. Serial runs only (the two-rank runs check the same numbers)."""
    def record(title: str, stresses: str, measured: dict, picture=None) -> None:
        if MPI.COMM_WORLD.size > 1:
            return
        folder = hard_cases_dir()
        folder.mkdir(parents=True, exist_ok=True)
        stem = re.sub(r"[^A-Za-z0-9_]+", "_", f"{request.node.module.__name__}_{request.node.name}").strip("_")
        entry = {"title": title, "stresses": stresses, "test": request.node.nodeid,
                 "measured": {k: (v.item() if hasattr(v, "item") else v) for k, v in measured.items()},
                 "pictures": []}
        if picture is not None:
            from dolfinx_corot import plot

            states, options = picture
            plot.picture(states, str(folder / f"{stem}.png"), **options)
            entry["pictures"].append(f"{stem}.png")
        (folder / f"{stem}.json").write_text(json.dumps(entry, indent=1, default=float))
    return record


def pytest_collection_modifyitems(items):
    """Tests that record a hard case carry the marker ``hard_case`` (``pytest -m hard_case``)."""
    for item in items:
        if "hard_case" in getattr(item, "fixturenames", ()):
            item.add_marker(pytest.mark.hard_case)
