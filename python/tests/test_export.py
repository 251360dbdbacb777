"""weft export: the Mitsuba .vol read back with numpy, both scene files checked against the
formats' documented structure (Mitsuba 3 plugin parameters; pbrt-v4 directives and the nanovdb
medium's parameters)."""

import math
import re
import struct
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest

import weft


def read_vol(path):
    """Mitsuba's gridvolume format (docs of src/volumes/grid.cpp), little endian."""
    data = open(path, "rb").read()
    assert data[:3] == b"VOL" and data[3] == 3
    encoding, nx, ny, nz, channels = struct.unpack("<5i", data[4:24])
    bbox = struct.unpack("<6f", data[24:48])
    values = np.frombuffer(data[48:], dtype="<f4")
    assert encoding == 1 and channels == 1 and values.size == nx * ny * nz
    # data[((z * yres + y) * xres + x)]: reshape (nz, ny, nx), then index as [x, y, z].
    return values.reshape(nz, ny, nx).transpose(2, 1, 0), bbox


@pytest.fixture(scope="module")
def exported(tmp_path_factory, small_cloth, run_cli):
    d = tmp_path_factory.mktemp("export")
    small_cloth.grid.save(d / "cloth.vdb")
    run_cli("export", "--grid", d / "cloth.vdb", "--out", d / "out", "--albedo", "0.9,0.8,0.7", "--g", "0.2",
            "--spp", 16)
    return d


def test_vol_values_and_bbox_match_the_vdb(exported):
    g = weft.load_grid(exported / "cloth.vdb")
    values, bbox = read_vol(exported / "out" / "mitsuba" / "cloth.vol")
    np.testing.assert_array_equal(values, g.to_numpy())  # float32, bit for bit
    (i0, j0, k0), (i1, j1, k1) = g.bbox
    o, h = g.origin, g.voxel_size
    expect = [o[0] + h * i0, o[1] + h * j0, o[2] + h * k0, o[0] + h * (i1 + 1), o[1] + h * (j1 + 1), o[2] + h * (k1 + 1)]
    np.testing.assert_allclose(bbox, np.float32(expect), rtol=0, atol=1e-6)


# Mitsuba 3 plugin parameters this exporter uses, with their documented types (mitsuba3 docs:
# integrator volpath, sensor perspective, film hdrfilm, sampler independent, emitter constant,
# medium heterogeneous, volume gridvolume, phase hg, shape cube, bsdf null).
MITSUBA_PLUGINS = {
    ("integrator", "volpath"): {"max_depth": "integer", "rr_depth": "integer", "hide_emitters": "boolean"},
    ("sensor", "perspective"): {"fov": "float", "fov_axis": "string", "to_world": "transform",
                                "near_clip": "float", "far_clip": "float"},
    ("sampler", "independent"): {"sample_count": "integer", "seed": "integer"},
    ("film", "hdrfilm"): {"width": "integer", "height": "integer", "file_format": "string",
                          "pixel_format": "string"},
    ("emitter", "constant"): {"radiance": "rgb"},
    ("medium", "heterogeneous"): {"albedo": "rgb", "sigma_t": "volume", "scale": "float",
                                  "sample_emitters": "boolean"},
    ("volume", "gridvolume"): {"filename": "string", "filter_type": "string", "wrap_mode": "string",
                               "to_world": "transform", "raw": "boolean"},
    ("phase", "hg"): {"g": "float"},
    ("shape", "cube"): {"to_world": "transform", "interior": "ref"},
    ("bsdf", "null"): {},
}
PROPERTY_TAGS = {"integer", "float", "string", "boolean", "rgb", "transform", "ref", "point", "vector", "spectrum"}


def check_mitsuba_object(el):
    key = (el.tag, el.get("type"))
    assert key in MITSUBA_PLUGINS, "unknown plugin %s" % (key,)
    params = MITSUBA_PLUGINS[key]
    for child in el:
        if child.tag in PROPERTY_TAGS:
            assert child.get("name") in params, "%s has no parameter %s" % (key, child.get("name"))
            assert params[child.get("name")] == child.tag, "%s.%s must be a %s" % (key, child.get("name"),
                                                                                   params[child.get("name")])
            if child.tag in ("integer", "float"):
                float(child.get("value"))
            if child.tag == "rgb":
                assert len(child.get("value").split(",")) == 3
        else:
            if child.get("name") is not None:
                assert params.get(child.get("name")) == child.tag
            check_mitsuba_object(child)


def test_mitsuba_scene_follows_the_documented_plugins(exported, small_cloth):
    root = ET.parse(exported / "out" / "mitsuba" / "cloth.xml").getroot()
    assert root.tag == "scene" and root.get("version") == "3.0.0"
    for child in root:
        check_mitsuba_object(child)
    medium = root.find("medium")
    assert medium.get("type") == "heterogeneous"
    r = json_fiber_radius(small_cloth)
    assert float(medium.find("float[@name='scale']").get("value")) == pytest.approx(2 / (math.pi * r), rel=1e-12)
    assert medium.find("rgb[@name='albedo']").get("value") == "0.9, 0.8, 0.7"
    vol = medium.find("volume[@name='sigma_t']")
    assert vol.find("string[@name='filename']").get("value") == "cloth.vol"
    assert (exported / "out" / "mitsuba" / "cloth.vol").exists()
    shape = root.find("shape")
    assert shape.find("ref[@name='interior']").get("id") == medium.get("id")
    # The gridvolume's unit cube and the cube shape's [-1, 1]^3 both map onto the grid's box.
    g = small_cloth.grid
    (i0, j0, k0), (i1, j1, k1) = g.bbox
    lo = np.array(g.origin) + g.voxel_size * np.array([i0, j0, k0])
    hi = np.array(g.origin) + g.voxel_size * (np.array([i1, j1, k1]) + 1)
    t = vol.find("transform")
    scale, translate = t[0], t[1]
    assert (scale.tag, translate.tag) == ("scale", "translate")
    np.testing.assert_allclose([float(scale.get(a)) for a in "xyz"], hi - lo, rtol=1e-12)
    np.testing.assert_allclose([float(translate.get(a)) for a in "xyz"], lo, rtol=1e-12, atol=1e-15)
    ts = shape.find("transform")
    np.testing.assert_allclose([float(ts[0].get(a)) for a in "xyz"], (hi - lo) / 2, rtol=1e-12)
    np.testing.assert_allclose([float(ts[1].get(a)) for a in "xyz"], (hi + lo) / 2, rtol=1e-12, atol=1e-15)


def json_fiber_radius(cloth):
    return cloth.spec["warp_yarn"]["fiber_radius"]


# pbrt-v4 scene description (pbrt-v4 file format docs): directives used here and the parameters
# of each plugin, "type name" with the documented type.
PBRT_DIRECTIVES = {"LookAt", "Camera", "Film", "Sampler", "Integrator", "WorldBegin", "LightSource",
                   "MakeNamedMedium", "AttributeBegin", "AttributeEnd", "MediumInterface", "Material", "Shape"}
PBRT_PARAMS = {
    ("Camera", "perspective"): {"fov": "float"},
    ("Film", "rgb"): {"xresolution": "integer", "yresolution": "integer", "filename": "string"},
    ("Sampler", "zsobol"): {"pixelsamples": "integer"},
    ("Integrator", "volpath"): {"maxdepth": "integer"},
    ("LightSource", "infinite"): {"L": "rgb"},
    ("MakeNamedMedium", "nanovdb"): {"type": "string", "filename": "string", "sigma_a": "rgb", "sigma_s": "rgb",
                                     "scale": "float", "g": "float", "Lescale": "float"},
    ("Material", "interface"): {},
    ("Shape", "trianglemesh"): {"P": "point3", "indices": "integer"},
}


def pbrt_tokens(text):
    text = re.sub(r"#[^\n]*", "", text)
    return re.findall(r'"[^"]*"|\[|\]|[^\s\[\]"]+', text)


def parse_pbrt(text):
    """Statements as (directive, positional args, {name: (type, values)})."""
    toks = pbrt_tokens(text)
    out, i = [], 0
    while i < len(toks):
        d = toks[i]
        assert d in PBRT_DIRECTIVES, "unknown directive %s" % d
        i += 1
        args, params = [], {}
        while i < len(toks) and toks[i] not in PBRT_DIRECTIVES:
            t = toks[i]
            if t.startswith('"') and " " in t.strip('"') and (i + 1 < len(toks)):
                ptype, pname = t.strip('"').split()
                i += 1
                values = []
                if toks[i] == "[":
                    i += 1
                    while toks[i] != "]":
                        values.append(toks[i])
                        i += 1
                    i += 1
                else:
                    values.append(toks[i])
                    i += 1
                params[pname] = (ptype, values)
            else:
                args.append(t.strip('"'))
                i += 1
        out.append((d, args, params))
    return out


def test_pbrt_scene_follows_the_documented_format(exported, small_cloth):
    text = (exported / "out" / "pbrt" / "cloth.pbrt").read_text()
    statements = parse_pbrt(text)
    names = [s[0] for s in statements]
    assert names.index("WorldBegin") > max(names.index(d) for d in ("Camera", "Film", "Sampler", "Integrator"))
    assert names.count("AttributeBegin") == names.count("AttributeEnd")
    media = {}
    for d, args, params in statements:
        kind = params["type"][1][0].strip('"') if d == "MakeNamedMedium" else (args[0] if args and d not in
                                                                                 ("LookAt", "MediumInterface") else None)
        if d == "MakeNamedMedium":
            media[args[0]] = params
        if (d, kind) in PBRT_PARAMS:
            allowed = PBRT_PARAMS[(d, kind)]
            for pname, (ptype, values) in params.items():
                assert allowed.get(pname) == ptype, "%s %s: parameter %s %s" % (d, kind, ptype, pname)
        elif d in ("Camera", "Film", "Sampler", "Integrator", "LightSource", "Material", "Shape"):
            pytest.fail("%s %s is not a plugin this check knows" % (d, kind))
        if d == "LookAt":
            assert len(args) == 9 and all(math.isfinite(float(a)) for a in args)
        if d == "MediumInterface":
            assert args[0] in media  # inside: the declared medium
        if d == "Shape":
            P = np.array(params["P"][1], float).reshape(-1, 3)
            idx = np.array(params["indices"][1], int).reshape(-1, 3)
            assert idx.max() < len(P)
            # A closed box: every edge shared by exactly two triangles, consistently oriented.
            edges = {}
            for tri in idx:
                for a, b in ((tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])):
                    edges[(a, b)] = edges.get((a, b), 0) + 1
            assert all(edges.get((b, a)) == 1 for (a, b) in edges) and all(c == 1 for c in edges.values())
            g = small_cloth.grid
            (i0, j0, k0), (i1, j1, k1) = g.bbox
            lo = np.array(g.origin) + g.voxel_size * np.array([i0, j0, k0])
            hi = np.array(g.origin) + g.voxel_size * (np.array([i1, j1, k1]) + 1)
            np.testing.assert_allclose(P.min(axis=0), lo, rtol=1e-12, atol=1e-15)
            np.testing.assert_allclose(P.max(axis=0), hi, rtol=1e-12, atol=1e-15)
    cloth = media["cloth"]
    assert cloth["filename"][1] == ['"cloth.nvdb"']
    sigma = float(cloth["scale"][1][0])
    assert sigma == pytest.approx(2 / (math.pi * json_fiber_radius(small_cloth)), rel=1e-12)
    # sigma_a + sigma_s = 1 per unit density (times scale: sigma_t = sigma C), sigma_s = albedo.
    sa = np.array(cloth["sigma_a"][1], float)
    ss = np.array(cloth["sigma_s"][1], float)
    np.testing.assert_allclose(sa + ss, 1.0, rtol=1e-12)
    np.testing.assert_allclose(ss, [0.9, 0.8, 0.7], rtol=1e-12)
    assert (exported / "out" / "pbrt" / "cloth.nvdb").stat().st_size > 0


def test_export_without_provenance_needs_sigma(tmp_path, weft_bin):
    g = weft.Grid.from_numpy(np.ones((3, 3, 3), np.float32), voxel_size=0.1)
    g.save(tmp_path / "plain.vdb")
    r = subprocess.run([weft_bin, "export", "--grid", tmp_path / "plain.vdb", "--out", tmp_path / "o"],
                       capture_output=True, text=True)
    assert r.returncode == 1 and "pass --sigma" in r.stderr and r.stderr.startswith("weft: error:")
    r = subprocess.run([weft_bin, "--quiet", "export", "--grid", tmp_path / "plain.vdb", "--out", tmp_path / "o",
                        "--sigma", "5", "--format", "mitsuba"], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    values, _ = read_vol(tmp_path / "o" / "mitsuba" / "cloth.vol")
    np.testing.assert_array_equal(values, 1.0)
    assert not (tmp_path / "o" / "pbrt").exists()
