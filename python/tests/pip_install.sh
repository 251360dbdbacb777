#!/usr/bin/env bash
# CTest python.pip_install (docs/python.md "Installing with pip"): a fresh venv, `pip install` of
# the checkout, and the pytest suite run against the installed package (not the build tree).
#   pip_install.sh SOURCE_DIR WORK_DIR PIP_BUILD_DIR C_COMPILER CXX_COMPILER
# The venv sees Debian's site-packages (--system-site-packages): numpy and pytest come from
# python3-numpy/python3-pytest, because Debian's pybind11 2.10 predates numpy 2 and PyPI's
# numpy would be 2.x. PIP_BUILD_DIR sits beside the test tree (same depth below the source), so
# ccache finds that tree's objects and only the module's own link is new.
set -euo pipefail
export CMAKE_BUILD_PARALLEL_LEVEL=${CMAKE_BUILD_PARALLEL_LEVEL:-2}  # a shared 2-core machine
src=$1 work=$2 build_dir=$3 cc=$4 cxx=$5
rm -rf "$work"
mkdir -p "$work"
/usr/bin/python3 -m venv --system-site-packages "$work/venv"
py=$work/venv/bin/python
t0=$(date +%s)
"$py" -m pip install --quiet --disable-pip-version-check --config-settings=build-dir="$build_dir" \
  --config-settings=cmake.define.CMAKE_C_COMPILER="$cc" --config-settings=cmake.define.CMAKE_CXX_COMPILER="$cxx" "$src"
t1=$(date +%s)
echo "pip install: $((t1 - t0)) s"
cd "$work"  # away from the checkout and the build tree: `import weft` must find the venv's
unset PYTHONPATH
"$py" - <<'PY'
import importlib.metadata, sys, weft
assert weft.__file__.startswith(sys.prefix), weft.__file__
assert weft.__version__ == importlib.metadata.version("weft"), (weft.__version__, importlib.metadata.version("weft"))
print("installed weft", weft.__version__, "at", weft.__file__)
PY
WEFT_INSTALLED=1 "$py" -m pytest -q -p no:cacheprovider -W error::pytest.PytestUnraisableExceptionWarning "$src/python/tests"
echo "pytest in the venv: $(($(date +%s) - t1)) s"
