"""What the package says about itself: its version (the CMake project's) and one line for an
interpreter that cannot use it (docs/python.md "Installing with pip")."""

import os
import re
import shutil
import subprocess
import sys

import weft


def project_version():
    text = open(os.path.join(os.environ["WEFT_SOURCE_DIR"], "CMakeLists.txt")).read()
    return re.search(r"project\(weft VERSION ([0-9.]+)", text).group(1)


def test_version_is_the_cmake_projects():
    assert weft.__version__ == project_version()
    if os.environ.get("WEFT_INSTALLED"):  # under pip_install.sh: the dist-info says the same
        import importlib.metadata
        assert importlib.metadata.version("weft") == weft.__version__


def import_error(tmp_path, prelude=""):
    """stderr's last line of `import weft` in a child Python, with `prelude` run first."""
    code = prelude + "\nimport weft\n"
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=tmp_path,
                       env=dict(os.environ, PYTHONPATH=str(tmp_path)))
    assert r.returncode != 0
    return r.stderr.strip().splitlines()[-1]


def test_python_without_numpy_gets_one_line_saying_what_to_install(tmp_path):
    shutil.copytree(os.path.dirname(weft.__file__), tmp_path / "weft")
    last = import_error(tmp_path, "import sys; sys.modules['numpy'] = None  # as if not installed")
    assert last.startswith("ImportError: weft needs numpy 1.x"), last
    assert "apt install python3-numpy" in last and "pip install 'numpy<2'" in last


def test_another_python_gets_one_line_naming_both(tmp_path):
    shutil.copytree(os.path.dirname(weft.__file__), tmp_path / "weft")
    info = tmp_path / "weft" / "_build_info.py"
    info.write_text(re.sub(r"python = \(\d+, \d+\)", "python = (3, 99)", info.read_text()))
    last = import_error(tmp_path)
    assert last.startswith("ImportError: weft was built for Python 3.99"), last
    assert "this is Python %d.%d" % sys.version_info[:2] in last and "pip install" in last
