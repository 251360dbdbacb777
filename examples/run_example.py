"""Runs one example as CTest does (python/tests/CMakeLists.txt, label `examples`): the script with
--quick --out <a temporary folder>, then checks that it exited 0, wrote every --file (non-empty)
and printed a line matching every --line regular expression (e.g. one table row per axis).

    PYTHONPATH=build/ci/python python3 examples/run_example.py examples/fig_s13.py \
        --file fig_s13.csv --line '^\\+x ' --line '^\\+z '
"""

import argparse
import os
import re
import shutil
import subprocess
import sys
import tempfile


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("script")
    parser.add_argument("--file", action="append", default=[], help="an output the script must write")
    parser.add_argument("--line", action="append", default=[], help="a regex some stdout line must match")
    args = parser.parse_args()
    out = tempfile.mkdtemp(prefix="weft-example-")
    try:
        run = subprocess.run([sys.executable, args.script, "--quick", "--out", out], capture_output=True, text=True)
        sys.stdout.write(run.stdout)
        sys.stderr.write(run.stderr)
        problems = [] if run.returncode == 0 else ["exit code %d" % run.returncode]
        for name in args.file:
            path = os.path.join(out, name)
            if not os.path.isfile(path) or os.path.getsize(path) == 0:
                problems.append("no output %s" % name)
        lines = run.stdout.splitlines()
        for pattern in args.line:
            if not any(re.search(pattern, line) for line in lines):
                problems.append("no line of the output matches %r" % pattern)
    finally:
        shutil.rmtree(out, ignore_errors=True)
    if problems:
        sys.exit("%s: %s" % (os.path.basename(args.script), "; ".join(problems)))


if __name__ == "__main__":
    main()
