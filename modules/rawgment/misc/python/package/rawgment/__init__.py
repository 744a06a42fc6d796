"""cv2.rawgment: OpenCV's generated binding of cv::rawgment, with exact integer samples.

OpenCV 4.6's cv2 casts every int64 or uint64 numpy array to int32 before C++ sees it, so values beyond
32 bits wrap silently: shapiroWilk([1, 2, 3, 2**40]) gave W 0.9929 instead of 0.6298. The functions below
take any numeric depth; here an integer array wider than 32 bits reaches them as float64, which holds every
integer up to 2**53 exactly, and one beyond that is refused. Every other name is the generated binding's
(OpenCV's loader copies them in; the originals stay in ``_native``). Functions that take only uint16 or
float32 mosaics refuse the int32 that cv2 makes of such an array, so they need no wrapper.
"""
import numpy as _np

_EXACT_LIMIT = 2 ** 53


def _exact(value, name):
    if isinstance(value, (list, tuple)) and any(isinstance(v, _np.ndarray) for v in value):
        return type(value)(_exact(v, name) for v in value)
    if not isinstance(value, _np.ndarray) or value.dtype.kind not in "iu" or value.dtype.itemsize < 4:
        return value
    if value.dtype == _np.int32:
        return value
    if value.size and (int(value.max()) > _EXACT_LIMIT or int(value.min()) < -_EXACT_LIMIT):
        raise ValueError("argument '%s': integers beyond 2**53 in a %s array cannot be taken exactly "
                         "(cv2 would cast them to int32, and float64 would round them)" % (name, value.dtype))
    return value.astype(_np.float64)


def _exact_integers(name):
    def call(*args, **kwargs):
        args = [_exact(a, "#%d" % k) for k, a in enumerate(args)]
        kwargs = {k: _exact(v, k) for k, v in kwargs.items()}
        return getattr(_native, name)(*args, **kwargs)  # noqa: F821 (set by OpenCV's loader)

    call.__name__ = name
    call.__doc__ = ("cv2.rawgment._native.%s, with integer arrays wider than 32 bits passed exactly as float64 "
                    "(see this module's documentation)" % name)
    return call


shapiroWilk = _exact_integers("shapiroWilk")
shapiroWilkBatch = _exact_integers("shapiroWilkBatch")
shapiroWilkBurst = _exact_integers("shapiroWilkBurst")
splitCfaPlanes = _exact_integers("splitCfaPlanes")
mergeCfaPlanes = _exact_integers("mergeCfaPlanes")
