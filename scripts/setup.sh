#!/usr/bin/env bash
# Idempotent set-up of dolfinx_corot on Debian 12.
#
#  1. Debian packages: DOLFINx 0.5.2 (PETSc 3.18, MUMPS), gmsh, meshio, h5py,
#     OpenBLAS (MUMPS is ~3x slower with the reference BLAS), EGL for
#     off-screen PyVista, matplotlib, scipy, pandas (Result.history.to_pandas).
#  2. .venv made by Debian's /usr/bin/python3 with --system-site-packages, so
#     that it sees dolfinx; numpy & friends are pinned to Debian's versions by
#     a constraints file that every pip call in the venv obeys (.venv/pip.conf).
#  3. The package itself (editable) with numba, pyvista, tqdm, pytest, pytest-xdist, hypothesis.
#  4. With the argument "docs": what the documentation site needs besides (Sphinx, MyST, MathJax,
#     Chromium and its driver with selenium for `make docs-check`; furo, jupytext, nbclient and
#     ipykernel from PyPI).
#
# A stamp file records what was installed; a second run takes about a second.
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$here"
venv="$here/.venv"
stamp="$venv/.dolfinx_corot-setup"

debs=(python3-dolfinx-real python3-gmsh python3-meshio python3-venv python3-h5py
      python3-matplotlib python3-scipy python3-dev libopenblas0-pthread
      python3-pandas libegl1 libegl-mesa0 openmpi-bin)
pip_pkgs=(numba pyvista tqdm pytest pytest-xdist hypothesis)
docs_debs=(python3-sphinx python3-myst-parser libjs-mathjax chromium chromium-driver python3-selenium)
docs_pip=("furo==2022.12.7" "markdown-it-py<3" jupytext nbclient ipykernel)  # myst-parser 0.18 needs markdown-it-py 2

if [[ "${1:-}" == "docs" ]]; then
    bash "$0"  # the library first
    sudo=""; [[ $(id -u) -ne 0 ]] && sudo="sudo"
    docs_stamp="$venv/.dolfinx_corot-docs"
    docs_want="$(printf '%s ' "${docs_debs[@]}" "${docs_pip[@]}" | sha256sum | cut -d' ' -f1)"
    if [[ -f "$docs_stamp" && "$(cat "$docs_stamp")" == "$docs_want" ]]; then
        exit 0
    fi
    missing=()
    for p in "${docs_debs[@]}"; do
        dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
    done
    if (( ${#missing[@]} )); then
        echo "setup: installing Debian packages for the documentation: ${missing[*]}"
        $sudo apt-get update -q
        DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
    fi
    "$venv/bin/python" -m pip install -q --disable-pip-version-check "${docs_pip[@]}"
    echo "$docs_want" > "$docs_stamp"
    exit 0
fi

# Bytecode of our modules and of Debian's DOLFINx and petsc4py, which Debian installs without it
# (they live outside /usr/lib/python3, where its byte-compilation looks): Python reads it even where
# PYTHONDONTWRITEBYTECODE keeps it from writing it, and then compiles nothing at start-up (about 0.1 s
# of every process). Files already current are left alone; run on every call, for edited sources.
bytecode() {
    "$venv/bin/python" -m compileall -q -j 0 "$here/dolfinx_corot" >/dev/null || true
    local sudo_=""; [[ $(id -u) -ne 0 ]] && sudo_="sudo -n"
    local d
    for d in $("$venv/bin/python" -c "import os, dolfinx, petsc4py
for m in (dolfinx, petsc4py): print(os.path.dirname(os.path.realpath(m.__file__)))" 2>/dev/null); do
        [[ -w "$d" || -n "$sudo_" ]] && $sudo_ /usr/bin/python3 -m compileall -q -j 0 "$d" >/dev/null 2>&1 || true
    done
}

# What the stamp must match: this script and the package metadata.
want="$(cat "$0" pyproject.toml | sha256sum | cut -d' ' -f1)"
if [[ -f "$stamp" && "$(cat "$stamp")" == "$want" ]] && "$venv/bin/python" -c "import dolfinx, dolfinx_corot, numba" 2>/dev/null; then
    bytecode
    exit 0
fi

sudo=""
if [[ $(id -u) -ne 0 ]]; then sudo="sudo"; fi

missing=()
for p in "${debs[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if (( ${#missing[@]} )); then
    echo "setup: installing Debian packages: ${missing[*]}"
    $sudo apt-get update -q
    DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

if [[ ! -x "$venv/bin/python" ]]; then
    echo "setup: creating $venv with Debian's python"
    /usr/bin/python3 -m venv --system-site-packages "$venv"
fi

# Pin the compiled stack to what Debian ships: pip must never replace numpy
# (numpy 2 breaks 'import dolfinx') nor h5py (pip's wheel bundles another HDF5).
/usr/bin/python3 - "$venv/constraints.txt" <<'EOF'
import importlib, sys
mods = {"numpy": "numpy", "scipy": "scipy", "matplotlib": "matplotlib", "mpi4py": "mpi4py",
        "petsc4py": "petsc4py", "h5py": "h5py", "cffi": "cffi", "pandas": "pandas"}
lines = []
for dist, mod in mods.items():
    lines.append(f"{dist}=={importlib.import_module(mod).__version__}")
open(sys.argv[1], "w").write("\n".join(lines) + "\n")
EOF
printf '[install]\nconstraint = %s\n' "$venv/constraints.txt" > "$venv/pip.conf"

echo "setup: installing Python packages into $venv"
"$venv/bin/python" -m pip install -q --disable-pip-version-check "${pip_pkgs[@]}"
"$venv/bin/python" -m pip install -q --disable-pip-version-check --no-build-isolation -e "$here" 2>/dev/null \
    || "$venv/bin/python" -m pip install -q --disable-pip-version-check -e "$here"

# the element kernels of every kind, compiled once into numba's cache (a part loads its kind's on first use),
# and the C libraries of the beams and of the assembly's loops (cffi, into ~/.cache/dolfinx_corot)
"$venv/bin/python" -c "import dolfinx_corot.console as c; c.announce_compilation()
import dolfinx_corot.kernels.line2d, dolfinx_corot.kernels.beam3d, dolfinx_corot.kernels.shell3d, dolfinx_corot.kernels.membrane_quad
import dolfinx_corot.kernels.compiled as k, dolfinx_corot.assembly.cells as a; k.library(); a.compiled()
import dolfinx, numpy, numba; print('setup: dolfinx', dolfinx.__version__, 'numpy', numpy.__version__, 'numba', numba.__version__)"
bytecode
echo "$want" > "$stamp"
