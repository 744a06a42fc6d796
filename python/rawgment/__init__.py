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


def _add_value_behaviour(cls):
    fields = _fields(cls)
    cls._fields = tuple(fields)
    cls.__repr__ = lambda self: "%s(%s)" % (
        type(self).__name__, ", ".join("%s=%s" % (f, _show(getattr(self, f))) for f in fields))
    cls.__eq__ = lambda self, other: type(self) is type(other) and all(
        _same(getattr(self, f), getattr(other, f)) for f in fields)
    cls.__hash__ = None
    # Rebuilt field by field without validation, so that any object the C++ side holds round-trips.
    cls.__reduce__ = lambda self: (_rebuild, (type(self), {f: getattr(self, f) for f in fields}))


for _name in __all__:
    _cls = getattr(_rawgment, _name)
    if isinstance(_cls, type) and _name not in _HANDLES and not hasattr(_cls, "__members__") and \
            not issubclass(_cls, BaseException) and _fields(_cls):
        _add_value_behaviour(_cls)
del _name, _cls
