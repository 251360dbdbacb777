"""Stopping a long call: Ctrl-C (SIGINT) or a raising progress callback stops the computation at
the next progress report, raises KeyboardInterrupt / the callback's exception, and the interpreter
stays usable (docs/python.md "Interrupting a call"). The CLI stops the same way at its next
report: it exits 130 with one line, its atomic writes remove their temporaries, and nothing is
half-written."""

import json
import os
import signal
import subprocess
import sys
import textwrap
import time

import pytest

import weft

# A cloth that takes well over a minute to generate on one core, so that an interrupted call
# that stops within seconds cannot have finished on its own.
BIG_CLOTH = {"pattern": "twill22", "warp_count": 24, "weft_count": 24, "voxel_size": 0.004, "seed": 2}
MEDIUM_CLOTH = {"pattern": "plain", "warp_count": 6, "weft_count": 6, "voxel_size": 0.01, "seed": 2}
SMALL_CLOTH = {"pattern": "plain", "warp_count": 2, "weft_count": 2, "voxel_size": 0.02, "seed": 5,
               "warp_yarn": {"fiber_count": 12}, "weft_yarn": {"fiber_count": 12}}

# The long calls, as the child runs them after `import weft` with `small` a small cloth and
# `scene` a small scene; each takes well over 5 s uninterrupted on this machine.
LONG_CALLS = {
    "gen": "weft.gen(%r, progress=cb)" % BIG_CLOTH,
    "render": "weft.render(scene, spp=1 << 16, progress=cb)",
    # One validate of the medium cloth takes under 0.1 s on a fast host, less than the wait before
    # the SIGINT; the same grid validated 1000 times is a long call on any machine.
    "validate": "[weft.validate(g, window='0.3', progress=cb) for g in [weft.gen(%r).grid] * 1000]" % MEDIUM_CLOTH,
    "measure_beam": "weft.measure_beam(small.grid, direction=(1, 1, 1), sigma=100, rays_per_column=1 << 12, "
                    "progress=cb)",
    "render_study": "weft.render_study(small.scene(lighting='back', width=32, height=24), spp=1, "
                    "reference_spp=1 << 16, factors=(2,), progress=cb)",
    # The matrix's first reports come from its cloth's generation; inside a case: below.
    "render_matrix": "weft.render_matrix(quick=True, cloths='plain', tilts=(45, 8), progress=cb)",
}

CHILD = textwrap.dedent("""
    import json, sys, time, weft
    small = weft.gen(%r)
    scene = json.loads(weft.builtin_scene("cloth_patch"))
    scene["camera"].update(width=64, height=48)
    def cb(label, done, total):
        if not getattr(cb, "said", False):
            cb.said = True
            print("started", flush=True)
    t0 = time.monotonic()
    try:
        %s
        print("finished uninterrupted", flush=True)
        sys.exit(3)
    except KeyboardInterrupt:
        print("interrupted after %%.1f s" %% (time.monotonic() - t0), flush=True)
    again = weft.gen(%r)  # the interpreter and the library still work
    assert again.grid.active_voxel_count == small.grid.active_voxel_count > 0
    print("usable", flush=True)
""")


def child_env():
    """The environment with this weft first on the path (the child runs in another folder)."""
    here = os.path.dirname(os.path.dirname(os.path.abspath(weft.__file__)))
    return dict(os.environ, PYTHONPATH=os.pathsep.join([here, os.environ.get("PYTHONPATH", "")]))


def interrupt_child(call, tmp_path):
    """Runs `call` in a child Python, sends SIGINT once its progress callback ran, and returns
    (exit code, stdout, stderr, seconds from SIGINT to exit)."""
    script = tmp_path / "child.py"
    script.write_text(CHILD % (SMALL_CLOTH, call, SMALL_CLOTH))
    child = subprocess.Popen([sys.executable, str(script)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, env=child_env(), cwd=tmp_path)
    try:
        first = child.stdout.readline()
        assert first == "started\n", first + child.stderr.read()
        time.sleep(0.1)  # inside the computation: its first stage has begun
        child.send_signal(signal.SIGINT)
        sent = time.monotonic()
        out, err = child.communicate(timeout=120)
        return child.returncode, first + out, err, time.monotonic() - sent
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()


@pytest.mark.parametrize("name", sorted(LONG_CALLS))
def test_ctrl_c_raises_keyboard_interrupt_and_the_interpreter_lives_on(name, tmp_path):
    code, out, err, seconds = interrupt_child(LONG_CALLS[name], tmp_path)
    assert code == 0, "exit %d (SIGABRT is -6)\n%s\n%s" % (code, out, err)
    assert "interrupted after" in out and out.rstrip().endswith("usable"), out
    assert "terminate called" not in err, err
    assert seconds < 30, "took %.1f s to stop" % seconds


class Third(Exception):
    pass


def raise_on_third_call():
    calls = []

    def cb(label, done, total):
        calls.append((label, done, total))
        if len(calls) == 3:
            raise Third("stop at call 3")
    return cb, calls


def small_scene():
    scene = json.loads(weft.builtin_scene("cloth_patch"))
    scene["camera"].update(width=64, height=48)
    return scene


@pytest.fixture(scope="module")
def small():
    return weft.gen(SMALL_CLOTH)


CALLBACK_CALLS = {
    "gen": lambda small, cb: weft.gen(SMALL_CLOTH, progress=cb),
    "render": lambda small, cb: weft.render(small_scene(), spp=4, progress=cb),
    "validate": lambda small, cb: weft.validate(small.grid, axes="x", window="0.05", progress=cb),
    "measure_beam": lambda small, cb: weft.measure_beam(small.grid, "x", sigma=100, progress=cb),
    "window_stats": lambda small, cb: weft.window_stats(small.grid, "x", window=0.05, progress=cb),
    "correlation_length": lambda small, cb: weft.correlation_length(small.grid, "x", progress=cb),
    "render_study": lambda small, cb: weft.render_study(small.scene(lighting="back", width=24, height=18), spp=2,
                                                        reference_spp=16, factors=(2,), progress=cb),
    "law_sample": lambda small, cb: weft.law("gamma", alpha=0.5, mean_extinction=1).sample(300_000, progress=cb),
}


@pytest.mark.parametrize("name", sorted(CALLBACK_CALLS))
def test_callback_raising_on_its_third_call_stops_the_call(name, small):
    cb, calls = raise_on_third_call()
    with pytest.raises(Third, match="stop at call 3"):
        CALLBACK_CALLS[name](small, cb)
    assert len(calls) == 3  # no report after the one that raised
    # The same call runs to the end afterwards, reporting as usual.
    seen = []
    CALLBACK_CALLS[name](small, lambda label, done, total: seen.append(done))
    assert len(seen) >= 3


def test_callback_raising_on_the_final_report_is_raised_too(small):
    def cb(label, done, total):
        if done == total and total > 0:
            raise Third("at the end")
    with pytest.raises(Third, match="at the end"):
        weft.window_stats(small.grid, "x", window=0.05, progress=cb)
    assert weft.window_stats(small.grid, "x", window=0.05).mean > 0


@pytest.mark.parametrize("sig, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_cli_ctrl_c_stops_without_a_half_written_file(sig, code, word, tmp_path, weft_bin):
    spec = tmp_path / "big.json"
    spec.write_text(repr(BIG_CLOTH).replace("'", '"'))
    out = tmp_path / "out"
    child = subprocess.Popen([weft_bin, "gen", "--config", str(spec), "--out", str(out)],
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(2.0)  # inside the generation: the big cloth takes over a minute
    assert child.poll() is None, "the big cloth finished in under 2 s: make it bigger"
    child.send_signal(sig)
    _, err = child.communicate(timeout=60)
    assert child.returncode == code, (child.returncode, err)
    assert err.replace("\r", "\n").rstrip().splitlines()[-1] == "weft: " + word, err
    left = sorted(p.name for p in out.rglob("*")) if out.exists() else []
    assert not any(name.endswith((".vdb", ".json")) or ".tmp" in name for name in left), left


@pytest.mark.parametrize("sig, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_cli_export_stops_without_a_file(sig, code, word, tmp_path, weft_bin):
    """`weft export` reports progress from its dense copy and its NanoVDB conversion and stops
    between its files: a signal leaves no file, whenever it comes (docs/export.md)."""
    g = weft.Grid(0.01)
    g.set_value(0, 0, 0, 0.5)
    g.set_value(511, 511, 255, 0.5)  # a 256 MiB dense .vol: about a second to copy and write
    g.save(tmp_path / "two.vdb")
    out = tmp_path / "out"
    child = subprocess.Popen([weft_bin, "export", "--grid", str(tmp_path / "two.vdb"), "--sigma", "2", "--out",
                              str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(0.3)
    assert child.poll() is None, "the export finished in under 0.3 s: make the box bigger"
    child.send_signal(sig)
    _, err = child.communicate(timeout=60)
    assert child.returncode == code, (child.returncode, err)
    assert err.replace("\r", "\n").rstrip().splitlines()[-1] == "weft: " + word, err
    assert not out.exists(), sorted(p.name for p in out.rglob("*"))


MATRIX_CHILD = textwrap.dedent("""
    import os, sys, time, weft
    def cb(label, done, total):
        # The first report inside the first case's renders (docs/render.md §6e: 1000 per case).
        if label == "study cases x1000" and 0 < done < 1000 and not getattr(cb, "said", False):
            cb.said = True
            print("in case", flush=True)
    try:
        weft.render_matrix(quick=True, cloths="plain", lightings="back", tilts=(45, 8), out=sys.argv[1],
                           progress=cb)
        print("finished uninterrupted", flush=True)
        sys.exit(3)
    except KeyboardInterrupt:
        print("interrupted", flush=True)
    print("stored %d" % len([n for n in os.listdir(os.path.join(sys.argv[1], "matrix.units"))
                             if n.startswith("unit-")]), flush=True)
""")


def test_ctrl_c_stops_the_matrix_inside_a_case(tmp_path):
    """Ctrl-C in the middle of a case's renders raises KeyboardInterrupt before the case ends:
    the case is not stored (docs/render.md §6e, docs/python.md)."""
    script = tmp_path / "matrix_child.py"
    script.write_text(MATRIX_CHILD)
    out = tmp_path / "m"
    child = subprocess.Popen([sys.executable, str(script), str(out)], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, env=child_env(), cwd=tmp_path)
    try:
        first = child.stdout.readline()
        assert first == "in case\n", first + child.stderr.read()
        child.send_signal(signal.SIGINT)
        sent = time.monotonic()
        rest, err = child.communicate(timeout=120)
        seconds = time.monotonic() - sent
    finally:
        if child.poll() is None:
            child.kill()
            child.wait()
    assert child.returncode == 0, "exit %d\n%s\n%s" % (child.returncode, rest, err)
    assert rest.splitlines() == ["interrupted", "stored 0"], rest + err
    assert "terminate called" not in err, err
    assert seconds < 30, "took %.1f s to stop" % seconds
    assert not list(out.glob("cases/*/reference.study.json"))


def test_cli_ctrl_c_in_the_matrix_keeps_the_finished_cases_for_resume(tmp_path, weft_bin):
    """`weft render --study` (the matrix) stopped by Ctrl-C in its second case: exit 130 at the
    case's next report, no aggregate file, no temporary and no half-written file, the first case
    stored; `--resume` takes it and renders the other (docs/render.md §6e)."""
    out = tmp_path / "m"
    args = [weft_bin, "--quiet", "render", "--study", "--quick", "--study-cloths", "plain", "--study-lightings", "back",
            "--study-tilts", "45,8", "--out", str(out)]
    child = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    units = out / "matrix.units"
    deadline = time.monotonic() + 240
    while time.monotonic() < deadline and child.poll() is None:
        if units.exists() and any(p.name.startswith("unit-") for p in units.iterdir()):
            break
        time.sleep(0.05)
    assert child.poll() is None, "the matrix ended before its first case was stored: %s" % child.communicate()[1]
    child.send_signal(signal.SIGINT)
    _, err = child.communicate(timeout=60)
    assert child.returncode == 130, (child.returncode, err)
    assert err.rstrip().splitlines()[-1] == "weft: interrupted", err
    left = sorted(p.name for p in out.rglob("*"))
    assert not any(name.startswith("matrix.") and name != "matrix.units" for name in left), left
    # The stop unwinds through the atomic writes, which remove their temporaries (docs/render.md
    # §6e, "Ranks, progress, resume").
    assert not any(".tmp" in name for name in left), left
    resumed = subprocess.run(args + ["--resume"], capture_output=True, text=True, timeout=300)
    assert resumed.returncode == 0, resumed.stderr
    assert (out / "matrix.json").exists()


SAMPLE_CHILD = textwrap.dedent("""
    import os, signal, sys, threading, time, weft
    law = weft.law("gamma", alpha=0.5, mean_extinction=1)
    start = time.monotonic()
    law.sample(1 << 22)
    rate = (1 << 22) / (time.monotonic() - start)
    n = 300_000_000
    # Ctrl-C 0.2 s into one call of n draws, which alone takes n / rate (~15 s on 2 cores).
    threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT)).start()
    start = time.monotonic()
    try:
        law.sample(n)
        print("finished uninterrupted")
    except KeyboardInterrupt:
        print("interrupted %.3f %.3f" % (time.monotonic() - start, n / rate), flush=True)
    print(law.sample(5).shape)
""")


def test_ctrl_c_stops_law_sample_inside_the_call(tmp_path):
    """One Law.sample call draws in chunks with progress reports, so Ctrl-C stops it at the next
    chunk, not when all n draws are done (docs/python.md "Interrupting a call")."""
    script = tmp_path / "sample_child.py"
    script.write_text(SAMPLE_CHILD)
    out = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, env=child_env(),
                         cwd=tmp_path, timeout=300)
    assert out.returncode == 0, out.stdout + out.stderr
    first, second = out.stdout.splitlines()
    word, stopped_at, whole_call = first.split()
    assert word == "interrupted", out.stdout
    assert float(whole_call) > 2.0, "n draws take only %s s: draw more" % whole_call
    assert float(stopped_at) < 0.2 + 1.0 < float(whole_call) / 2, first
    assert second == "(5,)"


@pytest.mark.parametrize("sig, code, word", [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")])
def test_cli_model_sample_stops_at_a_signal(sig, code, word, tmp_path, weft_bin):
    """`weft model --sample N` prints its draws chunk by chunk, each chunk a progress report: a
    signal stops it there with the usual exit, instead of after all N (docs/architecture.md
    "Progress and cancellation"). Standard output is a stream: the chunks printed before stay."""
    out = tmp_path / "samples.txt"
    with open(out, "w") as stdout:
        child = subprocess.Popen([weft_bin, "model", "--law", "gamma", "--alpha", "0.5", "--mean-extinction", "1",
                                  "--sample", "1000000000"], stdout=stdout, stderr=subprocess.PIPE, text=True)
        time.sleep(1.0)
        assert child.poll() is None, "1e9 samples printed in under 1 s"
        printed = out.stat().st_size
        child.send_signal(sig)
        sent = time.monotonic()
        _, err = child.communicate(timeout=120)
        seconds = time.monotonic() - sent
    assert child.returncode == code, (child.returncode, err)
    assert err.replace("\r", "\n").rstrip().splitlines()[-1] == "weft: " + word, err
    assert seconds < 2.0, "took %.1f s to stop" % seconds
    lines = out.read_text().splitlines()
    assert printed > 0 and 0 < len(lines) < 1000000000
    float(lines[-1])  # whole lines only: a chunk is written whole before the next report
