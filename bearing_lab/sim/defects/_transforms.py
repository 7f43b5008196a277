"""The half-space solver's convolution by FFT (:meth:`.halfspace_solver.HalfSpace.displacement`), pruned and
in single precision, with scipy's pocketfft called directly.

Why apart, and why not through ``scipy.fft``'s functions: on the tables' grids (boxes of about
20 x 15 to 50 x 30 cells, a few to a few dozen problems a batch) one convolution costs 3-20 µs of
arithmetic per problem, and each of the four ``scipy.fft`` calls it takes adds about 5 µs of
dispatch (the backend protocol, argument checks, the copy that pads the input) per batch: measured,
a tenth to a seventh of an aligned defect's table and of the slot's.  The transforms here are
scipy's own (pocketfft, the module ``scipy.fft`` calls), given preallocated, already padded arrays
and writing in place.  Where that module is missing or does not answer as expected (another scipy
version), the public ``scipy.fft`` functions do the same steps (:data:`DIRECT` says which).

The steps: the pressure (K, nx, ny) in the corner of a zero (K, nx, my) array, a real transform of
its rows, the columns padded to mx and transformed, the product with the kernel's spectrum, the
inverse along the columns, of which the first nx rows are kept, and the inverse of those rows, of
which the first ny columns are kept.  Both inverses are unnormalised: the kernel's spectrum carries
the 1 / (mx my) (:func:`kernel_spectrum`).
"""
from __future__ import annotations

import lazy_loader as lazy
import numpy as np

# loaded at the first convolution (scipy.fft carries pocketfft as its default backend)
sfft = lazy.load("scipy.fft", suppress_warning=True)

#: [True] where the transforms call pocketfft directly, [False] where they go through the public
#: ``scipy.fft`` functions; decided at the first use (scipy loaded then, not at import)
DIRECT: list[bool] = []


def kernel_spectrum(full: np.ndarray, scale: float) -> np.ndarray:
    """The spectrum (complex64, (mx, my // 2 + 1)) of the kernel's periodic array ``full`` (mx, my),
    divided by ``scale`` (a kernel of order one: no float32 product falls into the subnormal range,
    where the arithmetic is a hundred times slower) and by mx my (the inverses are unnormalised)."""
    mx, my = full.shape
    return (sfft.rfft2(full, workers=1) / (scale * mx * my)).astype(np.complex64)


def _direct() -> bool:
    """Whether pocketfft answers as scipy.fft does (a small convolution both ways)."""
    if not DIRECT:
        try:
            rng = np.random.default_rng(0)
            p = rng.random((2, 3, 4))
            kf = kernel_spectrum(rng.random((6, 8)), 1.0)
            ok = bool(np.allclose(_convolve(p, kf, 6, 8, True), _convolve(p, kf, 6, 8, False),
                                  rtol=1e-5, atol=1e-6))
        except Exception:        # pragma: no cover - another scipy: no such module, or other arguments
            ok = False
        DIRECT.append(ok)
    return DIRECT[0]


def convolve(p: np.ndarray, kf: np.ndarray, mx: int, my: int, scale: float) -> np.ndarray:
    """``scale`` times the linear convolution of ``p`` (..., nx, ny) with the kernel whose spectrum is
    ``kf`` (:func:`kernel_spectrum`, period (mx, my), mx >= 2 nx - 1, my >= 2 ny - 1), on the nx x ny
    cells of ``p``: float64, shaped as ``p``."""
    u = _convolve(p, kf, mx, my, _direct())
    return np.multiply(u, scale, dtype=np.float64).reshape(p.shape)


def _convolve(p, kf, mx, my, direct):
    """The unscaled convolution, float32 (K, nx, ny) (a view)."""
    nx, ny = p.shape[-2:]
    p = p.reshape((-1, nx, ny))
    k = p.shape[0]
    buf = np.zeros((k, nx, my), dtype=np.float32)
    buf[:, :, :ny] = p
    a = np.zeros((k, mx, my // 2 + 1), dtype=np.complex64)
    if direct:
        pf = sfft._pocketfft.pypocketfft      # scipy's pocketfft module, as scipy.fft calls it
        pf.r2c(buf, (2,), True, 0, a[:, :nx], 1)
        pf.c2c(a, (1,), True, 0, a, 1)
        a *= kf
        pf.c2c(a, (1,), False, 0, a, 1)
        u = pf.c2r(a[:, :nx], (2,), my, False, 0, None, 1)
    else:
        a[:, :nx] = sfft.rfft(buf, axis=-1, workers=1)
        a = sfft.fft(a, axis=-2, workers=1, overwrite_x=True)
        a *= kf
        a = sfft.ifft(a, axis=-2, norm="forward", workers=1, overwrite_x=True)
        u = sfft.irfft(a[:, :nx], n=my, axis=-1, norm="forward", workers=1)
    return u[:, :, :ny]
