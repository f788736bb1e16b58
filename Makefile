# dolfinx_corot — set-up, demo, tests, benchmarks.
# `make demo` and `make test` do the whole set-up on a fresh Debian 12 first.
PY := .venv/bin/python
export OPENBLAS_NUM_THREADS ?= 1
export OMP_NUM_THREADS ?= 1
export OMPI_ALLOW_RUN_AS_ROOT := 1
export OMPI_ALLOW_RUN_AS_ROOT_CONFIRM := 1

.PHONY: setup setup-docs demo demos test bench docs docs-check notebooks clean-cache

setup:
	@bash scripts/setup.sh

setup-docs:
	@bash scripts/setup.sh docs

demo: setup
	$(PY) demos/euler_beam_2d.py
	@echo "results: output/euler_beam_2d/"

demos: setup
	@for d in demos/*.py; do echo "== $$d"; $(PY) $$d || exit 1; done

# the serial tests on both cores (pytest-xdist), then the two-rank runs one at a time (they take
# both cores each); the demos' serial values, which the two-rank runs must reproduce, pass from the
# first run to the second through output/tests/serial
SERIAL_OUTPUTS := $(CURDIR)/output/tests/serial
test: setup
	rm -rf $(SERIAL_OUTPUTS)
	DC_SERIAL_OUTPUTS=$(SERIAL_OUTPUTS) $(PY) -m pytest -ra --durations=25 -n 2 --dist worksteal -m "not mpi" tests
	DC_SERIAL_OUTPUTS=$(SERIAL_OUTPUTS) $(PY) -m pytest -ra --durations=25 -m mpi tests

# the site: demo pages from demos/*.py and their outputs (shortened runs, reused while fresh)
docs: setup-docs
	$(PY) scripts/docs.py
	$(PY) -m sphinx -W --keep-going -q -b html docs docs/_build/html
	@echo "site: docs/_build/html/index.html"

# the built site in headless Chromium: images, internal links, console errors; screenshots
docs-check: docs
	$(PY) scripts/docs_check.py docs/_build/html

# every demo as a notebook (output/notebooks/), executed top to bottom in its shortened form
notebooks: setup-docs
	$(PY) scripts/notebooks.py

bench: setup
	$(PY) benchmarks/startup.py                    # import and a small model's whole process, against import dolfinx
	$(PY) benchmarks/beam2d.py
	$(PY) benchmarks/hertz_same.py                 # Hertz, two equal elastic bodies (the peer comparison's set-up)
	$(PY) benchmarks/pullout.py
	$(PY) benchmarks/pullout_snap.py               # the pull-out's snap converged: about 8 minutes
	$(PY) benchmarks/pullout_energy.py             # where the coarse quadrilaterals' excess energy lies
	$(PY) benchmarks/beam_kernels.py               # the beams' C kernels against numba's, 10⁵ elements
	$(PY) benchmarks/frame3d.py --sizes 7 15 32   # 10³, 10⁴, 10⁵ elements: about 20 minutes
	$(PY) benchmarks/block3d.py                    # 116 k dofs SVK block: about 9 s
	mpirun -n 2 $(PY) benchmarks/block3d.py
	$(PY) benchmarks/block3d.py --mesh 320 32 32   # 10⁶ dofs: under 2 minutes, 2.9 GB
	mpirun -n 2 $(PY) benchmarks/block3d.py --mesh 320 32 32
	$(PY) benchmarks/contact_search.py             # 10⁴, 10⁵, 10⁶ slaves and segments
	$(PY) benchmarks/contact_effects.py            # an idle interface's cost
	$(PY) benchmarks/lining_soft_ground.py         # Newton iterations of contact in soft ground, three meshes
	$(PY) benchmarks/friction.py --baseline 6245b6d^   # a block slid with friction; frictionless against the code before friction
	@echo "the benchmarks' table: output/bench/summary.md"

# numba's on-disk cache does not see edits of inlined callees in other modules
clean-cache:
	find dolfinx_corot -name '*.nbi' -delete -o -name '*.nbc' -delete
