"""cv::rawgment from Python: noise-accounted RAW augmentation with numpy arrays in and out.

Every function and class of the C++ module ``cv::rawgment`` is here under its C++ name
(``rawgment.colorJitter``, ``rawgment.NoiseModel``, ...), with the C++ documentation as its docstring.
Mosaics are ``HxW`` numpy arrays of ``uint16`` or ``float32``, as ``cv2.imread(path,
cv2.IMREAD_UNCHANGED)`` gives them; they are read without a copy. C++ errors raise
``rawgment.error`` (a ``RuntimeError``) with the C++ message. Heavy calls release the GIL, so Python
threads run them in parallel. Same seed, same bits as the C++ API, on any thread count and CPU path.

Optional parts: ``rawgment.torch`` (PyTorch transform and dataset; needs torch) and ``rawgment.batch``
(folder augmentation on one machine or a Dask cluster; needs dask.distributed for a cluster).
"""
import functools as _functools
import os as _os
import numbers as _numbers

import numpy as _np

from . import _rawgment
from ._rawgment import *  # noqa: F401,F403 - the C++ API, under its C++ names
from ._rawgment import __version__, _apps, _benchmark, _testing, error  # noqa: F401

__all__ = [name for name in dir(_rawgment) if not name.startswith("_")]

# Classes that hold values (option structs, results): keyword construction comes from C++; here they
# also get a readable repr, value equality and pickling (a DataLoader or Dask may ship them to workers).
_HANDLES = {"SensorSimulator", "BurstStatistics"}


def _fields(cls):
    names = []
    for base in reversed(cls.__mro__):
        for key, value in vars(base).items():
            if type(value) is property and not key.startswith("_") and key not in names:
                names.append(key)
    return names


def _show(value):
    if isinstance(value, _np.ndarray):
        return "<array %s %s>" % ("x".join(str(s) for s in value.shape), value.dtype)
    return repr(value)


def _same(a, b):
    if isinstance(a, _np.ndarray) or isinstance(b, _np.ndarray):
        return isinstance(a, _np.ndarray) and isinstance(b, _np.ndarray) and a.dtype == b.dtype and \
            _np.array_equal(a, b)
    return a == b


def _rebuild(cls, state):
    obj = cls()
    for key, value in state.items():
        setattr(obj, key, value)
    return obj


def _load_dark_frame_bank(path):
    """A pickled DarkFrameBank in another process: the bank its path names (DarkFrameBank.__reduce__)."""
    return _rawgment.DarkFrameBank.load(path)


def _add_value_behaviour(cls):
    fields = _fields(cls)
    cls._fields = tuple(fields)
    cls.__repr__ = lambda self: "%s(%s)" % (
        type(self).__name__, ", ".join("%s=%s" % (f, _show(getattr(self, f))) for f in fields))
    cls.__eq__ = lambda self, other: type(self) is type(other) and all(
        _same(getattr(self, f), getattr(other, f)) for f in fields)
    cls.__hash__ = None
    # Rebuilt field by field without validation, so that any object the C++ side holds round-trips; a class
    # that goes to other processes otherwise (a DarkFrameBank, by its path) keeps its own.
    if "__reduce__" not in cls.__dict__:
        cls.__reduce__ = lambda self: (_rebuild, (type(self), {f: getattr(self, f) for f in fields}))


for _name in __all__:
    _cls = getattr(_rawgment, _name)
    if isinstance(_cls, type) and _name not in _HANDLES and not hasattr(_cls, "__members__") and \
            not issubclass(_cls, BaseException) and _fields(_cls):
        _add_value_behaviour(_cls)
del _name, _cls


# pybind11 answers a call whose arguments do not convert with "incompatible function arguments" and the
# whole signature, naming no argument. Module functions are wrapped so that the error names the first
# argument that does not fit and what it must be; any other exception passes through unchanged.
_SEED_LIMIT = 2 ** 64


def _parameters(doc, name):
    """(name, type) of each parameter of the first signature in a pybind11 docstring; '*' is skipped."""
    for line in (doc or "").splitlines():
        line = line.strip()
        if line[:1].isdigit() and ". " in line:
            line = line.split(". ", 1)[1]
        if not line.startswith(name + "("):
            continue
        text, depth, parts, current = line[len(name) + 1:], 0, [], ""
        for ch in text:
            if ch in "([{":
                depth += 1
            elif ch in ")]}":
                if depth == 0:
                    break
                depth -= 1
            if ch == "," and depth == 0:
                parts.append(current)
                current = ""
            else:
                current += ch
        parts.append(current)
        params = []
        for part in parts:
            part = part.split("=", 1)[0].strip()
            if not part or part in ("*", "/"):
                continue
            pname, _, ptype = part.partition(":")
            params.append((pname.strip(), ptype.strip()))
        return params
    return None


def _misfit(pname, ptype, value):
    """Why `value` cannot be parameter `pname` of C++ type `ptype` (as pybind11 spells it), or None."""
    if ptype.startswith("rawgment._rawgment."):
        cls = getattr(_rawgment, ptype.rsplit(".", 1)[1], None)
        if isinstance(cls, type) and not isinstance(value, cls):
            return "must be a rawgment.%s, not %s" % (cls.__name__, type(value).__name__)
    elif ptype == "int":
        if not isinstance(value, _numbers.Integral):
            return "must be an int, not %s" % type(value).__name__
        if "seed" in pname.lower() and not 0 <= int(value) < _SEED_LIMIT:
            return "must be a seed, an integer from 0 to %d (got %d)" % (_SEED_LIMIT - 1, value)
        # pybind11 shows C++'s int and its 64-bit integers alike as "int"; a value it refused that does not
        # fit 32 bits was refused for its size.
        if "seed" not in pname.lower() and not -2 ** 31 <= int(value) < 2 ** 31:
            return "must fit a 32-bit int, from %d to %d (got %d)" % (-2 ** 31, 2 ** 31 - 1, value)
    elif ptype == "float":
        if not isinstance(value, _numbers.Real):
            return "must be a number, not %s" % type(value).__name__
    elif ptype == "str":
        if not isinstance(value, str):
            return "must be a str, not %s" % type(value).__name__
    elif ptype == "bool":
        if not isinstance(value, (bool, _np.bool_)):
            return "must be a bool, not %s" % type(value).__name__
    elif value is None and ptype != "object":
        return "must be %s, not None" % ptype
    return None


def _explain(fn, name, args, kwargs):
    params = _parameters(fn.__doc__, name)
    if params is None:
        return None
    names = [p for p, _ in params]
    if len(args) > len(params):
        return "%s(): %d positional arguments given, it takes at most %d" % (name, len(args), len(params))
    bound = dict(zip(names, args))
    for key, value in kwargs.items():
        if key not in names:
            return "%s(): unknown keyword argument '%s' (its arguments: %s)" % (name, key, ", ".join(names))
        bound[key] = value
    for pname, ptype in params:
        if pname in bound:
            why = _misfit(pname, ptype, bound[pname])
            if why:
                return "%s(): argument '%s' %s" % (name, pname, why)
    return None


def _explained(fn):
    name = fn.__name__

    @_functools.wraps(fn)
    def call(*args, **kwargs):
        # A pathlib.Path is as good a path as a str.
        args = tuple(_os.fspath(a) if isinstance(a, _os.PathLike) else a for a in args)
        kwargs = {k: _os.fspath(v) if isinstance(v, _os.PathLike) else v for k, v in kwargs.items()}
        try:
            return fn(*args, **kwargs)
        except TypeError as e:
            if "incompatible function arguments" not in str(e):
                raise
            why = _explain(fn, name, args, kwargs)
            if why is None:
                raise
            raise TypeError(why) from None

    return call


def _explainedProperty(cls, name, prop):
    """The property with a setter whose refusal names the field and why, not pybind11's generic message."""
    def fset(obj, value):
        try:
            prop.fset(obj, value)
        except TypeError as e:
            if "incompatible function arguments" not in str(e):
                raise
            ptype = "int" if isinstance(prop.fget(obj), int) and not isinstance(prop.fget(obj), bool) else ""
            why = _misfit(name, ptype, value) if ptype else None
            raise TypeError("%s.%s %s" % (cls.__name__, name, why or "cannot be set to %r (a %s)" % (
                value, type(value).__name__))) from None

    return property(prop.fget, fset, prop.fdel, prop.__doc__)


for _name in __all__:
    _fn = getattr(_rawgment, _name)
    if type(_fn).__name__ == "builtin_function_or_method":
        globals()[_name] = _explained(_fn)
    elif isinstance(_fn, type):
        for _field, _prop in list(vars(_fn).items()):
            if isinstance(_prop, property) and _prop.fset is not None:
                setattr(_fn, _field, _explainedProperty(_fn, _field, _prop))
del _name, _fn
