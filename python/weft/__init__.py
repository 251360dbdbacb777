"""weft: how light gets through cloth, from Python.

Transmittance laws (``weft.law``), sparse voxel grids (``weft.Grid``), ground truth by DDA
(``weft.measure_beam``), window statistics and gamma fits, the procedural cloth generator
(``weft.gen``) and the volumetric path tracer (``weft.render``). Every bad input raises
``weft.Error`` with weft's one-line message (or ``TypeError`` for a value of the wrong type).
Long calls release the GIL and take ``progress=callable(label, done, total)``.
See docs/python.md.
"""

import json as _json
import os as _os

from ._weft import *  # noqa: F401,F403  (the compiled bindings)
from ._weft import Error, Grid, _gen_json, _render, _validate_json


def validate(grid, sigma=None, window="yarn", axes="x,y,z", rays_per_column=1, seed=1, progress=None):
    """The main job on a grid, as ``weft validate --grid`` computes it: sigma from the grid's
    provenance unless given, the statistics scale ``window`` (yarn, yarn-measured, corr, extent or a
    length), ground truth per axis, the paper's gamma law and every predictive model. Returns the
    science part of report.json as Python objects: ``["axes"][i]["errors"][model]["rms_abs_T"]``,
    ``["axes"][i]["models"][model]["uses_ground_truth"]``, ``["axes"][i]["predicted"]`` (the one
    prediction), ``["axes"][i]["best_by_ground_truth"]`` (a diagnostic chosen with T_gt), ..."""
    return _json.loads(_validate_json(grid, sigma=sigma, window=window, axes=axes,
                                      rays_per_column=rays_per_column, seed=seed, progress=progress))

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
        self.grid = built["grid"]
        self.fibers = built["fibers"]
        self.report = built["report"]
        self.spec = _json.loads(built["spec_json"])

    def __repr__(self):
        return "<weft.Cloth %s, %d fibres, %d active voxels>" % (
            self.spec.get("pattern"), len(self.fibers["radius"]), self.grid.active_voxel_count)


def gen(spec=None, progress=None):
    """gen(spec=None, progress=None) -> Cloth

    Generates procedural cloth and voxelizes it, exactly as ``weft gen --config spec.json``:
    ``spec`` is a dict of the cloth.json fields (docs/cloth.md; missing fields take their
    defaults, e.g. ``{"pattern": "twill22", "warp_count": 6, "seed": 3}``), or None for the
    default cloth of ``weft gen``. Same seed, same grid as the CLI."""
    if spec is not None and not isinstance(spec, dict):
        raise TypeError("gen: spec must be a dict (the fields of cloth.json) or None, got %s"
                        % type(spec).__name__)
    text = None if spec is None else _dumps(spec, "gen")
    return Cloth(_gen_json(text, progress))


def render(scene, spp=None, seed=None, integrator="auto", time_budget=0.0, stats=False,
           base_dir=None, progress=None):
    """render(scene, spp=None, seed=None, integrator="auto", ...) -> numpy float32 (H, W, 3)

    Renders a scene with weft's path tracer (docs/render.md): ``scene`` is a scene file path,
    the name of a built-in scene (``weft.builtin_scene_names()``) or a dict of the scene JSON
    (docs/scene-format.md; relative file names resolve against ``base_dir``, default the current
    folder). ``spp``/``seed`` override the scene's. Linear RGB, rows from the top. With
    ``stats=True`` returns ``(image, stats)`` where stats holds the per-pixel ``variance`` of the
    mean and the run's counters. Same pixels as ``weft render`` for the same seed and spp."""
    if isinstance(scene, dict):
        kind, text = "dict", _dumps(scene, "render")
    elif isinstance(scene, (str, _os.PathLike)):
        text = _os.fspath(scene)
        looks_like_file = _os.path.exists(text) or "/" in text or text.endswith(".json")
        kind = "file" if looks_like_file else "builtin"
    else:
        raise TypeError("render: scene must be a path, a built-in scene name or a dict, got %s"
                        % type(scene).__name__)
    if base_dir is not None:
        base_dir = _os.fspath(base_dir)
    return _render(kind, text, base_dir or "", spp, seed, integrator, float(time_budget), bool(stats), progress)


def _dumps(value, what):
    try:
        return _json.dumps(value, allow_nan=False)
    except (TypeError, ValueError) as e:
        raise Error("%s: the spec is not JSON-serializable: %s" % (what, e)) from None


__all__ = [name for name in dir() if not name.startswith("_")]
