"""weft: how light gets through cloth, from Python.

Transmittance laws (``weft.law``), sparse voxel grids (``weft.Grid``), ground truth by DDA
(``weft.measure_beam``), window statistics and gamma fits, the procedural cloth generator
(``weft.gen``), the volumetric path tracer (``weft.render``) and the coarse-cloth image study
with its baselines (``weft.render_study``, ``weft.render_matrix``). Every bad input raises
``weft.Error`` with weft's one-line message naming the argument (a value of the wrong type:
``weft.ArgumentTypeError``, a ``weft.Error`` that is also a ``TypeError``).
Long calls release the GIL, take ``progress=callable(label, done, total)`` (or ``progress=True``
for a bar) and ``threads=N``. Warnings are ``weft.Warning`` (a ``UserWarning``). See docs/python.md.
"""

import contextlib as _contextlib
import functools as _functools
import inspect as _inspect
import json as _json
import math as _math
import numbers as _numbers
import os as _os
import sys as _sys
import time as _time
import tempfile as _tempfile

from . import _build_info


def _check_interpreter():
    """One line saying what to install or which Python to use, instead of a bare import error."""
    built = _build_info.python
    if tuple(_sys.version_info[:2]) != tuple(built):
        raise ImportError("weft was built for Python %d.%d (%s), this is Python %d.%d (%s): run it with that "
                          "interpreter, or build weft for this one (`%s -m pip install <weft checkout>`)"
                          % (built[0], built[1], _build_info.python_executable, _sys.version_info[0],
                             _sys.version_info[1], _sys.executable, _sys.executable))
    try:
        import numpy  # noqa: F401  (the bindings return numpy arrays)
    except ImportError:
        raise ImportError("weft needs numpy 1.x, which %s cannot import: install it (Debian: apt install "
                          "python3-numpy; in a venv: pip install 'numpy<2')" % _sys.executable) from None


_check_interpreter()

from . import _weft  # noqa: E402
from ._arguments import ArgumentTypeError, check_module as _check_module, check_public as _check_public  # noqa: E402

_check_module(_weft)  # every binding's bad arguments as weft.Error (weft/_arguments.py), before its names are taken
from ._weft import *  # noqa: E402,F401,F403  (the compiled bindings)
from ._weft import Error, Grid, LocalFields, _gen_json, _render, _validate_json  # noqa: E402

__version__ = _build_info.version


class _ProgressBar:
    """``progress=True``: a bar per stage on stderr, with tqdm when it is installed (never
    required), else the CLI's line (apps/terminal_progress.cpp): bar, percent, rate and ETA,
    rewritten in place at most every 0.1 s, and ``took`` when the stage ends."""

    _WIDTH = 30

    def __init__(self):
        try:
            import tqdm
            self._tqdm = tqdm.tqdm
        except ImportError:
            self._tqdm = None
        self._reset()

    def _reset(self):
        self._label, self._bar, self._total, self._done, self._start, self._drawn = None, None, 0, 0, 0.0, None

    def __call__(self, label, done, total):
        if label != self._label:
            self.close()
            self._label, self._total, self._start = label, total, _time.monotonic()
            if self._tqdm is not None:
                self._bar = self._tqdm(total=total, desc=label, leave=False, file=_sys.stderr)
        self._done = done
        if self._bar is not None:
            self._bar.update(done - self._bar.n)
            return
        now = _time.monotonic()
        if self._drawn is None or now - self._drawn >= 0.1 or done >= total:
            self._drawn = now
            self._draw(now, final=False)

    def _draw(self, now, final):
        elapsed = now - self._start
        total, done = self._total, self._done
        fraction = min(1.0, done / total) if total else 1.0
        filled = int(fraction * self._WIDTH)
        rate = done / elapsed if elapsed > 0 else 0.0
        # No rate before the first unit, so no estimate: "eta --", as the CLI.
        when = ("took %.1fs" % elapsed if final
                else "eta %.1fs" % ((total - min(done, total)) / rate) if rate > 0 else "eta --")
        _sys.stderr.write("\r%-22s [%s%s] %5.1f%% %10.3g/s  %s\x1b[K" % (
            self._label, "#" * filled, "." * (self._WIDTH - filled), 100.0 * fraction, rate, when))
        if final:
            _sys.stderr.write("\n")
        _sys.stderr.flush()

    def close(self):
        if self._bar is not None:
            self._bar.close()
        elif self._label is not None:
            self._draw(_time.monotonic(), final=True)
        self._reset()


def _run(fn, threads, progress):
    """Runs ``fn(progress)`` with at most ``threads`` worker threads (None: all cores) and the
    progress callback, ``True`` meaning a bar (_ProgressBar). Same numbers for any thread count."""
    if threads is not None:
        if isinstance(threads, bool) or not isinstance(threads, _numbers.Integral):
            raise ArgumentTypeError("threads must be a positive integer or None, got %s" % type(threads).__name__)
        if not 1 <= threads <= _weft._max_threads:
            raise Error("threads=%d: must be in [1, %d] (or None for every core), as the CLI's --threads"
                        % (threads, _weft._max_threads))
    bar = _ProgressBar() if progress is True else None
    callback = bar if bar is not None else (None if progress is False else progress)
    try:
        if threads is None:
            return fn(callback)
        return _weft._with_threads(int(threads), lambda: fn(callback))
    finally:
        if bar is not None:
            bar.close()


def _long_call(binding):
    """A compiled long call with ``threads=`` and ``progress=True`` added (docs/python.md)."""
    @_functools.wraps(binding)
    def call(*args, threads=None, progress=None, **kwargs):
        return _run(lambda p: binding(*args, progress=p, **kwargs), threads, progress)
    call.__doc__ = (binding.__doc__ or "") + ("\n\nthreads=N limits the worker threads (same result for any N); "
                                              "progress=True shows a bar (tqdm when installed).")
    signature = getattr(binding, "__signature__", None)
    if signature is not None:
        threads = _inspect.Parameter("threads", _inspect.Parameter.KEYWORD_ONLY, default=None)
        call.__signature__ = signature.replace(parameters=[*signature.parameters.values(), threads])
    call._weft_checked = True  # the binding checks its arguments (weft/_arguments.py), _run threads=
    return call


def _with_progress(method):
    """A compiled method that draws in one thread, with ``progress=True`` (a bar) added."""
    @_functools.wraps(method)
    def call(self, *args, progress=None, **kwargs):
        return _run(lambda p: method(self, *args, progress=p, **kwargs), None, progress)
    call.__doc__ = (method.__doc__ or "") + "\n\nprogress=True shows a bar (tqdm when installed)."
    return call


_weft.Law.sample = _with_progress(_weft.Law.sample)
_weft.TransmittancePair.sample = _with_progress(_weft.TransmittancePair.sample)
measure_beam = _long_call(_weft.measure_beam)
measure_fibre_beam = _long_call(_weft.measure_fibre_beam)
measure_fields_beam = _long_call(_weft.measure_fields_beam)
window_stats = _long_call(_weft.window_stats)
correlation_length = _long_call(_weft.correlation_length)
local_fields = _long_call(_weft.local_fields)


def validate(grid, sigma=None, window="yarn", axes=("x", "y", "z"), rays_per_column=1, seed=1, progress=None,
             threads=None, models="all"):
    """The main job on a grid, as ``weft validate --grid`` computes it and with its checks: sigma
    from the grid's provenance unless given, the statistics scale ``window`` ("yarn",
    "yarn-measured", "corr", "extent" or a length such as ``window=0.3``), ground truth along
    ``axes`` (``("x", "z")``, ``"x,z"`` or ``(0, 2)``), the paper's gamma law and every predictive
    model, or only the ``models`` named (``--models``: "all", "predicted" — the prediction alone,
    the cheapest run —, or names such as ``("gamma", "local-gamma")``; the exponential baseline
    always). Returns the science part of report.json as Python objects:
    ``["axes"][i]["errors"][model]["rms_abs_T"]``, ``["axes"][i]["models"][model]["uses_ground_truth"]``,
    ``["axes"][i]["predicted"]`` (the one prediction), ``["axes"][i]["best_by_ground_truth"]`` (a diagnostic chosen with T_gt), ..."""
    if not isinstance(grid, Grid):
        raise ArgumentTypeError("validate: grid must be a weft.Grid, got %s" % type(grid).__name__)
    if sigma is not None:
        sigma = _number("validate: sigma", sigma)
    window, axes = _window_text(window), _axes_text(axes)
    models = _names_text("validate: models", models)
    rays_per_column = _integer("validate: rays_per_column", rays_per_column)
    seed = _integer("validate: seed", seed, 0, _MAX_SEED)
    text, curves, sigma_source, window_used = _run(
        lambda p: _validate_json(grid, sigma=sigma, window=window, axes=axes, rays_per_column=rays_per_column,
                                 seed=seed, models=models, progress=p), threads, progress)
    report = _json.loads(text)
    report["sigma_source"] = sigma_source
    report["window"] = window_used
    report["version"] = __version__
    for axis, curve in zip(report["axes"], curves):
        axis.update(curve)  # depth, T_gt, stderr (numpy) and T[model] (numpy, on the same depths)
    return report


def plot_validation(result, path=None, log=False):
    """Draws the validation's figure (as ``weft validate`` does) from what ``weft.validate``
    returned: per axis, the ground truth T_gt(t) with a band of 2 standard errors and every
    model's T(t). Needs matplotlib; returns the matplotlib Figure, saved to ``path`` if given."""
    if not isinstance(result, dict) or not isinstance(result.get("axes"), list):
        raise ArgumentTypeError("plot_validation: result must be what weft.validate returned, got %s"
                                % type(result).__name__)
    path = _path_or_none("plot_validation: path", path)
    if path is not None:
        _weft._check_output_name(path, "plot_validation: path", False)
    log = _flag("plot_validation: log", log)
    try:
        import matplotlib
        if path is not None:
            matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        raise ImportError("weft.plot_validation needs matplotlib: install it (Debian: apt install "
                          "python3-matplotlib; in a venv: pip install matplotlib)") from None
    axes = result["axes"]
    fig, panels = plt.subplots(1, len(axes), figsize=(4.5 * len(axes), 4), squeeze=False)
    for panel, axis in zip(panels[0], axes):
        t, gt, se = axis["depth"], axis["T_gt"], axis["stderr"]
        panel.fill_between(t, gt - 2 * se, gt + 2 * se, color="0.8", label="ground truth ± 2 s.e.")
        panel.plot(t, gt, "k", lw=2, label="ground truth (DDA)")
        for name, model in axis["T"].items():
            style = ":" if axis["models"].get(name, {}).get("uses_ground_truth") else "-"
            panel.plot(t, model, style, lw=1, label=name)
        panel.set_title("%s (window %s)" % (axis["axis"], result["window"]["rule"]))
        panel.set_xlabel("depth t")
        panel.set_ylabel("T(t)")
        if log:
            panel.set_yscale("log")
    panels[0][-1].legend(fontsize="small")
    fig.suptitle("weft %s, sigma %.4g (%s)" % (result["version"], result["sigma"], result["sigma_source"]))
    fig.tight_layout()
    if path is not None:
        fig.savefig(path)
    return fig


def _window_text(window):
    """A window as the library parses it (fit::check_scale_text): a name or a length."""
    if isinstance(window, str):
        return window
    return repr(_number("validate: window", window))


def _items(value, message):
    """A str as itself, any other iterable as the list of its items (its parts, comma-joined by
    the callers, go to the library's parser); ArgumentTypeError ``message % type`` otherwise."""
    if isinstance(value, str):
        return value
    try:
        return list(value)
    except TypeError:
        raise ArgumentTypeError(message % type(value).__name__) from None


def _axes_text(axes):
    """("x", "z"), "x,z", (0, 2) or "x" -> "x,z" (fit::parse_axes checks the names)."""
    kinds = "validate: axes must be names like ('x', 'z') or indices (0, 2), got %s"
    parts = _items(axes, kinds)
    if isinstance(parts, str):
        return parts
    out = []
    for a in parts:
        if type(a).__name__ in ("bool", "bool_") or not isinstance(a, (str, _numbers.Integral)):
            raise ArgumentTypeError(kinds % repr(a))
        if not isinstance(a, str):
            a = int(a)  # np.int64 too
        out.append(a if isinstance(a, str) else ("x", "y", "z")[a] if 0 <= a <= 2 else str(a))
    return ",".join(out)


def _names_text(what, names):
    """"a,b", ("a", "b") or "a" -> "a,b" (the library checks the names)."""
    kinds = what + " must be a name or a sequence of names (str), got %s"
    if isinstance(names, (bytes, bytearray)):
        raise ArgumentTypeError(kinds % type(names).__name__)  # its items would be ints
    parts = _items(names, kinds)
    if isinstance(parts, str):
        return parts
    for n in parts:
        if not isinstance(n, str):
            raise ArgumentTypeError("%s must be names (str), got %r" % (what, n))
    if not parts:
        raise Error("%s: no name given" % what)
    return ",".join(parts)


_MAX_SEED = 2**64 - 1  # seeds are unsigned 64-bit, as the CLI's --seed
_MAX_INT = 2**31 - 1  # a C int of the bindings


def _number(what, value):
    if isinstance(value, bool) or not isinstance(value, _numbers.Real):
        raise ArgumentTypeError("%s must be a number, got %s" % (what, type(value).__name__))
    return float(value)


def _flag(what, value):
    """True/False (numpy booleans, 0 and 1 too), else an ArgumentTypeError naming ``what``."""
    if type(value).__name__ in ("bool", "bool_") or (isinstance(value, _numbers.Integral) and value in (0, 1)):
        return bool(value)
    raise ArgumentTypeError("%s must be True or False, got %s" % (what, type(value).__name__))


def _path_or_none(what, value):
    """A folder or file path (str or os.PathLike) as text, or None."""
    if value is None:
        return None
    if not isinstance(value, (str, bytes, _os.PathLike)):
        raise ArgumentTypeError("%s must be a path (str, bytes or os.PathLike) or None, got %s"
                                % (what, type(value).__name__))
    return _os.fsdecode(value)


def _integer(what, value, low=0, high=_MAX_INT):
    """``value`` as an int in [low, high] (numpy integers too), else an ArgumentTypeError (not an
    integer) or weft.Error naming ``what``: the range is weft's (e.g. kMaxSpp), narrower than the
    C++ type's that weft/_arguments.py names."""
    if isinstance(value, bool) or not isinstance(value, _numbers.Integral):
        raise ArgumentTypeError("%s must be an integer, got %s" % (what, type(value).__name__))
    value = int(value)
    if value < low:
        raise Error("%s must be >= %d, got %d" % (what, low, value))
    if value > high:
        raise Error("%s must be <= %d, got %d" % (what, high, value))
    return value


def load_grid(path, name=""):
    """Reads the float grid ``name`` (default: the first) of a .vdb file (same as ``Grid.load``)."""
    return Grid.load(path, name)


class Cloth:
    """What ``weft.gen`` made: ``grid`` (fibre volume fraction C, provenance in ``grid.metadata``),
    ``fibers`` (dict of numpy arrays: ``points`` (N, 3) mm, ``offsets`` (polyline i is
    points[offsets[i]:offsets[i+1]]), ``radius``, ``yarn``, ``ply``, ``fiber``, ``kind``),
    ``report`` (volume conservation, timings) and ``spec`` (every parameter, resolved: the dict
    ``weft gen --config`` reads as cloth.json)."""

    def __init__(self, built):
        if not isinstance(built, dict) or not isinstance(built.get("grid"), Grid):
            raise ArgumentTypeError("Cloth: built must be what weft.gen's binding returns (use weft.gen), got %s"
                                    % type(built).__name__)
        self.grid = built["grid"]
        self.fibers = built["fibers"]
        self.report = built["report"]
        self.spec = _json.loads(built["spec_json"])

    def __repr__(self):
        return "<weft.Cloth %s, %d fibres, %d active voxels>" % (
            self.spec.get("pattern"), len(self.fibers["radius"]), self.grid.active_voxel_count)

    def scene(self, lighting="key-and-back", tilt=30.0, width=320, height=240):
        """The scene that shows this cloth (``weft.cloth_scene(self.grid, ...)``)."""
        return cloth_scene(self.grid, lighting=lighting, tilt=tilt, width=width, height=height)


_IN_MEMORY = "<weft.Grid in memory>"


def cloth_scene(grid, lighting="key-and-back", tilt=30.0, width=320, height=240):
    """cloth_scene(grid, lighting="key-and-back", tilt=30, width=320, height=240) -> dict

    The scene ``weft gen`` writes beside its grid (docs/render.md §5c; render/cloth_scene.h): the
    cloth grid as a grid medium with the provenance's sigma, framed by the camera, lit by
    ``lighting`` ("key-and-back", "back", "front" or "grazing"), the camera ``tilt`` degrees off
    the normal, a ``width`` x ``height`` film. The medium's "file" is the Grid object itself, so
    ``weft.render(scene)`` renders it as is; a grid without weft gen's provenance is a weft.Error."""
    if not isinstance(grid, Grid):
        raise ArgumentTypeError("cloth_scene: grid must be a weft.Grid, got %s" % type(grid).__name__)
    scene = _json.loads(_weft._cloth_scene_json(grid, _IN_MEMORY, lighting, _number("cloth_scene: tilt", tilt),
                                                _integer("cloth_scene: width", width),
                                                _integer("cloth_scene: height", height)))
    for medium in scene.get("media", {}).values():
        if medium.get("file") == _IN_MEMORY:
            medium["file"] = grid
    return scene


def gen(spec=None, progress=None, *, pattern=None, yarns=None, yarn=None, warp_yarn=None, weft_yarn=None,
        threads=None, **fields):
    """gen(spec=None, progress=None, *, pattern=None, yarns=None, yarn=None, voxel_size=..., ...) -> Cloth

    Generates procedural cloth and voxelizes it, exactly as ``weft gen``: ``spec`` is a dict of
    the cloth.json fields (docs/cloth.md; missing fields take their defaults), or None for the
    default cloth. Keywords say the same as ``weft gen``'s options and override ``spec``:
    ``pattern="twill22"``, ``yarns=(3, 3)`` (warp x weft counts), ``yarn="wool"`` (the preset of
    both directions, replacing their yarn entirely, as ``--yarn``), ``warp_yarn``/``weft_yarn``
    (a preset name or a dict of yarn fields), and any other cloth.json field by name
    (``voxel_size=0.01``, ``seed=3``, ``crimp=...``):
    ``weft.gen(pattern="twill22", yarns=(3, 3), yarn="wool", voxel_size=0.02)``. As with
    ``weft gen --input``, ``input="curves.obj"`` (or .bcc) makes the pattern "import"; a woven or
    knit pattern or ``yarns=`` with input curves is an error. Same seed, same grid as the CLI, for
    any ``threads=``."""
    if spec is not None and not isinstance(spec, dict):
        raise ArgumentTypeError("gen: spec must be a dict (the fields of cloth.json) or None, got %s"
                        % type(spec).__name__)
    given = {"pattern": pattern, "yarns": yarns, "yarn": yarn, "warp_yarn": warp_yarn, "weft_yarn": weft_yarn}
    if all(v is None for v in given.values()) and not fields and not (spec or {}).get("input"):
        text = None if spec is None else _dumps(spec, "gen")
        return Cloth(_run(lambda p: _gen_json(text, p), threads, progress))
    merged = dict(spec or {})  # missing fields: the defaults, those that follow the yarn resolved after it
    merged.update(fields)  # unknown names are refused by the spec parser, with its suggestions
    if fields.get("input") == "":
        # cloth.json writes "input": "" for no curves; a keyword that names none is a mistake, as
        # ``weft gen --input ""``, not a request for the default weave.
        raise Error("gen: input must name a curve file (.bcc or .obj), got an empty string")
    if pattern is not None:
        merged["pattern"] = pattern
    if yarns is not None:
        try:
            merged["warp_count"], merged["weft_count"] = yarns
        except (TypeError, ValueError):
            raise ArgumentTypeError("gen: yarns must be two counts (warp, weft), got %r" % (yarns,)) from None
    for key, value in (("warp_yarn", yarn), ("weft_yarn", yarn), ("warp_yarn", warp_yarn), ("weft_yarn", weft_yarn)):
        if value is not None:
            merged[key] = {"preset": value} if isinstance(value, str) else value
    if merged.get("input"):
        _import_curves(merged, yarns)
    text = _dumps(merged, "gen")
    return Cloth(_run(lambda p: _gen_json(text, p), threads, progress))


def _import_curves(merged, yarns):
    """As ``weft gen --input`` (docs/cloth.md, Patterns): curves make the pattern "import", and a
    woven or knit pattern, which would ignore them, or yarn counts, which an import ignores, are
    errors rather than silently dropped."""
    if not isinstance(merged["input"], (str, _os.PathLike)):
        raise ArgumentTypeError("gen: input must be a path, got %s" % type(merged["input"]).__name__)
    merged["input"] = _os.path.abspath(_os.fspath(merged["input"]))
    merged.setdefault("pattern", "import")
    if merged["pattern"] != "import":
        raise Error("gen: input=%r and pattern=%r conflict: a woven or knit pattern ignores input curves (give one)"
                    % (merged["input"], merged["pattern"]))
    if yarns is not None:
        raise Error("gen: yarns=%r conflicts with the imported curves %r: it only shapes woven and knit patterns"
                    % (yarns, merged["input"]))


def render(scene, spp=None, seed=None, integrator="auto", time_budget=0.0, stats=False,
           base_dir=None, progress=None, threads=None):
    """render(scene, spp=None, seed=None, integrator="auto", ...) -> numpy float32 (H, W, 3)

    Renders a scene with weft's path tracer (docs/render.md): ``scene`` is a scene file path,
    the name of a built-in scene (``weft.builtin_scene_names()``) or a dict of the scene JSON
    (docs/scene-format.md; relative file names resolve against ``base_dir``, an existing
    folder, default the current folder). ``spp``/``seed`` override the scene's. Linear RGB, rows from the top. With
    ``stats=True`` returns ``(image, stats)`` where stats holds the per-pixel ``variance`` of the
    mean and the run's counters. Same pixels as ``weft render`` for the same seed and spp, for any
    ``threads=``. In a dict, a grid medium's "file" may be a ``weft.Grid`` and a local-gamma
    medium's "fields" a ``weft.LocalFields``: they are written to a temporary folder for the
    render (the renderer reads its grids from files) and removed after it."""
    with _contextlib.ExitStack() as stack:
        if isinstance(scene, dict):
            scene = _scene_with_files(scene, stack)
        return _render_scene(scene, spp, seed, integrator, time_budget, stats, base_dir, progress, threads)


def _scene_with_files(scene, stack):
    """A copy of the scene dict with in-memory grids and fields written to a temporary folder."""
    media = scene.get("media")
    if not isinstance(media, dict):
        return scene
    folder = None
    out = dict(scene, media=dict(media))
    for name, medium in media.items():
        if not isinstance(medium, dict):
            continue
        for key, kind in (("file", Grid), ("fields", LocalFields)):
            value = medium.get(key)
            if isinstance(value, kind):
                # Named here: the renderer would name only the temporary file it reads.
                if kind is Grid and value.active_voxel_count == 0:
                    raise Error("render: media.%s.%s: the weft.Grid is empty (no active voxel)" % (name, key))
                if folder is None:
                    folder = stack.enter_context(_tempfile.TemporaryDirectory(prefix="weft-scene-"))
                path = _os.path.join(folder, "%s.%s.vdb" % (len(_os.listdir(folder)), key))
                value.save(path)
                out["media"][name] = dict(out["media"][name], **{key: path})
    return out


def _scene_kind(scene, what):
    """A scene as the bindings take it: ("dict", JSON text), ("file", path) or ("builtin", name)."""
    if isinstance(scene, dict):
        return "dict", _dumps(scene, what)
    if isinstance(scene, (str, _os.PathLike)):
        text = _os.fspath(scene)
        looks_like_file = _os.path.exists(text) or "/" in text or text.endswith(".json")
        return ("file" if looks_like_file else "builtin"), text
    raise ArgumentTypeError("%s: scene must be a path, a built-in scene name or a dict, got %s" % (what, type(scene).__name__))


def _render_scene(scene, spp, seed, integrator, time_budget, stats, base_dir, progress, threads):
    kind, text = _scene_kind(scene, "render")
    base_dir = _path_or_none("render: base_dir", base_dir)
    if base_dir is not None and not _os.path.isdir(base_dir):
        raise Error("render: base_dir %r is not a folder" % base_dir)
    time_budget = _number("render: time_budget", time_budget)
    if spp is not None:
        spp = _integer("render: spp", spp, 1, _weft._max_spp)
    if seed is not None:
        seed = _integer("render: seed", seed, 0, _MAX_SEED)
    return _run(lambda p: _render(kind, text, base_dir or "", spp, seed, integrator, time_budget,
                                  _flag("render: stats", stats), p), threads, progress)


def _plain(value, where):
    """``value`` with numpy scalars and arrays as Python numbers and lists (``.tolist()``), tuples
    as lists; a non-finite number raises weft.Error naming its key (``where``: "camera.position[1]"),
    which json.dumps' "Out of range float values" does not."""
    if isinstance(value, dict):
        return {k: _plain(v, "%s.%s" % (where, k) if where else str(k)) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v, "%s[%d]" % (where, i)) for i, v in enumerate(value)]
    if isinstance(value, (str, bool)) or value is None:
        return value
    if isinstance(value, _numbers.Integral):
        return int(value)
    if isinstance(value, _numbers.Real):
        if not _math.isfinite(value):
            raise Error("%s must be a finite number, got %r" % (where or "the value", float(value)))
        return float(value)
    if hasattr(value, "tolist") and hasattr(value, "dtype"):  # numpy arrays and scalars, without numpy
        return _plain(value.tolist(), where)
    return value  # json.dumps names what it cannot serialize


def _dumps(value, what):
    try:
        return _json.dumps(_plain(value, ""), allow_nan=False)
    except Error as e:
        raise Error("%s: %s" % (what, e)) from None
    except (TypeError, ValueError) as e:
        raise Error("%s: the spec is not JSON-serializable: %s" % (what, e)) from None


# The image study, its matrix and the baselines (docs/render.md §6c-§6e).
from ._study import *  # noqa: E402,F401,F403

# weft.Warning stays out of `from weft import *`, which would hide the built-in Warning.
__all__ = [name for name in dir() if not name.startswith("_") and name != "Warning"]
_check_public(globals(), __all__)  # the Python functions and classes too (weft/_arguments.py)
