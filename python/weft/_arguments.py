"""Bad arguments of every public call as one ``weft.Error`` line (docs/python.md "Errors").

pybind11 refuses a value its C++ parameter cannot take (a str for a number, -1 for an unsigned
seed, None for an array) with a ``TypeError`` that prints every overload's signature over several
lines and names no argument; a binding's own ``py::type_error`` is a bare ``TypeError``. Every
callable of the compiled module, and every public function and class of the package, is wrapped
once (``check_module``, ``check_public``) by ``checked``: a call that fails that way is diagnosed
from the call's signature (pybind11's, parsed from the docstring) and raised again as
``ArgumentTypeError``, a ``weft.Error`` that is also a ``TypeError`` (``except TypeError`` keeps
working), or as a ``weft.Error`` for an integer out of its C++ type's range; both name the call
and the argument. An exception raised by Python code the call ran (a progress callback's own
error) passes unchanged. pybind11 lets some values through without a word, so they are checked
before the call: None where a bool or an array is taken (it reads as False or NaN), a str where
an array is taken ("1.5" reads as a number), a bool where a number, an integer or an array is
taken (it reads as 1), and, where an array is taken, a complex number or a NumPy array or scalar
whose dtype is not a real number (kinds b, c, U, S, O, V, M, m: the array caster's forcecast
keeps a complex's real part, parses a str array, reads a bool as 0 or 1); real kinds (f, i, u)
are taken.
"""

import ast as _ast
import functools as _functools
import inspect as _inspect
import numbers as _numbers
import re as _re

import numpy as _numpy

from ._weft import Error

__all__ = ["ArgumentTypeError"]


class ArgumentTypeError(Error, TypeError):
    """A value of the wrong type, or a call with missing or unexpected arguments: a weft.Error
    (one line naming the call and the argument) that is also a TypeError."""


ArgumentTypeError.__module__ = "weft"

_INCOMPATIBLE = ("incompatible function arguments", "incompatible constructor arguments")
_INT_MAX = 2**31 - 1  # the narrowest C++ integer a binding takes (int); anything above may be refused
_INT_MIN = -(2**31)  # below it, int refuses a value (as does any unsigned type): "out of range", not ">= 0"
_REAL_KINDS = "fiu"  # NumPy dtype kinds that are real numbers: float, signed and unsigned integer
# Parameter types whose values are checked before the call (the values pybind11 would misread).
_PRECHECKED = _re.compile(r"\b(bool|int|float|numpy\.ndarray)\b")


# ---- pybind11 signatures ---------------------------------------------------------------------

def _split_top(text, sep=","):
    """``text`` split at ``sep`` outside brackets and quotes."""
    parts, depth, quote, start = [], 0, None, 0
    for i, c in enumerate(text):
        if quote:
            quote = None if c == quote else quote
        elif c in "'\"":
            quote = c
        elif c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        elif c == sep and depth == 0:
            parts.append(text[start:i].strip())
            start = i + 1
    tail = text[start:].strip()
    return parts + [tail] if tail else parts


class _Shown:
    """A default value pybind11 prints but Python cannot rebuild (e.g. an enum member)."""

    def __init__(self, text):
        self._text = text

    def __repr__(self):
        return self._text


def _default(text):
    try:
        return _ast.literal_eval(text)
    except (ValueError, SyntaxError):
        return _Shown(text)


def _pybind_signature(fn):
    """The inspect.Signature of a pybind11 function, from its docstring's first line
    ``name(a: int, b: float = 1.0, *, c: str = 'x') -> T`` (annotations are pybind11's type
    names, as text); None for an overloaded function or an unreadable line."""
    first = (getattr(fn, "__doc__", None) or "").split("\n", 1)[0]
    match = _re.match(r"^\w+\((.*)\)( -> .*)?$", first)
    if not match:
        return None
    params, kind = [], _inspect.Parameter.POSITIONAL_OR_KEYWORD
    for part in _split_top(match.group(1)):
        if part == "*":
            kind = _inspect.Parameter.KEYWORD_ONLY
            continue
        if part == "/":
            params = [p.replace(kind=_inspect.Parameter.POSITIONAL_ONLY) for p in params]
            continue
        if part.startswith("**"):
            params.append(_inspect.Parameter(part[2:].split(":")[0], _inspect.Parameter.VAR_KEYWORD))
            continue
        if part.startswith("*"):
            params.append(_inspect.Parameter(part[1:].split(":")[0], _inspect.Parameter.VAR_POSITIONAL))
            kind = _inspect.Parameter.KEYWORD_ONLY
            continue
        pieces = _split_top(part, "=")
        default = "=".join(pieces[1:]).strip() if len(pieces) > 1 else None
        name, _, annotation = pieces[0].partition(":")
        try:
            params.append(_inspect.Parameter(
                name.strip(), kind, annotation=annotation.strip() or _inspect.Parameter.empty,
                default=_inspect.Parameter.empty if default is None else _default(default)))
        except ValueError:
            return None
    try:
        return _inspect.Signature(params)
    except ValueError:
        return None


def _signature(fn):
    if type(fn).__name__ in ("builtin_function_or_method", "instancemethod"):
        return _pybind_signature(fn)
    try:
        return _inspect.signature(fn)
    except (TypeError, ValueError):
        return None


# ---- what a pybind11 type name takes ---------------------------------------------------------

def _generic(annotation):
    """``"List[int[3]]"`` -> ("List", ["int[3]"]); a plain name -> (name, []); no annotation ->
    ("object", [])."""
    if not isinstance(annotation, str):
        return "object", []
    match = _re.match(r"^([\w.]+)\[(.*)\]$", annotation)
    if not match:
        return annotation, []
    return match.group(1), _split_top(match.group(2))


def _described(annotation, plural=False):
    """What a pybind11 type name takes, in words."""
    head, args = _generic(annotation)
    words = {"int": ("an integer", "integers"), "float": ("a number", "numbers"), "bool": ("True or False", "booleans"),
             "str": ("a str", "strs"), "bytes": ("bytes", "bytes"), "None": ("None", "None")}
    if head in words and not args:
        return words[head][plural]
    if head == "Optional" and args:
        return "%s or None" % _described(args[0], plural)
    if head == "numpy.ndarray":
        return "arrays of numbers" if plural else "an array (or a number, or a list) of numbers"
    if head in ("List", "Sequence", "Set") and len(args) == 1:
        inner, size = _fixed(args[0])
        if size is not None:
            return "%s of %d %s" % ("sequences" if plural else "a sequence", size, _described(inner, True))
        return "%s of %s" % ("lists" if plural else "a list", _described(args[0], True))
    if head == "Tuple":
        return "%s (%s)" % ("tuples" if plural else "a tuple", ", ".join(_described(a) for a in args))
    if head == "Dict":
        return "dicts" if plural else "a dict"
    if head == "Callable":
        return "callables" if plural else "a callable"
    name = head.rsplit(".", 1)[-1]
    return ("weft.%s objects" if plural else "a weft.%s") % name


def _fixed(annotation):
    """``"int[3]"`` (std::array) -> ("int", 3); anything else -> (annotation, None)."""
    match = _re.match(r"^(.*[^\]])\[(\d+)\]$", annotation)
    return (match.group(1), int(match.group(2))) if match else (annotation, None)


def _weft_class(name):
    from . import _weft
    if not name.startswith("weft."):
        return None
    cls = getattr(_weft, name.rsplit(".", 1)[-1], None)
    return cls if isinstance(cls, type) else None


def _fits(annotation, value):
    """Whether pybind11 can convert ``value`` to the type it names ``annotation`` (as its casters
    decide, in convert mode), integer ranges aside; True for a name it does not know."""
    head, args = _generic(annotation)
    if head in ("object", ""):
        return True
    if head == "Optional" and args:
        return value is None or _fits(args[0], value)
    if value is None:
        return head == "None"
    if head == "int":
        if isinstance(value, (float, bool, _numpy.bool_)):
            return False
        try:
            value.__index__()
        except (AttributeError, TypeError):
            return False
        return True
    if head == "float":
        if isinstance(value, (str, bytes, bytearray, bool)):
            return False
        if isinstance(value, _numpy.generic) and value.dtype.kind not in _REAL_KINDS:
            return False  # np.bool_, np.complex128 (float() would keep its real part)
        try:
            float(value)
        except (TypeError, ValueError, OverflowError):
            return False
        return True
    if head == "bool":
        return hasattr(type(value), "__bool__")
    if head == "str":
        return isinstance(value, (str, bytes))
    if head == "numpy.ndarray":
        if isinstance(value, (str, bytes)) or isinstance(value, (list, tuple)) and _odd(value):
            return False  # NumPy would read [True, 0.5] as floats
        try:
            return _numpy.asarray(value).dtype.kind in _REAL_KINDS
        except (TypeError, ValueError):
            return False
    if head == "Set":
        return isinstance(value, (set, frozenset))
    if head in ("List", "Sequence", "Tuple"):
        # PySequence_Check, as pybind11's list caster asks: item access and not a dict; not a str.
        if isinstance(value, (str, bytes, dict)) or not hasattr(type(value), "__getitem__"):
            return False
        items = list(value)
        if head == "Tuple":
            return len(items) == len(args) and all(_fits(a, v) for a, v in zip(args, items))
        inner, size = _fixed(args[0]) if args else ("object", None)
        if size is not None and len(items) != size:
            return False
        return all(_fits(inner, v) for v in items)
    if head == "Dict":
        return isinstance(value, dict)
    if head == "Callable":
        return callable(value)
    cls = _weft_class(head)
    return cls is None or isinstance(value, cls)


def _int_out_of_range(annotation, value, where=""):
    """For an int that pybind11 may have refused for its range, also inside a sequence or tuple
    of them (``box=((0, 0, 0), (2**40, 1, 1))``): the problem, prefixed with the item's place
    (``[1][0] is out of …``), else None."""
    head, args = _generic(annotation)
    if head == "Optional" and args:
        return None if value is None else _int_out_of_range(args[0], value, where)
    if head in ("List", "Sequence", "Tuple") and args:
        if value is None or isinstance(value, (str, bytes, dict)) or not hasattr(type(value), "__getitem__"):
            return None
        items = list(value)
        for i, item in enumerate(items):
            if head == "Tuple":
                if i >= len(args):
                    return None
                inner = args[i]
            else:
                inner = _fixed(args[0])[0]
            problem = _int_out_of_range(inner, item, "%s[%d]" % (where, i))
            if problem:
                return problem
        return None
    if annotation != "int" or value is None or not _fits("int", value):
        return None
    value = value.__index__()
    if _INT_MIN <= value < 0:
        # Every C++ integer type a binding takes holds these but an unsigned one.
        return "%s must be >= 0, got %d" % (where, value)
    if value < _INT_MIN or value > _INT_MAX:
        return "%s is out of the range of its C++ integer type, got %d" % (where, value)
    return None


def _shown(value):
    if value is None or isinstance(value, (bool, int, float, complex, str, bytes)):
        text = repr(value)
        return "%s %s" % (type(value).__name__, text if len(text) <= 40 else text[:37] + "...")
    if isinstance(value, _numpy.ndarray):
        return "ndarray of %s" % value.dtype
    return type(value).__name__


# ---- the diagnosis ---------------------------------------------------------------------------

def _bound(call, signature, args, kwargs):
    try:
        return signature.bind(*args, **kwargs).arguments
    except TypeError as e:
        raise ArgumentTypeError("%s: %s" % (call, e)) from None


def _mismatch(call, signature, arguments, values=None):
    """ArgumentTypeError for the first argument whose value its type cannot take (only among
    ``values``' names when given), else None."""
    for name, value in arguments.items():
        parameter = signature.parameters[name]
        if values is not None and name not in values:
            continue
        if parameter.kind in (parameter.VAR_POSITIONAL, parameter.VAR_KEYWORD):
            continue
        if not _fits(parameter.annotation, value):
            return ArgumentTypeError("%s: %s must be %s, got %s" % (call, name, _described(parameter.annotation),
                                                                    _shown(value)))
    return None


def _diagnosed(call, signature, args, kwargs):
    """The weft.Error of a call pybind11 refused: the argument it could not convert."""
    if signature is None:
        return ArgumentTypeError("%s: the arguments do not match %s (see help)" % (call, call))
    arguments = _bound(call, signature, args, kwargs)
    wrong = _mismatch(call, signature, arguments)
    if wrong is not None:
        return wrong
    ranges = [(name, problem) for name, value in arguments.items()
              for problem in [_int_out_of_range(signature.parameters[name].annotation, value)] if problem]
    if len(ranges) == 1:
        return Error("%s: %s%s" % (call, ranges[0][0], ranges[0][1]))
    if ranges:
        return Error("%s: %s: one of these is out of its integer type's range" % (
            call, ", ".join("%s=%s" % (name, arguments[name]) for name, _ in ranges)))
    return ArgumentTypeError("%s: the arguments (%s) do not match %s%s" % (
        call, ", ".join("%s=%s" % (n, _shown(v)) for n, v in arguments.items()), call, signature))


def _raised_below(error):
    """Whether ``error`` was raised in Python code under the wrapper's frame (e.g. a progress
    callback's own error), not by the C code of the call itself."""
    tb = error.__traceback__
    return tb is not None and tb.tb_next is not None


def _one_line(call, message):
    line = message.strip().split("\n", 1)[0]
    bare = call.rsplit(".", 1)[-1]
    named = line.startswith(tuple(prefix + sep for prefix in (call, bare) for sep in (":", " ")))
    return line if named else "%s: %s" % (call, line)


# Values that may be odd (_odd); anything else is not, which is all a plain number costs.
_SUSPECT = (str, bytes, bool, complex, list, tuple, _numpy.ndarray, _numpy.generic)
# Per type, whether its values may be odd: one dict lookup per argument (a float, an int, a weft
# object), cheaper than isinstance against the eight types above.
_SUSPECT_TYPES = {type(None): True}


def _suspect_type(t):
    suspect = _SUSPECT_TYPES[t] = issubclass(t, _SUSPECT)
    return suspect


def _odd(v):
    """Whether ``v`` is a value pybind11 may take where it should not (the module's docstring):
    None, a str or bytes, a bool, a complex, a NumPy array or scalar of a kind that is not a real
    number, or a list or tuple holding any of these (at any depth)."""
    if type(v) is _numpy.ndarray:
        return v.dtype.kind not in _REAL_KINDS
    if v is None:
        return True
    if not isinstance(v, _SUSPECT):
        return False
    if isinstance(v, (_numpy.ndarray, _numpy.generic)):
        return v.dtype.kind not in _REAL_KINDS
    if isinstance(v, (list, tuple)):
        for item in v:
            suspect = _SUSPECT_TYPES.get(type(item))
            if (_suspect_type(type(item)) if suspect is None else suspect) and _odd(item):
                return True
        return False
    return True  # str, bytes, bool, complex


def _holds_odd(args, kwargs):
    """Whether an argument is _odd. Plain loops, not generators, and a type lookup before _odd: it
    runs on every call of such a binding (a generator doubled the cost of a scalar ``Law.T``)."""
    for v in args:
        suspect = _SUSPECT_TYPES.get(type(v))
        if (_suspect_type(type(v)) if suspect is None else suspect) and _odd(v):
            return True
    if kwargs:
        for v in kwargs.values():
            suspect = _SUSPECT_TYPES.get(type(v))
            if (_suspect_type(type(v)) if suspect is None else suspect) and _odd(v):
                return True
    return False


_FLOAT32_MAX = float(_numpy.finfo(_numpy.float32).max)


def _holds_wide_floats(args, kwargs):
    """Whether an argument is a NumPy array of floats wider than 32 bits (which a float32
    parameter's cast could overflow)."""
    for v in args:
        if type(v) is _numpy.ndarray and v.dtype.kind == "f" and v.dtype.itemsize > 4:
            return True
    for v in kwargs.values():
        if type(v) is _numpy.ndarray and v.dtype.kind == "f" and v.dtype.itemsize > 4:
            return True
    return False


def _past_float32(call, arguments, names):
    """weft.Error for the first finite value past float32's range in the ``names`` arguments, else
    None: NumPy's cast would make it inf with a RuntimeWarning, and the binding would then name an
    inf the caller never gave."""
    for name in names:
        v = arguments.get(name)
        if type(v) is not _numpy.ndarray or v.dtype.kind != "f" or v.dtype.itemsize <= 4:
            continue
        past = _numpy.isfinite(v) & (_numpy.abs(v) > _FLOAT32_MAX)
        if past.any():
            index = tuple(int(i) for i in _numpy.unravel_index(int(_numpy.argmax(past)), v.shape))
            return Error("%s: %s: value %r at index %s is past the range of a 32-bit float (+-%.6g)"
                         % (call, name, float(v[index]), index, _FLOAT32_MAX))
    return None


def checked(fn, call):
    """``fn`` whose bad arguments raise weft.Error naming ``call`` and the argument."""
    if getattr(fn, "_weft_checked", False):
        return fn
    signature = _signature(fn)
    compiled = type(fn).__name__ in ("builtin_function_or_method", "instancemethod")
    precheck = compiled and signature is not None and any(
        isinstance(p.annotation, str) and _PRECHECKED.search(p.annotation) for p in signature.parameters.values())
    # The parameters that take float32 arrays (images, dense grids).
    float32 = [n for n, p in signature.parameters.items()
               if isinstance(p.annotation, str) and "numpy.float32" in p.annotation] if compiled and signature else []

    @_functools.wraps(fn)
    def call_checked(*args, **kwargs):
        if float32 and _holds_wide_floats(args, kwargs):
            wide = _past_float32(call, _bound(call, signature, args, kwargs), float32)
            if wide is not None:
                raise wide
        if precheck and _holds_odd(args, kwargs):
            arguments = _bound(call, signature, args, kwargs)
            odd = {n for n, v in arguments.items() if _odd(v)}
            wrong = _mismatch(call, signature, arguments, odd)
            if wrong is not None:
                raise wrong
        try:
            return fn(*args, **kwargs)
        except Error as e:
            # A private binding a public function called names itself: say the public call.
            text = str(e)
            private = _re.match(r"^_\w+: ", text)
            if private and not compiled and not call.startswith("_"):
                raise type(e)("%s: %s" % (call, text[private.end():])) from None
            raise
        except TypeError as e:
            if _raised_below(e):
                raise
            if any(text in str(e) for text in _INCOMPATIBLE):
                raise _diagnosed(call, signature, args, kwargs) from None
            if not compiled and signature is not None:
                _bound(call, signature, args, kwargs)  # a Python function called with missing or extra arguments
                raise
            raise ArgumentTypeError(_one_line(call, str(e))) from None
        except RuntimeError as e:
            # pybind11's cast_error: a value a binding's body could not convert.
            if _raised_below(e) or not str(e).startswith("Unable to cast"):
                raise
            raise ArgumentTypeError(_one_line(call, str(e))) from None

    if signature is not None:
        call_checked.__signature__ = signature
    call_checked._weft_checked = True
    return call_checked


def _not_constructible(cls):
    def __init__(self, *args, **kwargs):
        self = None  # noqa: F841 -- half-built (_forgets_half_built); this frame is in the traceback
        raise ArgumentTypeError("weft.%s cannot be made directly: weft's functions return it (help(weft.%s))"
                                % (cls.__name__, cls.__name__))
    return __init__


def _forgets_half_built(init):
    """A compiled class's ``__init__`` that, when it raises, leaves no reference to the object it
    failed to make in the traceback. pybind11 has allocated that object but not constructed its
    C++ value, and any method or attribute of it reads uninitialised memory: pytest printing a
    failed test's locals, a debugger or IPython's verbose traceback would crash the interpreter.
    The frames of weft's wrappers held it in ``self``/``args``; they are dropped from the
    traceback, and so is a suppressed context that held them too."""
    @_functools.wraps(init)
    def __init__(self, *args, **kwargs):
        try:
            init(self, *args, **kwargs)
        except BaseException as error:  # noqa: B902 -- KeyboardInterrupt included
            self = args = kwargs = None  # noqa: F841 -- this frame stays in the traceback
            if error.__suppress_context__:
                error.__context__ = None
            raise error.with_traceback(None)
    return __init__


def check_class(cls, prefix):
    """Every public method, static method and the constructor of ``cls``, checked in place."""
    name = prefix + cls.__name__
    if getattr(cls, "_weft_checked_class", False):
        return
    members = dict(vars(cls))
    if type(cls).__name__ == "pybind11_type":
        if type(members.get("__init__")).__name__ != "instancemethod":
            members.pop("__init__", None)
            cls.__init__ = _not_constructible(cls)  # pybind11's own says "No constructor defined!"
    elif "__init__" not in members and _inspect.isfunction(cls.__init__):
        members["__init__"] = cls.__init__  # inherited: checked under this class's name
    for member, value in members.items():
        if member.startswith("_") and member != "__init__":
            continue
        call = name if member == "__init__" else "%s.%s" % (name, member)
        if isinstance(value, staticmethod):
            setattr(cls, member, staticmethod(checked(value.__func__, call)))
        elif isinstance(value, classmethod):
            setattr(cls, member, classmethod(checked(value.__func__, call)))
        elif type(value).__name__ == "instancemethod":
            wrapped = checked(value.__func__, call)
            setattr(cls, member, _forgets_half_built(wrapped) if member == "__init__" else wrapped)
        elif _inspect.isfunction(value):
            setattr(cls, member, checked(value, call))
    cls._weft_checked_class = True


def check_module(module):
    """Every function and class of the compiled module ``module``, checked in place (before the
    package imports its names)."""
    for name, value in list(vars(module).items()):
        if name.startswith("__"):
            continue
        if isinstance(value, type) and not issubclass(value, BaseException):
            check_class(value, "")
        elif type(value).__name__ == "builtin_function_or_method":
            setattr(module, name, checked(value, name))


def check_public(namespace, names):
    """The package's public functions and classes, checked: ``namespace`` (a module's globals)
    gets the wrapped functions."""
    for name in names:
        value = namespace[name]
        if isinstance(value, type):
            if not issubclass(value, BaseException):
                check_class(value, "")
        elif callable(value):
            namespace[name] = checked(value, name)
