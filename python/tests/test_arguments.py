"""Every public call refuses a bad argument with one weft.Error line naming the call and the
argument (weft/_arguments.py; docs/python.md "Errors"), never with pybind11's TypeError listing
a private signature: the callables are found by walking the package, their parameters and types
read from their signatures, so a function added later is covered without an edit here."""

import inspect
import re

import numpy as np
import pytest

import weft
from conftest import random_grid


class Unconvertible:
    """A value no parameter of weft takes."""

    def __repr__(self):
        return "<Unconvertible>"


# A valid value per pybind11 type name, for the arguments around the bad one (nothing runs: the
# bad one is refused first), and per name for parameters of type `object`.
def valid_value(annotation, name, tmp_path):
    by_name = {"axis": "x", "radius": 0.1, "path": str(tmp_path / "file.vdb"), "direction": "z"}
    if annotation in ("object", inspect.Parameter.empty) and name in by_name:
        return by_name[name]
    head = re.match(r"^([\w.]+)", annotation).group(1) if isinstance(annotation, str) else "object"
    inner = annotation[len(head) + 1:-1] if isinstance(annotation, str) and annotation.endswith("]") else ""
    if head == "Optional":
        return None
    if head == "List":
        fixed = re.match(r"^(.*[^\]])\[(\d+)\]$", inner)
        if fixed:
            return [valid_value(fixed.group(1), name, tmp_path)] * int(fixed.group(2))
        return [valid_value(inner, name, tmp_path)]
    if head == "numpy.ndarray":
        return np.ones((2, 2, 3), dtype=np.float32 if "float32" in inner else np.float64)
    simple = {"int": 1, "float": 1.0, "bool": False, "str": "x", "object": None}
    if head in simple:
        return simple[head]
    return INSTANCES[head.rsplit(".", 1)[-1]]()


GRID = random_grid()[0]
LAW = weft.law("exponential", mu=1)
CURVE = weft.measure_beam(GRID, "x", sigma=1)
STATS = weft.window_stats(GRID, "x")
INSTANCES = {
    "Grid": lambda: GRID,
    "Law": lambda: LAW,
    "TransmittancePair": lambda: weft.TransmittancePair.same(LAW),
    "TransmittanceCurve": lambda: CURVE,
    "ConcentrationStats": lambda: STATS,
    "GammaFit": lambda: weft.gamma_from_moments(0.3, 0.01, 2.0),
    "LeastSquaresFit": lambda: weft.fit_gamma_to_curve(CURVE, 1.0),
    "CurveError": lambda: weft.compare(CURVE, list(CURVE.log_T)),
    "LocalFields": lambda: weft.local_fields(GRID, 2),
    "ShadowedGrids": lambda: weft.shadowed_downsample(GRID, 2, sigma=1.0),
    "Fibres": lambda: weft.Fibres([[[0, 0, 0], [1, 0, 0]]], 0.1),
    "Origin": lambda: weft.Origin.source,
}
# Reports made only by a render: their methods take no argument but self (checked for arity below).
RECORDS = {"StudyResult", "StudyCandidate", "AlbedoFit", "MatrixResult", "MatrixCase", "MatrixCandidate",
           "MatrixVerdict", "MatrixHeadline", "Cloth"}


def public_callables():
    """(name, callable, is_method) for every public function, constructor and method."""
    out = []
    for name in sorted(weft.__all__):
        obj = getattr(weft, name)
        if inspect.isclass(obj):
            if issubclass(obj, BaseException):
                continue
            out.append((name, obj, False))
            for member, value in vars(obj).items():
                if member.startswith("_") or isinstance(value, property) or not callable(getattr(obj, member)):
                    continue
                static = isinstance(value, (staticmethod, classmethod))
                out.append(("%s.%s" % (name, member), getattr(obj, member), not static))
        elif callable(obj):
            out.append((name, obj, False))
    return out


CALLABLES = public_callables()


def test_every_public_callable_has_a_signature():
    for name, fn, _ in CALLABLES:
        try:
            inspect.signature(fn)
        except (TypeError, ValueError):
            pytest.fail("%s: no signature (pybind11's docstring unreadable?)" % name)


def compiled_cases():
    """(name, callable, parameter, method's class) for every typed parameter of a compiled call."""
    cases = []
    for name, fn, is_method in CALLABLES:
        if is_method and name.split(".")[0] not in INSTANCES:
            continue
        signature = inspect.signature(fn)
        for p in signature.parameters.values():
            if p.name == "self" or p.kind in (p.VAR_POSITIONAL, p.VAR_KEYWORD):
                continue
            if isinstance(p.annotation, str) and p.annotation != "object":
                cases.append(pytest.param(name, p.name, id="%s-%s" % (name, p.name)))
    return cases


def bound(name):
    """The callable `name`, a method bound to an instance of its class."""
    fn = dict((n, f) for n, f, _ in CALLABLES)[name]
    cls, _, member = name.partition(".")
    if member and not isinstance(inspect.getattr_static(getattr(weft, cls), member), (staticmethod, classmethod)):
        fn = getattr(INSTANCES[cls](), member)
    return fn


def call_with(name, parameter, bad, tmp_path, keyword):
    """Calls `name` with `bad` as `parameter` (by keyword, or by position with the parameters
    before it) and the other required arguments valid."""
    fn = bound(name)
    params = [p for p in inspect.signature(fn).parameters.values()
              if p.name != "self" and p.kind not in (p.VAR_POSITIONAL, p.VAR_KEYWORD)]
    index = [p.name for p in params].index(parameter)
    positional = not keyword and params[index].kind == params[index].POSITIONAL_OR_KEYWORD
    args, kwargs = [], {}
    for i, p in enumerate(params):
        rebuildable = p.default is not p.empty and type(p.default).__name__ != "_Shown"
        value = bad if i == index else p.default if rebuildable else valid_value(p.annotation, p.name, tmp_path)
        if positional and i <= index:
            args.append(value)
        elif i == index or p.default is p.empty:
            kwargs[p.name] = value
    return fn(*args, **kwargs)


@pytest.mark.parametrize("keyword", [False, True], ids=["positional", "keyword"])
@pytest.mark.parametrize("name, parameter", compiled_cases())
def test_a_wrong_type_is_a_weft_error_naming_the_argument(name, parameter, keyword, tmp_path):
    with pytest.raises(weft.Error) as e:
        call_with(name, parameter, Unconvertible(), tmp_path, keyword)
    message = str(e.value)
    assert "\n" not in message and message.startswith(name + ": ") and parameter in message, message
    assert isinstance(e.value, TypeError)  # weft.ArgumentTypeError: `except TypeError` still works


def typed(annotation_head):
    return [c for c in compiled_cases() if re.match(
        r"^%s\b" % re.escape(annotation_head),
        str(inspect.signature(dict((n, f) for n, f, _ in CALLABLES)[c.values[0]]).parameters[c.values[1]].annotation))]


@pytest.mark.parametrize("keyword", [False, True], ids=["positional", "keyword"])
@pytest.mark.parametrize("name, parameter", typed("int"))
@pytest.mark.parametrize("bad", ["1", 1.5, 2**70], ids=["str", "float", "2**70"])
def test_integers_refuse_what_no_cpp_integer_holds(name, parameter, bad, keyword, tmp_path):
    with pytest.raises(weft.Error) as e:
        call_with(name, parameter, bad, tmp_path, keyword)
    assert parameter in str(e.value) and "\n" not in str(e.value), str(e.value)


@pytest.mark.parametrize("keyword", [False, True], ids=["positional", "keyword"])
@pytest.mark.parametrize("name, parameter", typed("float"))
def test_numbers_refuse_a_str(name, parameter, keyword, tmp_path):
    with pytest.raises(weft.Error, match="%s: %s must be a number, got str '1.0'" % (re.escape(name), parameter)):
        call_with(name, parameter, "1.0", tmp_path, keyword)


# pybind11 reads None as False for a bool and as NaN for an array, and "1.5" as an array.
@pytest.mark.parametrize("name, parameter", typed("bool") + typed("numpy.ndarray"))
@pytest.mark.parametrize("bad", [None, "1.5"], ids=["None", "str"])
def test_none_and_str_are_refused_before_pybind11_reads_them(name, parameter, bad, tmp_path):
    with pytest.raises(weft.Error, match="%s: %s must be " % (re.escape(name), parameter)):
        call_with(name, parameter, bad, tmp_path, True)


# pybind11's array caster (forcecast) converts any NumPy array or sequence: a complex kept its real
# part (with only NumPy's ComplexWarning), a str array was parsed, a bool read as 0 or 1.
NOT_REAL = [np.array([1 + 5j]), np.array(["1.5"]), np.array([b"1"]), np.array([True]), np.array([0.5], object),
            np.array(["2020-01-01"], "datetime64[D]"), np.array([1], "timedelta64[s]"),
            np.zeros(1, [("a", "f8")]), np.complex64(1), np.bool_(True), True, 1 + 5j, [True, 0.5], [[0.5], [1j]]]
NOT_REAL_IDS = ["complex", "str", "bytes", "bool", "object", "datetime", "timedelta", "void", "np.complex64",
                "np.bool_", "True", "1+5j", "list-bool", "nested-complex"]


@pytest.mark.parametrize("name, parameter", typed("numpy.ndarray"))
@pytest.mark.parametrize("bad", NOT_REAL, ids=NOT_REAL_IDS)
def test_arrays_refuse_what_is_not_a_real_number(name, parameter, bad, tmp_path):
    with pytest.raises(weft.ArgumentTypeError, match="^%s: %s must be an array .* of numbers, got " % (
            re.escape(name), parameter)):
        call_with(name, parameter, bad, tmp_path, True)


@pytest.mark.parametrize("keyword", [False, True], ids=["positional", "keyword"])
@pytest.mark.parametrize("name, parameter", typed("float") + typed("int"))
@pytest.mark.parametrize("bad", [True, np.bool_(False), np.complex128(1)], ids=["True", "np.bool_", "np.complex128"])
def test_a_bool_or_a_complex_is_not_a_number(name, parameter, bad, keyword, tmp_path):
    with pytest.raises(weft.ArgumentTypeError, match="^%s: %s must be " % (re.escape(name), parameter)):
        call_with(name, parameter, bad, tmp_path, keyword)


def test_real_arrays_of_every_width_are_taken():
    law = weft.law("gamma", mean_extinction=2, alpha=0.5)
    expected = law.T(np.array([0.0, 1.0, 2.0]))
    for dtype in (np.float16, np.float32, np.int8, np.int64, np.uint8, np.uint64):
        assert np.array_equal(law.T(np.array([0, 1, 2], dtype)), expected), dtype
    assert np.array_equal(law.T([0, 1.0, np.float32(2)]), expected)
    for dtype in (np.float64, np.int16, np.uint16):
        grid = weft.Grid.from_numpy(np.ones((2, 3, 4), dtype), voxel_size=0.1)
        assert grid.active_voxel_count == 24, dtype


@pytest.mark.parametrize("call", [
    lambda: weft.measure_beam(GRID, seed=-1),
    lambda: weft.measure_beam(GRID, "x", seed=-1, sigma=1),
    lambda: LAW.sample(3, seed=-1),
    lambda: weft.measure_fibre_beam(INSTANCES["Fibres"](), seed=-1),
], ids=["measure_beam", "measure_beam_args", "Law.sample", "measure_fibre_beam"])
def test_a_negative_seed_is_named(call):
    with pytest.raises(weft.Error) as e:
        call()
    assert re.search(r"(^|: )seed must be >= 0, got -1$", str(e.value)), str(e.value)


@pytest.mark.parametrize("call, message", [
    (lambda: GRID.to_numpy(box=((0, 0, 0), (2**40, 1, 1))),
     r"^Grid.to_numpy: box\[1\]\[0\] is out of the range of its C\+\+ integer type, got 1099511627776$"),
    (lambda: weft.Grid.from_numpy(np.ones((2, 2, 2), np.float32), index_origin=(2**31, 0, 0)),
     r"^Grid.from_numpy: index_origin\[0\] is out of the range of its C\+\+ integer type, got 2147483648$"),
    # Below -2^31 an int refuses the value for its range: negative indices are legal, so not ">= 0".
    (lambda: GRID.to_numpy(box=((0, 0, -2**31 - 1), (0, 0, 0))),
     r"^Grid.to_numpy: box\[0\]\[2\] is out of the range of its C\+\+ integer type, got -2147483649$"),
    (lambda: weft.Grid.from_numpy(np.ones((2, 2, 2), np.float32), index_origin=(0, 0, -2**31 - 1)),
     r"^Grid.from_numpy: index_origin\[2\] is out of the range of its C\+\+ integer type, got -2147483649$"),
    (lambda: weft.Grid(1.0).set_value(0, 0, -2**31 - 1, 1.0),
     r"^Grid.set_value: k is out of the range of its C\+\+ integer type, got -2147483649$"),
], ids=["to_numpy_box", "from_numpy_index_origin", "to_numpy_box_below", "from_numpy_below", "set_value_below"])
def test_an_integer_out_of_range_inside_a_sequence_is_named_with_its_place(call, message):
    with pytest.raises(weft.Error, match=message):
        call()


@pytest.mark.parametrize("keywords, name", [
    (dict(spp=2**40), "spp"), (dict(reference_spp=2**31), "reference_spp"), (dict(yarns=-2**31 - 1), "yarns"),
    (dict(film=(2**40, 8)), "film's width"), (dict(factors=[2, 2**40]), "factors"), (dict(seed=2**64), "seed"),
], ids=["spp", "reference_spp", "yarns", "film", "factors", "seed"])
def test_the_studys_integers_beyond_their_cpp_type_are_out_of_range_not_of_a_wrong_type(keywords, name, tmp_path):
    # Refused before a cloth is made: the same message whichever keyword, naming it and the value.
    with pytest.raises(weft.Error) as e:
        weft.render_matrix(quick=True, out=tmp_path / "m", threads=1, **keywords)
    assert not isinstance(e.value, TypeError), str(e.value)
    assert re.search(r"^render_matrix: %s is out of the range of its C\+\+ integer type, got -?\d+$" % re.escape(name),
                     str(e.value)), str(e.value)
    assert not (tmp_path / "m").exists()


def test_the_brief_examples():
    with pytest.raises(weft.Error, match=r"^measure_beam: seed must be >= 0, got -1$"):
        weft.measure_beam(GRID, seed=-1)
    with pytest.raises(weft.Error, match=r"^measure_beam: rays_per_column must be an integer, got str 'two'$"):
        weft.measure_beam(GRID, rays_per_column="two")
    with pytest.raises(weft.Error, match=r"^Law.T: t must be an array .*, got NoneType None$"):
        LAW.T(None)
    with pytest.raises(weft.Error, match=r"^Grid.save: path must be a str, bytes or os.PathLike, got int$"):
        GRID.save(3)
    with pytest.raises(weft.Error, match=r"^measure_beam: progress must be a callable"):
        weft.measure_beam(GRID, "x", sigma=1, progress=3)


def test_classes_without_a_constructor_say_so():
    for name, fn, is_method in CALLABLES:
        if inspect.isclass(fn) and type(fn).__name__ == "pybind11_type" and "." not in name:
            if type(inspect.getattr_static(fn, "__init__")).__name__ == "function" and name not in (
                    "Grid", "Fibres", "Origin", "GammaFit", "ConcentrationStats"):
                with pytest.raises(weft.Error, match="weft.%s cannot be made directly" % name):
                    fn()


@pytest.mark.parametrize("name", [n for n, f, m in CALLABLES if not inspect.isclass(f)])
def test_extra_arguments_are_weft_errors(name):
    cls, _, member = name.partition(".")
    if member and cls not in INSTANCES and not isinstance(inspect.getattr_static(getattr(weft, cls), member),
                                                          (staticmethod, classmethod)):
        pytest.skip("no cheap %s to call its methods on" % cls)
    fn = bound(name)
    with pytest.raises(weft.Error) as e:
        fn(*([None] * 12), no_such_argument=1)
    assert "\n" not in str(e.value) and str(e.value).startswith(name), str(e.value)


@pytest.mark.parametrize("name", [n for n, f, m in CALLABLES if "." not in n and not inspect.isclass(f)])
def test_functions_refuse_a_wrong_first_argument(name):
    """Also the package's own functions (validate, render, gen, ...), positional and keyword."""
    fn = getattr(weft, name)
    parameters = [p for p in inspect.signature(fn).parameters.values() if p.kind != p.VAR_KEYWORD]
    if not parameters:
        pytest.skip("takes no argument")
    first = parameters[0]
    calls = [lambda: fn(Unconvertible())]
    if first.kind in (first.POSITIONAL_OR_KEYWORD, first.KEYWORD_ONLY):
        calls.append(lambda: fn(**{first.name: Unconvertible()}))
    for call in calls:
        with pytest.raises(weft.Error) as e:
            call()
        assert "\n" not in str(e.value), str(e.value)


def test_a_callback_error_is_raised_as_itself():
    class Mine(TypeError):
        pass

    def progress(label, done, total):
        raise Mine("from the callback")

    with pytest.raises(Mine):
        weft.measure_beam(GRID, "x", sigma=1, progress=progress)


def test_numpy_numbers_and_bytes_paths_are_taken_as_their_python_equals(small_cloth, tmp_path):
    # NumPy registers its scalars as numbers.Real / numbers.Integral: a notebook's np.float32 or
    # np.int64 is the number it holds, everywhere a number is taken (a bool is not a number).
    law = weft.law("gamma", alpha=0.5, mean_extinction=1.0)
    for alpha, mean in ((np.float32(0.5), 1.0), (0.5, np.int64(1)), (np.float64(0.5), np.int32(1))):
        assert np.array_equal(weft.law("gamma", alpha=alpha, mean_extinction=mean).T([0.3, 2.0]), law.T([0.3, 2.0]))
    with pytest.raises(weft.Error, match="must be a number, got <class 'bool'>"):
        weft.law("gamma", alpha=True, mean_extinction=1.0)
    grid = small_cloth.grid
    a = weft.measure_beam(grid, 2, sigma=1.0)
    b = weft.measure_beam(grid, np.int64(2), sigma=1.0)
    assert np.array_equal(a.log_T, b.log_T)
    with pytest.raises(weft.Error, match=r"^measure_beam: axis must be 0, 1, 2 or .x., .y., .z., got bool$"):
        weft.measure_beam(grid, np.bool_(True), sigma=1.0)
    # bytes paths, as open() and os.fspath take them
    path = tmp_path / "g.vdb"
    grid.save(bytes(path))
    assert weft.load_grid(bytes(path)).active_voxel_count == grid.active_voxel_count


def _half_built_in(error):
    """(frame, name) of every traceback local that is a weft object whose constructor failed (a
    type check only: any attribute of such an object reads uninitialised memory)."""
    found = []
    tb = error.__traceback__
    while tb is not None:
        for name, value in list(tb.tb_frame.f_locals.items()):
            for item in value if isinstance(value, (tuple, list)) else (value,):
                if type(item).__module__.startswith("weft") and type(type(item)).__name__ == "pybind11_type":
                    found.append((tb.tb_frame.f_code.co_name, name))
        tb = tb.tb_next
    return found


@pytest.mark.parametrize("name", sorted(n for n in weft.__all__ if isinstance(getattr(weft, n), type)
                                        and type(getattr(weft, n)).__name__ == "pybind11_type"))
def test_a_failed_constructor_leaves_no_half_built_object_in_the_traceback(name):
    # pytest printing a failed test's locals, a debugger or IPython's verbose traceback would call
    # a method of such an object and crash the interpreter.
    with pytest.raises(weft.Error) as caught:
        getattr(weft, name)(__not_an_argument__=1)
    assert _half_built_in(caught.value) == []


# Every public call that writes where an argument says, with that argument empty or blank. They
# get the CLI's rule for --out / --output (weft::output_name_problem): an empty out= would put
# the files in the working folder, a blank one in a folder named " ", and an empty path= failed
# on renaming an internal temporary file. The refusal comes first: nothing runs, nothing is written.
def _writers(name):
    image = np.ones((2, 2, 3), dtype=np.float32)
    fields = weft.local_fields(GRID, 2)
    return {
        "render_matrix": ("out", True, lambda v: weft.render_matrix(
            quick=True, cloths="plain", lightings="back", tilts=45, factors=2, spp=2, reference_spp=4, out=v,
            threads=2)),
        "render_study": ("out", True, lambda v: weft.render_study(
            "furnace", quick=True, spp=1, reference_spp=2, factors=2, window=0.5, out=v, threads=2)),
        "fit_albedo": ("out", True, lambda v: weft.fit_albedo("furnace", quick=True, spp=1, reference_spp=2,
                                                              factors=2, out=v, threads=2)),
        "Grid.save": ("path", False, lambda v: GRID.save(v)),
        "LocalFields.save": ("path", False, lambda v: fields.save(v)),
        "write_exr": ("path", False, lambda v: weft.write_exr(v, image)),
        "write_png": ("path", False, lambda v: weft.write_png(v, image)),
        "plot_validation": ("path", False, lambda v: weft.plot_validation({"axes": []}, path=v)),
    }[name]


WRITERS = ["render_matrix", "render_study", "fit_albedo", "Grid.save", "LocalFields.save", "write_exr", "write_png",
           "plot_validation"]


def test_every_call_with_an_out_argument_is_among_the_writers():
    # (StudyResult and MatrixResult take the binding's result as `out`: no path.)
    with_out = {name for name, fn, _ in CALLABLES if not inspect.isclass(fn)
                and (sig := weft._arguments._signature(fn)) is not None and "out" in sig.parameters}
    assert with_out <= set(WRITERS)


@pytest.mark.parametrize("name", WRITERS)
@pytest.mark.parametrize("value, word", [("", "an empty"), ("  ", "a blank"), ("\t", "a blank")])
def test_an_empty_or_blank_output_is_refused_naming_the_argument(name, value, word, tmp_path, monkeypatch):
    argument, folder, call = _writers(name)
    monkeypatch.chdir(tmp_path)
    with pytest.raises(weft.Error) as caught:
        call(value)
    assert str(caught.value) == "%s: %s: must name a %s, got %s value" % (
        name, argument, "folder" if folder else "file", word)
    assert sorted(p.name for p in tmp_path.iterdir()) == []
