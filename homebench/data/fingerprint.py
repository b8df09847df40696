"""Content fingerprints of grid images: what a generated image must keep on any processor.

Generated worlds are rendered with floating point whose last bits depend on the processor:
OpenCV's and NumPy's vectorised code paths (SSE, AVX2, AVX-512, with or without fused
multiply-add) and the vector math libraries behind ``sin``, ``exp`` or ``pow`` round
differently. The renderer quantises to 8 bits at the end, so such a difference changes a pixel
only when its value lies within a rounding error of a half grey level: on another x86-64
machine a few images of a set differ from the reference sums in a handful of pixels, by one
grey level. Bit-exact images across processors would need every stage in exact arithmetic;
homebench does not promise that. It promises the **fingerprint**: the same world, camera and
pose give, on any processor, an image whose fingerprint matches the reference one within
:data:`TOLERANCE`. A wrong image (another pose, seed, variant, exposure or a corrupted file)
does not.

A fingerprint is ``"<mean>:<gradient>:<dhash>"``, all from exact integer arithmetic on the
8-bit pixels (so the fingerprint itself is the same on every processor):

- ``mean``: the mean grey level in hundredths, rounded half up;
- ``gradient``: the mean absolute difference between horizontal neighbours, in hundredths
  (falls with blur, rises with noise);
- ``dhash``: 264 bits, a difference hash: the image cut into 12 x 12 blocks; one bit per pair
  of horizontal and of vertical neighbours, set when the first block is darker (compared as
  exact rational means). 12 x 12 blocks keep enough of a raw image's annulus that the black
  frame around it does not make every raw image look alike.

Two fingerprints match when the means and the gradients differ by at most 0.2 grey levels and
0.5 % (and 0.05 levels), and the hashes in at most 4 of 264 bits. A pixel changed by one level
moves the mean of a 360 x 95 panorama by 3e-5 levels and tips a hash bit only where two
neighbouring blocks are equal to within that; the neighbouring grid position 0.3 m away changes
16-50 bits (measured on the generated worlds, both image kinds).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

#: Hash blocks per side; the hash has 2 * _BLOCKS * (_BLOCKS - 1) bits.
_BLOCKS = 12
_HASH_DIGITS = (2 * _BLOCKS * (_BLOCKS - 1) + 3) // 4


@dataclass(frozen=True)
class Tolerance:
    """How far two fingerprints of the same image content may differ."""

    mean_centi: int = 20  # hundredths of a grey level
    gradient_relative: float = 0.005
    gradient_centi: int = 5
    hash_bits: int = 4


TOLERANCE = Tolerance()


def _edges(n: int, parts: int) -> NDArray[np.intp]:
    """Start indices of ``parts`` near-equal integer blocks of ``n`` items."""
    return (np.arange(parts) * n) // parts


def _centi(total: int, count: int) -> int:
    """round(100 * total / count), half up, in exact integers."""
    return (200 * total + count) // (2 * count)


def fingerprint(image: NDArray[np.uint8]) -> str:
    """The fingerprint of a grey image (height, width) uint8 (see the module docstring)."""
    a = np.asarray(image)
    if a.dtype != np.uint8 or a.ndim != 2 or min(a.shape) < 2:
        raise ValueError(f"need a grey uint8 image of at least 2 x 2, got {a.dtype} {a.shape}")
    pixels = a.astype(np.int64)
    h, w = a.shape
    mean = _centi(int(pixels.sum()), h * w)
    gradient = _centi(int(np.abs(np.diff(pixels, axis=1)).sum()), h * (w - 1))
    # an image under 12 pixels on a side is repeated pixel by pixel to make whole blocks
    pixels = np.repeat(pixels, -(-_BLOCKS // h), axis=0)
    pixels = np.repeat(pixels, -(-_BLOCKS // w), axis=1)
    h, w = pixels.shape
    rows, cols = _edges(h, _BLOCKS), _edges(w, _BLOCKS)
    sums = np.add.reduceat(np.add.reduceat(pixels, rows, axis=0), cols, axis=1)
    sizes = np.outer(np.diff([*rows, h]), np.diff([*cols, w]))
    # exact comparisons of rational means: s_a / n_a < s_b / n_b  <=>  s_a n_b < s_b n_a
    across = sums[:, :-1] * sizes[:, 1:] < sums[:, 1:] * sizes[:, :-1]
    down = sums[:-1, :] * sizes[1:, :] < sums[1:, :] * sizes[:-1, :]
    bits = int("".join("1" if b else "0" for b in (*across.ravel(), *down.ravel())), 2)
    return f"{mean}:{gradient}:{bits:0{_HASH_DIGITS}x}"


def parse(value: str) -> tuple[int, int, int]:
    """(mean, gradient, hash) of a fingerprint string; ValueError if it is not one."""
    parts = value.split(":")
    if len(parts) != 3 or len(parts[2]) != _HASH_DIGITS:
        raise ValueError(f"not a fingerprint: {value!r}")
    return int(parts[0]), int(parts[1]), int(parts[2], 16)


def matches(a: str, b: str, tolerance: Tolerance = TOLERANCE) -> bool:
    """Whether two fingerprints describe the same content within ``tolerance``."""
    (mean_a, grad_a, hash_a), (mean_b, grad_b, hash_b) = parse(a), parse(b)
    gradient_slack = max(tolerance.gradient_centi, tolerance.gradient_relative * max(grad_a, 1))
    return (
        abs(mean_a - mean_b) <= tolerance.mean_centi
        and abs(grad_a - grad_b) <= gradient_slack
        and bin(hash_a ^ hash_b).count("1") <= tolerance.hash_bits
    )
