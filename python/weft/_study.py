"""The coarse-cloth image study, its matrix and the baselines (docs/render.md §6c-§6e).

Thin calls of the library with the CLI's defaults (``weft render --study``). The results are the
library's own reports: every field of study.json / matrix.json is an attribute of the typed row
it belongs to, and ``to_dict()`` / ``to_json()`` are that JSON, so a column the library adds is
there without an edit here. Images are numpy arrays where the library holds them.
"""

import contextlib as _contextlib
import copy as _copy
import json as _json
import numbers as _numbers
import os as _os
import tempfile as _tempfile

_INT_MIN, _INT_MAX = -(2**31), 2**31 - 1  # a C++ int's range

from . import _weft
from . import ArgumentTypeError, Error, Grid, _flag, _path_or_none, _run, _scene_kind, _scene_with_files


class _Record:
    """One object of a report: its JSON fields as attributes (``row.bias``), ``to_dict()``."""

    def __init__(self, fields):
        if not isinstance(fields, dict):
            raise ArgumentTypeError("%s: fields must be a dict (a report's JSON object), got %s"
                                    % (type(self).__name__, type(fields).__name__))
        object.__setattr__(self, "_fields", fields)

    def __getattr__(self, name):
        fields = self.__dict__.get("_fields", {})
        if name in fields:
            return fields[name]
        raise AttributeError("weft.%s has no field %r (it has: %s)" % (type(self).__name__, name,
                                                                      ", ".join(sorted(fields))))

    def __setattr__(self, name, value):
        raise AttributeError("weft.%s is read-only" % type(self).__name__)

    def __dir__(self):
        return sorted(set(super().__dir__()) | set(self._fields))

    def __eq__(self, other):
        return type(self) is type(other) and self._fields == other._fields

    __hash__ = None

    def fields(self):
        """The names of the JSON fields, in the report's order."""
        return list(self._fields)

    def to_dict(self):
        """The JSON object of the report (a copy)."""
        return _copy.deepcopy(self._fields)


def _scalars(fields):
    return {k: v for k, v in fields.items() if not isinstance(v, (list, dict))}


def _named(records, key, name, what):
    """The record whose field ``key`` is ``name``; a KeyError listing the names otherwise."""
    for r in records:
        if r._fields[key] == name:
            return r
    raise KeyError("no %s %r (%ss: %s)" % (what, name, what, ", ".join(r._fields[key] for r in records)))


class StudyCandidate(_Record):
    """A candidate of the image study (study.json's ``candidates[i]``): ``name``, ``model``,
    ``factor``, ``spp``, ``bias``, ``bias_sq``, ``bias_sq_stderr``, ``bias_z``, ``rmse``,
    ``noise``, ``cloth_bias`` ..., ``memory_bytes``, ``cpu_seconds``, ``speedup``,
    ``fitted_to_images``, ``uses_ground_truth``, ``curve``; ``image`` (A) and ``error_map``
    (|A - R|) as float32 arrays (H, W, 3)."""

    def __init__(self, fields, image, error_map):
        super().__init__(fields)
        object.__setattr__(self, "_image", image)
        object.__setattr__(self, "_error_map", error_map)

    @property
    def image(self):
        return self._image

    @property
    def error_map(self):
        return self._error_map

    def __repr__(self):
        f = self._fields
        return "<weft.StudyCandidate %s: %d spp, bias %.4g (z %.3g), rmse %.4g, noise %.4g, %d bytes%s>" % (
            f["name"], f["spp"], f["bias"], f["bias_z"], f["rmse"], f["noise"], f["memory_bytes"],
            ", fitted to images" if f.get("fitted_to_images") else "")


class AlbedoFit(_Record):
    """One coarsening level's albedo multiplier (study/albedo_fit.h): ``factor``, ``k``,
    ``target``, ``fitted``, ``tolerance``, ``renders``, ``converged``; fitted to images of the
    fine grid, so ``fitted_to_images`` and ``uses_ground_truth`` are True."""

    def __repr__(self):
        f = self._fields
        return "<weft.AlbedoFit %dx: k %.6g, %s after %d renders, fitted to images>" % (
            f["factor"], f["k"], "converged" if f["converged"] else "not converged", f["renders"])


class StudyResult(_Record):
    """What ``weft.render_study`` returns: the fields of ``weft render --study``'s study.json
    (``mode``, ``headline``, ``reference``, ``best_by_ground_truth`` (chosen with the ground truth,
    also under its former key ``best_predictive``), ``slab_law``, ``notes``) as attributes,
    ``candidates`` (StudyCandidate, also ``result["exponential-2x"]``), the images
    (``reference_image``, ``reference_variance``: float32 (H, W, 3); ``cloth_mask``: bool (H, W)),
    ``albedo_fits`` (with ``albedo="fit"``), ``to_json()`` (study.json's text), ``csv`` and
    ``curves_csv`` (its .study.csv and .study.curves.csv), ``rows()`` (a table)."""

    def __init__(self, out):
        if not isinstance(out, dict) or "json" not in out:
            raise ArgumentTypeError("%s: out must be the binding's result (weft.render_study and weft.render_matrix "
                                    "make these), got %s" % (type(self).__name__, type(out).__name__))
        super().__init__(_json.loads(out["json"]))
        objects = {
            "_text": out["json"],
            "_candidates": [StudyCandidate(c, image, error) for c, image, error in
                            zip(self._fields["candidates"], out["images"], out["error_maps"])],
            "_reference": out["reference"],
            "_variance": out["reference_variance"],
            "_mask": out["cloth_mask"],
            "_fits": [AlbedoFit(f) for f in out["albedo_fits"]],
            "_csv": out["csv"],
            "_curves": out["curves_csv"],
        }
        for name, value in objects.items():
            object.__setattr__(self, name, value)

    candidates = property(lambda self: list(self._candidates), doc="The candidates, in the report's order.")
    reference_image = property(lambda self: self._reference, doc="The reference R, float32 (H, W, 3).")
    reference_variance = property(lambda self: self._variance, doc="Per-pixel variance of R's mean.")
    cloth_mask = property(lambda self: self._mask, doc="The cloth's pixels, bool (H, W) (docs/render.md §6c).")
    albedo_fits = property(lambda self: list(self._fits), doc="The albedo fits (albedo='fit'), else [].")
    csv = property(lambda self: self._csv, doc="The study's CSV, one row per candidate.")
    curves_csv = property(lambda self: self._curves, doc="RMSE against spp and seconds per candidate.")

    def to_json(self):
        """study.json's text, from the library's writer."""
        return self._text

    def rows(self):
        """One flat dict per candidate (its scalar fields): ``pandas.DataFrame(result.rows())``."""
        return [_scalars(c) for c in self._fields["candidates"]]

    def __getitem__(self, name):
        return _named(self._candidates, "name", name, "candidate")

    def __repr__(self):
        r = self._fields["reference"]
        return "<weft.StudyResult %d candidates, reference %d spp %dx%d, %d cloth pixels: %s>" % (
            len(self._candidates), r["spp"], r["width"], r["height"], r["cloth_pixels"], self._fields["headline"])


class MatrixCandidate(_Record):
    """A candidate in one case of the matrix (matrix.json's ``cases[i]["candidates"][j]``):
    ``name``, ``model``, ``factor``, ``spp``, ``cloth_bias``, ``cloth_bias_sq_stderr``,
    ``cloth_bias_z``, ``cloth_relative_bias``, ``cloth_rmse``, ``cloth_noise``, ``memory_bytes``,
    ``memory_ratio``, ``sample_cpu_seconds``, ``cost_ratio``, ``speedup`` (at RMSE 5 %),
    ``speedup_ceiling`` (at any RMSE), ``error_for_3x`` (the RMSE from which it is 3x faster,
    relative; None: never), ..."""

    def __repr__(self):
        f = self._fields
        return "<weft.MatrixCandidate %s: cloth bias %.4g (%.1f%%, z %.3g), rmse %.4g, %d bytes>" % (
            f["name"], f["cloth_bias"], 100.0 * f["cloth_relative_bias"], f["cloth_bias_z"], f["cloth_rmse"],
            f["memory_bytes"])


class MatrixCase(_Record):
    """One cloth x lighting x view of the matrix (``case``, ``cloth``, ``lighting``, ``tilt``,
    ``fitted_on``, ``cloth_pixels``, ``cloth_mean``, ``albedo_factors``, ...) and its
    ``candidates`` (MatrixCandidate, also ``case["local-gamma-4x"]``)."""

    def __init__(self, fields):
        super().__init__(fields)
        object.__setattr__(self, "_candidates", [MatrixCandidate(c) for c in fields["candidates"]])

    candidates = property(lambda self: list(self._candidates), doc="The case's candidates, in order.")

    def __getitem__(self, name):
        return _named(self._candidates, "name", name, "candidate")

    def __repr__(self):
        f = self._fields
        return "<weft.MatrixCase %s: %d candidates, %d cloth pixels, mean %.4g%s>" % (
            f["case"], len(self._candidates), f["cloth_pixels"], f["cloth_mean"],
            ", albedo fitted here" if f["fitted_on"] else "")


class MatrixVerdict(_Record):
    """A representation of one cloth judged over its set-ups: ``name``, ``factor``,
    ``worst_relative_bias``, ``worst_case``, ``mean_relative_bias``, ``memory_ratio``,
    ``cost_ratio``, ``speedup``, ``speedup_ceiling``, ``error_for_3x`` (the worst over the
    set-ups)."""

    def __repr__(self):
        f = self._fields
        return "<weft.MatrixVerdict %s: worst cloth bias %.1f%% (%s), memory %.3gx>" % (
            f["name"], 100.0 * f["worst_relative_bias"], f["worst_case"], f["memory_ratio"])


class MatrixHeadline(_Record):
    """The verdict on one cloth: ``cloth``, ``judged_cases``, ``text``, ``best`` (per factor),
    ``representations`` (every coarse one) and ``resolution_floors`` (per factor), as MatrixVerdict."""

    best = property(lambda self: [MatrixVerdict(v) for v in self._fields["best"]],
                    doc="Per factor, the representation with the smallest worst-case bias.")
    representations = property(lambda self: [MatrixVerdict(v) for v in self._fields["representations"]],
                               doc="Every coarse representation, in candidate order.")
    resolution_floors = property(lambda self: [MatrixVerdict(v) for v in self._fields["resolution_floors"]],
                                 doc="Per factor, the resolution floor judged like a representation "
                                     "(docs/render.md §6e, 'The resolution floor').")

    def __repr__(self):
        f = self._fields
        return "<weft.MatrixHeadline %s, %d set-ups; least worst cloth bias: %s>" % (
            f["cloth"], f["judged_cases"],
            ", ".join("%s %.1f%%" % (v["name"], 100.0 * v["worst_relative_bias"]) for v in f["best"]))


class MatrixResult(_Record):
    """What ``weft.render_matrix`` returns: matrix.json's fields (``spec``, ``error_fraction``,
    ``memory``) as attributes, ``cases`` (MatrixCase, also ``result["plain-back-45deg"]``),
    ``headlines`` (MatrixHeadline), ``to_json()`` (matrix.json's text), ``csv``, ``cost_csv``
    and ``markdown`` (matrix.csv, matrix.cost.csv, matrix.md), ``rows()`` (a table)."""

    def __init__(self, out):
        if not isinstance(out, dict) or "json" not in out:
            raise ArgumentTypeError("%s: out must be the binding's result (weft.render_study and weft.render_matrix "
                                    "make these), got %s" % (type(self).__name__, type(out).__name__))
        super().__init__(_json.loads(out["json"]))
        for name, value in (("_text", out["json"]), ("_csv", out["csv"]), ("_cost", out["cost_csv"]),
                            ("_markdown", out["markdown"]), ("_resumed", out["resumed"]),
                            ("_cases", [MatrixCase(c) for c in self._fields["cases"]])):
            object.__setattr__(self, name, value)

    cases = property(lambda self: list(self._cases), doc="Every case, cloth x lighting x view in order.")
    headlines = property(lambda self: [MatrixHeadline(h) for h in self._fields["headlines"]],
                         doc="The headline of each cloth.")
    csv = property(lambda self: self._csv, doc="matrix.csv: per case and candidate, what timing does not change.")
    cost_csv = property(lambda self: self._cost, doc="matrix.cost.csv: time, cost per sample, speed-up.")
    markdown = property(lambda self: self._markdown, doc="matrix.md: the headline table and the goals.")
    resumed = property(lambda self: self._resumed, doc="How many cases were taken from out/matrix.units.")

    def to_json(self):
        """matrix.json's text, from the library's writer."""
        return self._text

    def rows(self):
        """One flat dict per case and candidate (the case's scalar fields, then the
        candidate's): ``pandas.DataFrame(result.rows())``."""
        return [dict(_scalars(case), **_scalars(c)) for case in self._fields["cases"] for c in case["candidates"]]

    def __getitem__(self, name):
        return _named(self._cases, "case", name, "case")

    def __repr__(self):
        spec = self._fields["spec"]
        return "<weft.MatrixResult %d cases (%s x %s x %s deg), %d candidates each, %d spp>" % (
            len(self._cases), ",".join(spec["cloths"]), ",".join(spec["lightings"]),
            ",".join("%g" % t for t in spec["tilts"]), len(self._cases[0].candidates) if self._cases else 0,
            spec["spp"])


# ---- arguments: Python values as the library's spec takes them; a wrong type is an ArgumentTypeError
# naming the argument, a bad value the library's check (a weft.Error naming it).

def _integer(call, name, value, low=_INT_MIN, high=_INT_MAX):
    if isinstance(value, bool) or not isinstance(value, _numbers.Integral):
        raise ArgumentTypeError("%s: %s must be an integer, got %s" % (call, name, type(value).__name__))
    value = int(value)
    # The study's integers are C++ ints (the seed a 64-bit unsigned): a value beyond its type is out
    # of range, not of the wrong type, as the binding's conversion would say. Inside the type, the
    # library's own limits speak (e.g. the study's spp).
    if value > high or (low is not None and value < low):  # low None: the caller refuses below
        raise Error("%s: %s is out of the range of its C++ integer type, got %d" % (call, name, value))
    return value


def _real(call, name, value):
    if isinstance(value, bool) or not isinstance(value, _numbers.Real):
        raise ArgumentTypeError("%s: %s must be a number, got %s" % (call, name, type(value).__name__))
    return float(value)


def _listed(call, name, value, item):
    """A comma-separated string or an iterable (a single number too) -> a list of item(...)."""
    if isinstance(value, str):
        value = [v.strip() for v in value.split(",")]
    elif isinstance(value, _numbers.Number):
        value = [value]
    try:
        values = list(value)
    except TypeError:
        raise ArgumentTypeError("%s: %s must be a list (or a comma-separated string), got %s"
                        % (call, name, type(value).__name__)) from None
    return [item(call, name, v) for v in values]


def _name(call, name, value):
    if not isinstance(value, str):
        raise ArgumentTypeError("%s: %s must be names, got %r" % (call, name, value))
    return value


def _integer_item(call, name, value):
    if isinstance(value, str):
        try:
            return int(value)
        except ValueError:
            raise ArgumentTypeError("%s: %s must be integers, got %r" % (call, name, value)) from None
    return _integer(call, name, value)


def _real_item(call, name, value):
    if isinstance(value, str):
        try:
            return float(value)
        except ValueError:
            raise ArgumentTypeError("%s: %s must be numbers, got %r" % (call, name, value)) from None
    return _real(call, name, value)


def _albedo(call, albedo):
    """None, "fit", {factor: k} or [(factor, k), ...] -> (fit, pairs)."""
    if albedo is None:
        return False, None
    if isinstance(albedo, str):
        if albedo != "fit":
            raise Error("%s: albedo=%r: give 'fit', {factor: k} or [(factor, k), ...]" % (call, albedo))
        return True, None
    items = albedo.items() if isinstance(albedo, dict) else albedo
    try:
        return False, [(_integer(call, "albedo's factor", f), _real(call, "albedo's k", k)) for f, k in items]
    except (TypeError, ValueError):
        raise ArgumentTypeError("%s: albedo must be 'fit', {factor: k} or [(factor, k), ...], got %r" % (call, albedo)) from None


def _study_options(call, spp, reference_spp, factors, memory, window, seed, quick, components=None):
    o = {"quick": _flag(call + ": quick", quick)}
    if components is not None:
        o["components"] = _listed(call, "components", components, _name)
    if spp is not None:
        o["spp"] = _integer(call, "spp", spp)
    if reference_spp is not None:
        o["reference_spp"] = _integer(call, "reference_spp", reference_spp)
    if factors is not None:
        o["factors"] = _listed(call, "factors", factors, _integer_item)
    if memory is not None:
        o["memory"] = _listed(call, "memory", memory, _name)
    if window is not None:  # a name or a length, as fit::check_scale_text reads it
        o["window"] = window if isinstance(window, str) else repr(_real(call, "window", window))
    if seed is not None:
        seed = _integer(call, "seed", seed, None, 2**64 - 1)
        if seed < 0:
            raise Error("%s: seed=%d: must be >= 0" % (call, seed))
        o["seed"] = seed
    return o


@_contextlib.contextmanager
def _work_dir(call, out):
    """out: the folder for the study's grids, fields and scenes (created), or None: a temporary
    one removed after the call."""
    if out is None:
        with _tempfile.TemporaryDirectory(prefix="weft-study-") as folder:
            yield folder
        return
    if not isinstance(out, (str, _os.PathLike)):
        raise ArgumentTypeError("%s: out must be a folder path or None, got %s" % (call, type(out).__name__))
    # An empty or blank out= would put the files in the working folder or in one named " ": the
    # CLI's --out rule (weft::output_name_problem).
    _weft._check_output_name(out, call + ": out", True)
    folder = _os.path.abspath(_os.fspath(out))
    if _os.path.exists(folder) and not _os.path.isdir(folder):
        raise Error("%s: out=%r is a file, not a folder" % (call, _os.fspath(out)))
    created = []  # the folders made here, deepest first
    parent = folder
    while not _os.path.exists(parent) and parent != _os.path.dirname(parent):
        created.append(parent)
        parent = _os.path.dirname(parent)
    try:
        _os.makedirs(folder, exist_ok=True)
    except OSError as e:
        raise Error("%s: out=%r cannot be created: %s" % (call, _os.fspath(out), e.strerror or e)) from None
    try:
        yield folder
    except BaseException:
        # A failed call leaves no empty folder (docs/robustness.md), as weft::FolderRollback.
        for made in created:
            try:
                _os.rmdir(made)  # only an empty folder goes
            except OSError:
                break
        raise


def _scene_options(call, scene, base_dir, stack):
    if isinstance(scene, dict):
        scene = _scene_with_files(scene, stack)
    kind, text = _scene_kind(scene, call)
    return {"kind": kind, "text": text, "base_dir": _path_or_none(call + ": base_dir", base_dir) or ""}


def render_study(scene, *, spp=None, seconds=None, reference_spp=None, factors=None, memory=None, albedo=None,
                 window=None, components=None, seed=None, quick=False, base_dir=None, out=None, progress=None,
                 threads=None):
    """render_study(scene, *, spp=None, seconds=None, reference_spp=None, factors=None, ...) -> StudyResult

    ``weft render SCENE --study`` (docs/render.md §6c): coarse representations of the scene's one
    grid medium against the fine grid, with the same defaults and checks. ``scene`` is a scene
    file, a built-in scene's name or a dict (a Grid object as a medium's "file": e.g.
    ``weft.gen().scene(lighting="back")``). The keywords are the CLI's options:
    ``spp`` (--study-spp: every candidate at this spp, deterministic) or ``seconds``
    (--study-time: wall seconds per candidate image; default 10, 1 with quick),
    ``reference_spp`` (default 1024, 256 with quick), ``factors`` (--study-factors, default
    (2, 4, 8, 16)), ``memory`` (--study-memory: the local-gamma candidates' rules, default
    ("optical-depth",)), ``albedo`` (--study-albedo: "fit" fits k_N on this scene, or {factor: k}
    fitted elsewhere; those candidates are ``fitted_to_images``), ``window`` (--study-window,
    default "yarn"), ``components`` (--study-components: the candidate families, e.g.
    ("exponential",), also rendered as transmission, single and multiple scattering; default
    none), ``seed`` (default the scene's), ``quick`` (a film of 48 px on its longest
    side). ``out``: the folder for the candidates' grids, fields and scene files (a temporary
    one, removed after the call, when None: the ``scene`` paths in the result then name removed
    files). Same numbers as the CLI for the same seed and spp, for any ``threads=``."""
    call = "render_study"
    fit, pairs = _albedo(call, albedo)
    options = _study_options(call, spp, reference_spp, factors, memory, window, seed, quick, components)
    if seconds is not None:
        options["seconds"] = _real(call, "seconds", seconds)
    if pairs is not None:
        options["albedo"] = pairs
    options["fit_albedo"] = fit
    with _contextlib.ExitStack() as stack:
        options.update(_scene_options(call, scene, base_dir, stack))
        folder = stack.enter_context(_work_dir(call, out))
        return StudyResult(_run(lambda p: _weft._render_study(options, folder, p), threads, progress))


def fit_albedo(scene, *, factors=None, spp=None, reference_spp=None, seed=None, quick=False, base_dir=None,
               out=None, progress=None, threads=None):
    """fit_albedo(scene, *, factors=None, spp=None, reference_spp=None, seed=None, ...) -> [AlbedoFit]

    The albedo multiplier k_N of each coarsening level N fitted on ``scene`` (docs/render.md §6d
    (b); study::fit_albedo): the exponential-N x grid with albedo x k_N renders as bright as the
    fine grid at ``reference_spp``. Fitted to images of the fine grid, so every result says
    ``fitted_to_images`` and ``uses_ground_truth``; pass ``{f.factor: f.k for f in fits}`` as
    ``albedo=`` of ``render_study`` on another scene to judge it out of sample. Defaults as
    ``render_study`` (``spp`` None: 16 per coarse render)."""
    call = "fit_albedo"
    options = _study_options(call, spp, reference_spp, factors, None, None, seed, quick)
    with _contextlib.ExitStack() as stack:
        options.update(_scene_options(call, scene, base_dir, stack))
        folder = stack.enter_context(_work_dir(call, out))
        return [AlbedoFit(f) for f in _run(lambda p: _weft._fit_albedo(options, folder, p), threads, progress)]


def render_matrix(*, cloths=None, lightings=None, tilts=None, film=None, yarns=None, spp=None, reference_spp=None,
                  factors=None, memory=None, window=None, components=None, seed=None, quick=False, out=None,
                  resume=False, progress=None, threads=None):
    """render_matrix(*, cloths=None, lightings=None, tilts=None, film=None, ...) -> MatrixResult

    ``weft render --study`` with no scene (docs/render.md §6e): the study on every cloth x light
    set-up x view, with the CLI's defaults and checks. Keywords: ``cloths`` (--study-cloths,
    default ("plain", "twill22", "stockinette")), ``lightings`` (--study-lightings, default
    ("back", "front", "grazing")), ``tilts`` (--study-tilts, default (45, 8)), ``film``
    (--study-film, (width, height), default (96, 72)), ``yarns`` (--study-yarns, default 4),
    ``spp`` (--study-spp, default 64), ``reference_spp`` (default 1024), ``factors`` (default
    (2, 4, 8)), ``memory`` (default ("optical-depth", "segment")), ``window``, ``components`` (as
    ``render_study``'s), ``seed`` (default 1), ``quick`` (2 x 2 yarns at 20 um, a 32 x 24 film, 8 spp, a 128 spp reference). The
    albedo-corrected candidates are fitted per cloth on its first set-up (``fitted_on``).
    ``out``: the folder of the cases' files, the cloths and the finished cases
    (``out/matrix.units``; ``resume=True`` takes those of the same spec, as --resume); None: a
    temporary folder removed after the call. Same numbers as the CLI for any ``threads=``
    (timings aside)."""
    call = "render_matrix"
    options = _study_options(call, spp, reference_spp, factors, memory, window, seed, quick, components)
    if cloths is not None:
        options["cloths"] = _listed(call, "cloths", cloths, _name)
    if lightings is not None:
        options["lightings"] = _listed(call, "lightings", lightings, _name)
    if tilts is not None:
        options["tilts"] = _listed(call, "tilts", tilts, _real_item)
    if film is not None:
        try:
            width, height = film
        except (TypeError, ValueError):
            raise ArgumentTypeError("%s: film must be (width, height), got %r" % (call, film)) from None
        options["film"] = (_integer(call, "film's width", width), _integer(call, "film's height", height))
    if yarns is not None:
        options["yarns"] = _integer(call, "yarns", yarns)
    resume = _flag(call + ": resume", resume)
    if resume and out is None:
        raise Error("%s: resume=True needs out= (the folder whose matrix.units holds the finished cases)" % call)
    with _work_dir(call, out) as folder:
        return MatrixResult(_run(lambda p: _weft._render_matrix(options, folder, out is not None, resume, p),
                                 threads, progress))


def shadowed_downsample(grid, factor, sigma=None):
    """shadowed_downsample(grid, factor, sigma=None) -> ShadowedGrids

    The grid ``factor`` x coarser with each coarse voxel's extinction corrected for the
    self-shadowing inside its block (docs/render.md §6d (c); volume::shadowed_downsample): per
    axis a (``.per_axis``) the value whose extinction through the block along a transmits the
    block's mean transmittance along a, and ``.isotropic`` their mean (what the study's
    ``shadow-corrected-Nx`` renders). Values stay concentrations; sigma (extinction per unit
    concentration) from the grid's provenance unless given (values that are extinction: 1).
    Predicted from the voxels alone: nothing is fitted to images."""
    if not isinstance(grid, Grid):
        raise ArgumentTypeError("shadowed_downsample: grid must be a weft.Grid, got %s" % type(grid).__name__)
    factor = _integer("shadowed_downsample", "factor", factor)
    if sigma is not None:
        sigma = _real("shadowed_downsample", "sigma", sigma)
    return _weft._shadowed_downsample(grid, factor, sigma)


def downsample(grid, factor):
    """downsample(grid, factor) -> Grid

    The grid ``factor`` x coarser, each coarse voxel the mean of its block (inactive voxels 0;
    volume::downsample): linear downsampling, the study's ``exponential-Nx`` (docs/render.md §6c)."""
    if not isinstance(grid, Grid):
        raise ArgumentTypeError("downsample: grid must be a weft.Grid, got %s" % type(grid).__name__)
    return _weft._downsample(grid, _integer("downsample", "factor", factor))


__all__ = ["AlbedoFit", "MatrixCandidate", "MatrixCase", "MatrixHeadline", "MatrixResult", "MatrixVerdict",
           "StudyCandidate", "StudyResult", "downsample", "fit_albedo", "render_matrix", "render_study",
           "shadowed_downsample"]
