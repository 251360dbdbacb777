"""A command that writes a folder either completes, every file it wrote new, or leaves the folder
as it was: an interrupted run into a folder that holds an earlier run's files puts back every
file it had replaced and removes every file it had added (docs/robustness.md "Output folders of
failed runs", weft::FolderRollback). The signal comes once the run has replaced one of the
earlier files and has others still to write: half-way through its files."""
import hashlib
import json
import os
import signal
import subprocess
import time

import pytest

import weft

SMALL_CLOTH = {"pattern": "plain", "warp_count": 2, "weft_count": 2, "voxel_size": 0.02, "seed": 5,
               "warp_yarn": {"fiber_count": 12}, "weft_yarn": {"fiber_count": 12}}


def snapshot(folder):
    """Every file under `folder` with its bytes' digest and its inode (a file written anew by a
    rename has a new inode even with the same bytes), and every subfolder."""
    files = {}
    for root, dirs, names in os.walk(folder):
        for d in dirs:
            files[os.path.relpath(os.path.join(root, d), folder) + "/"] = "folder"
        for n in names:
            p = os.path.join(root, n)
            with open(p, "rb") as f:
                files[os.path.relpath(p, folder)] = (hashlib.md5(f.read()).hexdigest(), os.stat(p).st_ino)
    return files


def replaced_one(folder, before):
    """True once the run has replaced one of the earlier run's files (a new inode by that name)."""
    for name, was in before.items():
        if was != "folder":
            try:
                if os.stat(os.path.join(folder, name)).st_ino != was[1]:
                    return True
            except FileNotFoundError:
                pass
    return False


def interrupted_after_replacing_one(args, out):
    before = snapshot(out)
    child = subprocess.Popen(args, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while child.poll() is None and not replaced_one(out, before) and time.monotonic() < deadline:
        time.sleep(0.0005)
    assert child.poll() is None, "the run ended before it was seen writing: give it more to write"
    child.send_signal(signal.SIGINT)
    _, err = child.communicate(timeout=120)
    return before, child.returncode, err


def check_all_or_nothing(args, out):
    subprocess.run(args, check=True, capture_output=True)  # the earlier run's files
    before, code, err = interrupted_after_replacing_one(args, out)
    assert code == 130, err
    assert err.rstrip().splitlines()[-1] == "weft: interrupted", err
    assert snapshot(out) == before  # every earlier file, byte for byte and the same file; nothing added
    subprocess.run(args, check=True, capture_output=True)
    after = snapshot(out)
    assert after.keys() == before.keys()
    renewed = [k for k, v in before.items() if v != "folder" and after[k][1] == v[1]]
    assert not renewed, f"files the completed run did not write anew: {renewed}"


@pytest.fixture(scope="module")
def small_cloth(tmp_path_factory, weft_bin):
    folder = tmp_path_factory.mktemp("cloth")
    spec = folder / "small.json"
    spec.write_text(json.dumps(SMALL_CLOTH))
    subprocess.run([weft_bin, "gen", "--config", str(spec), "--out", str(folder)], check=True, capture_output=True)
    return folder


def test_export_into_an_earlier_export(tmp_path, weft_bin):
    g = weft.Grid(0.01)
    g.set_value(0, 0, 0, 0.5)
    g.set_value(511, 511, 127, 0.5)  # a 128 MiB dense .vol: the writes take a while
    g.save(tmp_path / "two.vdb")
    out = tmp_path / "out"
    check_all_or_nothing([weft_bin, "export", "--grid", str(tmp_path / "two.vdb"), "--sigma", "2", "--out", str(out)],
                         out)


def test_gen_into_an_earlier_gen(tmp_path, weft_bin):
    spec = tmp_path / "medium.json"
    spec.write_text(json.dumps({"pattern": "plain", "warp_count": 6, "weft_count": 6, "voxel_size": 0.01, "seed": 2}))
    out = tmp_path / "out"
    check_all_or_nothing([weft_bin, "gen", "--config", str(spec), "--write", "grid,fibers,yarns,config", "--out",
                          str(out)], out)


def test_render_study_into_an_earlier_study(tmp_path, weft_bin, small_cloth):
    out = tmp_path / "out"
    check_all_or_nothing([weft_bin, "render", str(small_cloth / "scene.json"), "--study", "--quick", "--study-spp", "1",
                          "--study-factors", "2", "--reference-spp", "64", "--out", str(out)], out)


def test_render_convergence_into_an_earlier_one(tmp_path, weft_bin, small_cloth):
    """The reference is written before the series is rendered: a stop in the series puts the
    earlier reference back."""
    out = tmp_path / "out"
    check_all_or_nothing([weft_bin, "render", str(small_cloth / "scene.json"), "--convergence", "auto", "--quick",
                          "--spp", "128", "--reference-spp", "16", "--out", str(out)], out)


def test_a_file_size_limit_is_an_error_naming_the_file(tmp_path, weft_bin, small_cloth):
    """`ulimit -f` makes the kernel stop a file at the limit and send SIGXFSZ, whose default action
    kills the process; weft ignores it, so the write fails and is reported like a full disk: exit
    1, one line naming the file, and the folder as it was (docs/robustness.md "Short writes"). The
    child starts with the default action (Python ignores SIGXFSZ, and exec keeps an ignored one)."""
    import resource

    out = tmp_path / "out"
    args = [weft_bin, "gen", "--config", str(small_cloth / "small.json"), "--write", "grid,config", "--out", str(out)]
    subprocess.run(args, check=True, capture_output=True)
    before = snapshot(out)
    grid_bytes = os.path.getsize(out / "cloth.vdb")

    def limited():
        signal.signal(signal.SIGXFSZ, signal.SIG_DFL)
        resource.setrlimit(resource.RLIMIT_FSIZE, (grid_bytes // 2, resource.RLIM_INFINITY))

    run = subprocess.run(args, capture_output=True, text=True, preexec_fn=limited)
    assert run.returncode == 1, (run.returncode, run.stderr)
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"weft: error: cannot write '{out / 'cloth.vdb'}'"), run.stderr
    assert snapshot(out) == before


def test_a_short_vti_write_fails_the_validate_run(tmp_path, weft_bin, small_cloth):
    """validate's cloth.vti is optional only for a grid it cannot hold: a write that fails (a file
    size limit between the other files' sizes and the .vti's) fails the run, with one line, and
    leaves the folder as it was."""
    import resource

    out = tmp_path / "out"
    args = [weft_bin, "validate", "--grid", str(small_cloth / "cloth.vdb"), "--sigma", "2", "--window", "extent",
            "--no-plot", "--out", str(out)]
    subprocess.run(args, check=True, capture_output=True)
    before = snapshot(out)
    vti = os.path.getsize(out / "cloth.vti")
    others = max(os.path.getsize(out / n) for n in os.listdir(out) if n != "cloth.vti")
    limit = (vti + others) // 2
    assert others < limit < vti, (others, vti)

    def limited():
        signal.signal(signal.SIGXFSZ, signal.SIG_DFL)
        resource.setrlimit(resource.RLIMIT_FSIZE, (limit, resource.RLIM_INFINITY))

    run = subprocess.run(args, capture_output=True, text=True, preexec_fn=limited)
    assert run.returncode == 1, (run.returncode, run.stderr)
    assert run.stderr.strip().splitlines() == [f"weft: error: cannot write '{out / 'cloth.vti'}': File too large"]
    assert snapshot(out) == before


def xvfb_child(pid):
    """The pid of the Xvfb that the weft process `pid` started, or None."""
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open(f"/proc/{entry}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
            with open(f"/proc/{entry}/comm") as f:
                comm = f.read().strip()
        except OSError:
            continue
        if int(fields[1]) == pid and comm == "Xvfb":
            return int(entry)
    return None


def test_a_signal_to_the_process_group_while_drawing_stops_like_ctrl_c(tmp_path, weft_bin, small_cloth):
    """A terminal's Ctrl-C (and `timeout`, `kill -- -PGID`) signals the whole process group. The
    X server weft starts for its charts when there is no display is in a session of its own, so
    the signal stops the run as a Ctrl-C does (exit 130, the folder as it was) instead of killing
    the server under the run's charts (which crashed the run or ended it in Xlib's exit, with the
    folder half old, half new)."""
    out = tmp_path / "out"
    args = [weft_bin, "validate", "--grid", str(small_cloth / "cloth.vdb"), "--no-vti", "--out", str(out)]
    env = {k: v for k, v in os.environ.items() if k != "DISPLAY"}
    subprocess.run(args, check=True, capture_output=True, env=env)  # the earlier run's files
    before = snapshot(out)
    child = subprocess.Popen(args + ["--window", "extent"], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                             text=True, env=env, start_new_session=True)
    deadline = time.monotonic() + 120
    server = None
    while child.poll() is None and server is None and time.monotonic() < deadline:
        server = xvfb_child(child.pid)
        time.sleep(0.0005)
    if server is None:
        child.communicate(timeout=120)
        pytest.skip("the run ended before its X server was seen (a display of its own was reachable?)")
    assert os.getpgid(server) != os.getpgid(child.pid)  # out of weft's process group
    os.killpg(child.pid, signal.SIGINT)
    _, err = child.communicate(timeout=120)
    after = snapshot(out)
    if child.returncode == 0:  # the signal came after the last file was in place
        assert after.keys() == before.keys()
        assert all(after[k][1] != v[1] for k, v in before.items() if v != "folder")
    else:
        assert child.returncode == 130, err
        assert err.rstrip().splitlines()[-1] == "weft: interrupted", err
        assert after == before
