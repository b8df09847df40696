"""Procedural grey-level textures (albedo in [0, 1], float32, row 0 at the top).

Every painter takes a numpy ``Generator`` and a pixel shape ``(rows, cols)`` and draws only from
that generator, so a seeded layout always paints the same room.
"""

from __future__ import annotations

import importlib.util
import string
from collections.abc import Callable
from functools import lru_cache
from pathlib import Path

import cv2
import numpy as np
from numpy.typing import NDArray

from homebench.errors import DataError

Texture = NDArray[np.float32]
Rng = np.random.Generator
#: A painter bound to its generator: pixel shape (rows, cols) -> texture of that shape.
Painter = Callable[[tuple[int, int]], Texture]

#: matplotlib's bundled sample images used as posters.
SAMPLE_IMAGES = ("grace_hopper.jpg", "Minduka_Present_Blue_Pack.png", "logo2.png")
#: matplotlib's bundled elevation arrays, shown as grey images: (file, array name).
SAMPLE_ARRAYS = (("jacksboro_fault_dem.npz", "elevation"), ("topobathy.npz", "topo"))


# --------------------------------------------------------------------------- basics


def noise(rng: Rng, shape: tuple[int, int], cell: float, octaves: int = 3) -> Texture:
    """Smooth fractal value noise of ``shape``, zero mean, roughly unit std; ``cell`` in px."""
    h, w = shape
    out = np.zeros(shape, np.float32)
    amplitude, total = 1.0, 0.0
    for _ in range(octaves):
        gh, gw = max(2, int(np.ceil(h / cell)) + 1), max(2, int(np.ceil(w / cell)) + 1)
        grid = rng.standard_normal((gh, gw)).astype(np.float32)
        out += amplitude * cv2.resize(grid, (w, h), interpolation=cv2.INTER_CUBIC)
        total += amplitude
        amplitude *= 0.5
        cell = max(1.0, cell / 2.0)
    return out / total


def fit(image: NDArray, shape: tuple[int, int]) -> Texture:
    """Resize ``image`` (any 2-D array) to ``shape`` (rows, cols), float32."""
    interp = cv2.INTER_AREA if image.shape[0] > shape[0] else cv2.INTER_LINEAR
    return cv2.resize(image.astype(np.float32), (shape[1], shape[0]), interpolation=interp)


def normalise(image: NDArray, low: float = 0.05, high: float = 0.95) -> Texture:
    """Stretch ``image`` linearly to [low, high]."""
    a = image.astype(np.float32)
    span = float(a.max() - a.min()) or 1.0
    return low + (high - low) * (a - a.min()) / span


def fill_rect(tex: Texture, r0: int, c0: int, r1: int, c1: int, value: float | Texture) -> None:
    """Paint rows [r0, r1) x cols [c0, c1) (clipped to the texture) with a value or a patch."""
    h, w = tex.shape
    a0, b0, a1, b1 = max(r0, 0), max(c0, 0), min(r1, h), min(c1, w)
    if a1 <= a0 or b1 <= b0:
        return
    if isinstance(value, np.ndarray):
        value = value[a0 - r0 : a1 - r0, b0 - c0 : b1 - c0]
    tex[a0:a1, b0:b1] = value


def frame(tex: Texture, r0: int, c0: int, r1: int, c1: int, width: int, value: float) -> None:
    """Draw a rectangular border of ``width`` px inside the rectangle."""
    fill_rect(tex, r0, c0, r0 + width, c1, value)
    fill_rect(tex, r1 - width, c0, r1, c1, value)
    fill_rect(tex, r0, c0, r1, c0 + width, value)
    fill_rect(tex, r0, c1 - width, r1, c1, value)


def random_word(rng: Rng, n: int) -> str:
    letters = string.ascii_uppercase + string.digits
    return "".join(rng.choice(list(letters), size=n))


def text_lines(
    tex: Texture, rng: Rng, rect: tuple[int, int, int, int], value: float, scale: float
) -> None:
    """Fill ``rect`` (r0, c0, r1, c1) with lines of random words in a Hershey font."""
    r0, c0, r1, c1 = rect
    line = max(4, int(30 * scale))
    thickness = max(1, int(round(2 * scale)))
    ink = np.zeros(tex.shape, np.uint8)  # cv2.putText draws on 8-bit images only
    for baseline in range(r0 + line, r1 - 2, int(line * 1.5)):
        x = c0 + 2
        while x < c1 - 4 * line:
            word = random_word(rng, int(rng.integers(2, 8)))
            cv2.putText(
                ink,
                word,
                (x, baseline),
                cv2.FONT_HERSHEY_SIMPLEX,
                scale,
                255,
                thickness,
                cv2.LINE_AA,
            )
            x += int(line * 0.6 * (len(word) + 1))
    alpha = ink.astype(np.float32) / 255.0
    tex *= 1.0 - alpha
    tex += value * alpha


def blank(shape: tuple[int, int], value: float) -> Texture:
    return np.full(shape, value, np.float32)


# --------------------------------------------------------------------------- sample data


def _sample_path(name: str) -> Path:
    """The path of matplotlib's bundled sample file ``name``, found without importing
    matplotlib (0.3 s per generating process): its package's ``mpl-data/sample_data``."""
    spec = importlib.util.find_spec("matplotlib")
    if spec is None or spec.origin is None:
        raise DataError("generated worlds need matplotlib's sample data: pip install matplotlib")
    return Path(spec.origin).parent / "mpl-data" / "sample_data" / name


@lru_cache(maxsize=8)
def _sample_image(name: str) -> Texture:
    buffer = np.frombuffer(_sample_path(name).read_bytes(), np.uint8)
    image = cv2.imdecode(buffer, cv2.IMREAD_UNCHANGED)
    if image.ndim == 3 and image.shape[2] == 4:  # composite on white
        alpha = image[..., 3:4].astype(np.float32) / 255.0
        image = (image[..., :3] * alpha + 255.0 * (1.0 - alpha)).astype(np.uint8)
    if image.ndim == 3:
        image = cv2.cvtColor(image, cv2.COLOR_BGR2GRAY)
    return normalise(image, 0.0, 1.0)


@lru_cache(maxsize=4)
def _sample_array(name: str, key: str) -> Texture:
    with np.load(_sample_path(name), allow_pickle=False) as data:
        return normalise(np.asarray(data[key], np.float32), 0.0, 1.0)


# --------------------------------------------------------------------------- posters


def poster(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A framed poster: a sample photo, an elevation map, shapes or text."""
    h, w = shape
    kind = int(rng.integers(0, 6))
    if kind < 3:
        which = SAMPLE_IMAGES[int(rng.integers(len(SAMPLE_IMAGES)))]
        content = fit(_sample_image(which), shape)
    elif kind == 3:
        name, key = SAMPLE_ARRAYS[int(rng.integers(len(SAMPLE_ARRAYS)))]
        content = fit(_sample_array(name, key), shape)
    elif kind == 4:
        content = shapes_picture(rng, shape)
    else:
        content = blank(shape, float(rng.uniform(0.75, 0.95)))
        fill_rect(content, h // 12, w // 12, h // 4, w - w // 12, float(rng.uniform(0.1, 0.3)))
        text_lines(content, rng, (h // 3, w // 12, h - h // 12, w - w // 12), 0.1, 0.6)
    content = normalise(content, float(rng.uniform(0.03, 0.15)), float(rng.uniform(0.8, 0.97)))
    frame(content, 0, 0, h, w, max(2, min(h, w) // 30), float(rng.uniform(0.05, 0.3)))
    return content


def shapes_picture(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Random filled circles, rectangles and lines on a noisy background."""
    h, w = shape
    tex = 0.5 + 0.15 * noise(rng, shape, max(h, w) / 3)
    for _ in range(int(rng.integers(6, 16))):
        v = float(rng.uniform(0.0, 1.0))
        x, y = int(rng.integers(0, w)), int(rng.integers(0, h))
        size = int(rng.integers(max(2, min(h, w) // 12), max(3, min(h, w) // 3)))
        pick = rng.integers(3)
        if pick == 0:
            cv2.circle(tex, (x, y), size, v, -1, cv2.LINE_AA)
        elif pick == 1:
            cv2.rectangle(tex, (x, y), (x + size, y + int(size * rng.uniform(0.3, 2))), v, -1)
        else:
            x2, y2 = int(rng.integers(0, w)), int(rng.integers(0, h))
            cv2.line(tex, (x, y), (x2, y2), v, max(1, size // 6), cv2.LINE_AA)
    return tex


# --------------------------------------------------------------------------- wall fixtures


def door(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A panelled door with its frame and handle (frame included in ``shape``)."""
    h, w = shape
    leaf = float(rng.uniform(0.35, 0.7))
    tex = leaf + 0.05 * noise(rng, shape, w / 2)
    f = max(2, w // 14)
    frame(tex, 0, 0, h + f, w, f, float(np.clip(leaf + rng.choice([-0.25, 0.25]), 0.05, 0.95)))
    for r0, r1 in ((h // 10, h * 9 // 20), (h // 2, h * 9 // 10)):
        frame(tex, r0, w // 5, r1, w - w // 5, max(1, f // 2), leaf - 0.12)
    handle(tex, h * 53 // 100, w - w // 7, f)
    return tex


def handle(tex: Texture, row: int, col: int, size: int) -> None:
    """A lever handle ending at (``row``, ``col``) px, ``size`` px thick, and a key hole below."""
    fill_rect(tex, row - size // 2, col - 2 * size, row + size // 2, col, 0.9)
    fill_rect(tex, row + size, col - size // 2, row + 2 * size, col, 0.05)


def curtains_closed(
    rng: Rng,
    shape: tuple[int, int],
    shade: tuple[float, float] = (0.4, 0.7),
    contrast: float = 1.0,
) -> Texture:
    """Drawn curtains: vertical folds over a faint woven pattern; base grey drawn from ``shade``,
    ``contrast`` scales folds and weave (1: a mid-grey curtain's)."""
    h, w = shape
    base = float(rng.uniform(*shade))
    period = float(rng.uniform(6, 14))
    cols = np.arange(w, dtype=np.float32)
    phase = 2 * np.pi * cols / period + 0.8 * noise(rng, (1, w), w / 8)[0]
    folds = 0.12 * contrast * np.sin(phase)
    tex = base + folds[None, :] + 0.04 * contrast * noise(rng, shape, 6, octaves=2)
    pattern_step = int(rng.integers(12, 30))
    tex[::pattern_step, :] -= 0.08 * contrast
    return tex


def outside_view(rng: Rng, shape: tuple[int, int]) -> Texture:
    """The view through a window: bright sky, a tree line and buildings (relative luminance)."""
    h, w = shape
    tex = np.empty(shape, np.float32)
    tex[:] = np.linspace(1.0, 0.8, h, dtype=np.float32)[:, None]
    horizon = h * float(rng.uniform(0.45, 0.65))
    skyline = horizon + h * 0.2 * noise(rng, (1, w), w / 6)[0]
    rows = np.arange(h, dtype=np.float32)[:, None]
    trees = rows > skyline[None, :]
    tex[trees] = 0.25 + 0.1 * noise(rng, shape, 4)[trees]
    for _ in range(int(rng.integers(1, 4))):
        c0 = int(rng.integers(0, w))
        bw, top = int(rng.integers(w // 8, w // 3)), int(horizon - rng.uniform(0, h * 0.3))
        fill_rect(tex, top, c0, h, c0 + bw, float(rng.uniform(0.45, 0.7)))
        for r in range(top + 6, h - 4, 12):  # windows of the building
            for c in range(c0 + 4, c0 + bw - 6, 10):
                fill_rect(tex, r, c, r + 5, c + 5, 0.2)
    return tex


def window(rng: Rng, shape: tuple[int, int], frame_px: int) -> tuple[Texture, Texture, Texture]:
    """A window with sill: (albedo with curtains shut, albedo with them open, glow mask).

    The glow mask (0..1) is the relative luminance of the outside view where it shows through.
    """
    h, w = shape
    closed = curtains_closed(rng, shape)
    view = outside_view(rng, shape)
    opened = blank(shape, 0.0)
    glow = view.copy()
    side = w // 6
    fill_rect(opened, 0, 0, h, side, curtains_closed(rng, (h, side)))
    fill_rect(opened, 0, w - side, h, w, curtains_closed(rng, (h, side)))
    glow[:, :side] = 0.0
    glow[:, w - side :] = 0.0
    for tex in (closed, opened, glow):
        frame(tex, 0, 0, h, w, frame_px, 0.85 if tex is not glow else 0.0)
    bars = (w // 2, h // 2)
    fill_rect(opened, 0, bars[0] - frame_px // 2, h, bars[0] + frame_px // 2, 0.85)
    fill_rect(glow, 0, bars[0] - frame_px // 2, h, bars[0] + frame_px // 2, 0.0)
    return closed, opened, glow


def radiator(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A ribbed radiator: bright fins with dark gaps and a pipe."""
    h, w = shape
    tex = blank(shape, float(rng.uniform(0.75, 0.9)))
    period = int(rng.integers(4, 7))
    tex[:, ::period] = 0.35
    tex[:, 1::period] *= 0.8
    fill_rect(tex, 0, 0, max(2, h // 12), w, 0.95)
    fill_rect(tex, h - max(2, h // 12), 0, h, w, 0.5)
    return tex


def bookshelf(rng: Rng, shape: tuple[int, int], board_px: int) -> Texture:
    """Shelves with books of random widths, heights and greys, some with spine labels."""
    h, w = shape
    wood = float(rng.uniform(0.3, 0.6))
    tex = wood - 0.15 + 0.03 * noise(rng, shape, 20)
    n_boards = max(2, h // int(rng.integers(30, 40)))
    pitch = h / n_boards
    for k in range(n_boards):
        bottom = int((k + 1) * pitch)
        fill_rect(tex, bottom - board_px, 0, bottom, w, wood)
        c = board_px
        while c < w - board_px:
            bw = int(rng.integers(2, 7))
            bh = int(pitch * rng.uniform(0.5, 0.9))
            grey = float(rng.uniform(0.05, 0.95))
            fill_rect(tex, bottom - board_px - bh, c, bottom - board_px, c + bw, grey)
            if bw >= 4 and rng.random() < 0.5:
                label = 1.0 - grey
                fill_rect(
                    tex,
                    bottom - board_px - bh * 2 // 3,
                    c + 1,
                    bottom - board_px - bh // 2,
                    c + bw - 1,
                    label,
                )
            c += bw + int(rng.integers(0, 2))
            if rng.random() < 0.05:
                c += int(rng.integers(5, 20))
    frame(tex, 0, 0, h, w, board_px, wood)
    return tex


def whiteboard(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A whiteboard with scribbles, a diagram and text."""
    h, w = shape
    tex = blank(shape, 0.93)
    pts = rng.integers(0, [w, h], size=(int(rng.integers(3, 8)), 2)).astype(np.int32)
    cv2.polylines(tex, [pts], False, 0.15, 2, cv2.LINE_AA)
    for _ in range(int(rng.integers(2, 5))):
        c = rng.integers(0, [w, h])
        cv2.circle(
            tex, (int(c[0]), int(c[1])), int(rng.integers(5, max(6, h // 5))), 0.2, 2, cv2.LINE_AA
        )
    text_lines(tex, rng, (h // 10, w // 20, h - h // 10, w // 2), 0.15, 0.5)
    frame(tex, 0, 0, h, w, 3, 0.6)
    return tex


def clock(rng: Rng, size: int) -> Texture:
    """A round wall clock on a transparent-looking square (the wall shows as NaN)."""
    tex = blank((size, size), np.nan)
    c, r = size // 2, size // 2 - 1
    cv2.circle(tex, (c, c), r, 0.95, -1, cv2.LINE_AA)
    cv2.circle(tex, (c, c), r, 0.1, max(2, size // 15), cv2.LINE_AA)
    for k in range(12):
        a = k * np.pi / 6
        p1 = (int(c + 0.75 * r * np.cos(a)), int(c + 0.75 * r * np.sin(a)))
        p2 = (int(c + 0.88 * r * np.cos(a)), int(c + 0.88 * r * np.sin(a)))
        cv2.line(tex, p1, p2, 0.1, 2, cv2.LINE_AA)
    for length, a in ((0.5, rng.uniform(0, 2 * np.pi)), (0.8, rng.uniform(0, 2 * np.pi))):
        tip = (int(c + length * r * np.cos(a)), int(c + length * r * np.sin(a)))
        cv2.line(tex, (c, c), tip, 0.05, max(2, size // 20), cv2.LINE_AA)
    return tex


def notice_board(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A cork board covered with notes, some with text."""
    h, w = shape
    tex = 0.45 + 0.06 * noise(rng, shape, 2, octaves=2)
    for _ in range(int(h * w / 900) + 3):
        nh, nw = int(rng.integers(12, 30)), int(rng.integers(10, 24))
        r0, c0 = int(rng.integers(-5, h - 5)), int(rng.integers(-5, w - 5))
        grey = float(rng.uniform(0.6, 1.0))
        fill_rect(tex, r0, c0, r0 + nh, c0 + nw, grey)
        if rng.random() < 0.7:
            text_lines(tex, rng, (r0, c0, r0 + nh, c0 + nw + 20), 0.1, 0.25)
    frame(tex, 0, 0, h, w, 3, 0.3)
    return tex


def pipes(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Horizontal pipes and a cable tray (rows of light and dark bands); NaN = wall."""
    h, w = shape
    tex = blank(shape, np.nan)
    r = 0
    while r < h - 3:
        width = int(rng.integers(2, 7))
        grey = float(rng.uniform(0.3, 0.95))
        fill_rect(tex, r, 0, r + width, w, grey)
        fill_rect(tex, r + width - 1, 0, r + width, w, grey * 0.5)
        r += width + int(rng.integers(1, 6))
    for c in range(int(rng.integers(10, 40)), w, int(rng.integers(60, 140))):  # brackets
        fill_rect(tex, 0, c, h, c + 2, 0.2)
    return tex


def plain_wall(
    rng: Rng, shape: tuple[int, int], shade: tuple[float, float] = (0.6, 0.8)
) -> Texture:
    """Painted plaster: a base grey drawn from ``shade`` with blotches and fine grain."""
    base = float(rng.uniform(*shade))
    return base + 0.04 * noise(rng, shape, 60) + 0.015 * noise(rng, shape, 2, octaves=1)


# --------------------------------------------------------------------------- floor and ceiling


def floor(rng: Rng, shape: tuple[int, int], px_per_m: float) -> Texture:
    """Floor tiles with grout and per-tile shade, or a patterned carpet."""
    h, w = shape
    if rng.random() < 0.5:
        tex = tiles(rng, shape, int(px_per_m * rng.uniform(0.3, 0.5)), (0.25, 0.6))
    else:
        tex = 0.35 + 0.08 * noise(rng, shape, 40) + 0.05 * noise(rng, shape, 3, octaves=1)
        period = int(px_per_m * rng.uniform(0.15, 0.3))
        rows, cols = np.mgrid[0:h, 0:w]
        motif = ((rows // period + cols // period) % 2).astype(np.float32)
        tex = tex + 0.1 * motif
    for _ in range(int(rng.integers(1, 4))):  # rugs / stains
        c = rng.integers(0, [w, h])
        axes = (int(rng.integers(20, 80)), int(rng.integers(20, 80)))
        cv2.ellipse(
            tex,
            (int(c[0]), int(c[1])),
            axes,
            float(rng.uniform(0, 180)),
            0,
            360,
            float(rng.uniform(0.1, 0.7)),
            -1,
            cv2.LINE_AA,
        )
    return tex


def tiles(
    rng: Rng,
    shape: tuple[int, int],
    tile: int,
    shades: tuple[float, float],
    alternate: float = 0.0,
) -> Texture:
    """Square tiles of ``tile`` px, each a grey drawn from ``shades`` (plus ``alternate`` on every
    other tile, a checkerboard), with grain and 1 px grout lines."""
    h, w = shape
    grid = (h // tile + 1, w // tile + 1)
    shade = rng.uniform(*shades, size=grid).astype(np.float32)
    shade += np.float32(alternate) * (np.add.outer(*(np.arange(n) for n in grid)) % 2)
    tex = np.kron(shade, np.ones((tile, tile), np.float32))[:h, :w]
    tex = tex + 0.05 * noise(rng, shape, 8)
    tex[::tile, :] = 0.15
    tex[:, ::tile] = 0.15
    return tex


def linoleum(rng: Rng, shape: tuple[int, int], px_per_m: float) -> Texture:
    """Sheet flooring: a mottled grey with fine speckle and the welded seams of 2 m wide sheets
    laid along the rows (v)."""
    tex = float(rng.uniform(0.3, 0.5)) + 0.03 * noise(rng, shape, 40)
    tex += 0.025 * noise(rng, shape, 1.5, octaves=1)
    tex[:, int(rng.integers(0, int(2 * px_per_m))) :: int(2 * px_per_m)] -= 0.08
    return tex


def ceiling_tiles(rng: Rng, shape: tuple[int, int], px_per_m: float, tile: float = 0.6) -> Texture:
    """Acoustic ceiling tiles in a ``tile`` metre grid with speckle."""
    tex = 0.8 + 0.05 * noise(rng, shape, 3, octaves=2)
    step = int(tile * px_per_m)
    tex[::step, :] = 0.5
    tex[:, ::step] = 0.5
    return tex


# --------------------------------------------------------------------------- object materials


def wood(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Wood grain: stretched noise along the columns."""
    h, w = shape
    grain = noise(rng, (max(2, h // 8), w), 6)
    grain = cv2.resize(grain, (w, h), interpolation=cv2.INTER_LINEAR)
    return float(rng.uniform(0.35, 0.65)) + 0.08 * grain


def cabinet(rng: Rng, shape: tuple[int, int], front_cols: int) -> Texture:
    """A cabinet unrolled around its sides; the first ``front_cols`` columns are its front."""
    h, w = shape
    tex = wood(rng, shape) if rng.random() < 0.5 else metal(rng, shape)
    fc = max(4, front_cols)
    n_drawers = int(rng.integers(1, 5))
    edge = tex[0, 0] - 0.2
    for k in range(n_drawers):
        r0, r1 = h * k // n_drawers, h * (k + 1) // n_drawers
        frame(tex, r0, 0, r1, fc, 2, edge)
        hr = (r0 + r1) // 2 if n_drawers > 1 else h // 3
        fill_rect(tex, hr - 2, fc // 2 - 8, hr + 2, fc // 2 + 8, 0.05)
    if rng.random() < 0.6:
        label = (h // 8, fc // 4, h // 8 + max(6, h // 10), fc * 3 // 4)
        fill_rect(tex, *label, 0.95)
        text_lines(tex, rng, label, 0.05, 0.35)
    return tex


def metal(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Painted sheet metal with faint vertical streaks."""
    h, w = shape
    streak = noise(rng, (1, w), 3)[0]
    return float(rng.uniform(0.45, 0.85)) + 0.03 * streak[None, :] + np.zeros(shape, np.float32)


def cardboard(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Cardboard with tape, a printed label and arrows."""
    h, w = shape
    tex = float(rng.uniform(0.45, 0.65)) + 0.04 * noise(rng, shape, 10)
    fill_rect(tex, 0, w // 2 - 3, h // 5, w // 2 + 3, 0.8)
    for c0 in range(0, w, max(8, w // 4)):
        r0 = int(rng.integers(h // 4, max(h // 4 + 1, h - 20)))
        if rng.random() < 0.5:
            fill_rect(tex, r0, c0 + 4, r0 + 14, c0 + 30, 0.95)
            text_lines(tex, rng, (r0, c0 + 4, r0 + 14, c0 + 40), 0.05, 0.3)
        else:
            tip = (c0 + 10, r0)
            cv2.arrowedLine(tex, (c0 + 10, r0 + 20), tip, 0.1, 2, cv2.LINE_AA, tipLength=0.4)
    return tex


def striped(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Plastic with horizontal bands and vertical ribs (bins, pots)."""
    h, w = shape
    tex = blank(shape, float(rng.uniform(0.2, 0.8)))
    tex[:, :: int(rng.integers(5, 12))] -= 0.12
    for _ in range(int(rng.integers(1, 3))):
        r0 = int(rng.integers(0, max(1, h - 6)))
        fill_rect(tex, r0, 0, r0 + int(rng.integers(3, 8)), w, float(rng.uniform(0, 1)))
    return tex


def foliage(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Dense leaves: many overlapping ellipses in dark to light greys."""
    h, w = shape
    tex = 0.12 + 0.05 * noise(rng, shape, 6)
    n = int(h * w / 40) + 10
    centres = rng.integers(0, [w, h], size=(n, 2))
    sizes = rng.integers(3, 9, size=(n, 2))
    angles = rng.uniform(0, 180, size=n)
    greys = rng.uniform(0.1, 0.7, size=n)
    for (x, y), (a, b), ang, g in zip(centres, sizes, angles, greys, strict=True):
        cv2.ellipse(
            tex,
            (int(x), int(y)),
            (int(a), int(b // 2 + 1)),
            float(ang),
            0,
            360,
            float(g),
            -1,
            cv2.LINE_AA,
        )
    return tex


def bark(rng: Rng, shape: tuple[int, int]) -> Texture:
    h, w = shape
    streaks = cv2.resize(noise(rng, (max(2, h // 10), w), 2), (w, h))
    return 0.25 + 0.08 * streaks


def fabric(rng: Rng, shape: tuple[int, int]) -> Texture:
    """Upholstery: a woven check pattern with a random base grey."""
    h, w = shape
    rows, cols = np.mgrid[0:h, 0:w]
    period = int(rng.integers(3, 8))
    check = (((rows // period) + (cols // period)) % 2).astype(np.float32)
    return float(rng.uniform(0.15, 0.7)) + 0.1 * check + 0.03 * noise(rng, shape, 4)


def checker(
    shape: tuple[int, int], squares: tuple[int, int], low: float = 0.05, high: float = 0.95
) -> Texture:
    """A checkerboard of ``squares`` = (rows, cols) cells (marker objects)."""
    h, w = shape
    rows = (np.arange(h) * squares[0] // h)[:, None]
    cols = (np.arange(w) * squares[1] // w)[None, :]
    return np.where((rows + cols) % 2 == 0, high, low).astype(np.float32)


# --------------------------------------------------------------------------- offices and labs


def luminaire(shape: tuple[int, int], louvres: int = 0) -> tuple[Texture, Texture]:
    """A ceiling luminaire seen from below: (albedo, glow mask 0..1). A 3 px frame; ``louvres``
    cross blades (across the long side) shade the diffuser, 0 gives a plain diffuser."""
    h, w = shape
    albedo, glow = blank(shape, 0.9), blank(shape, 1.0)
    long_rows = h >= w
    n = h if long_rows else w
    for k in range(1, louvres + 1):
        at = k * n // (louvres + 1)
        rows, cols = ((at - 1, at + 1), (0, w)) if long_rows else ((0, h), (at - 1, at + 1))
        fill_rect(albedo, rows[0], cols[0], rows[1], cols[1], 0.6)
        fill_rect(glow, rows[0], cols[0], rows[1], cols[1], 0.25)
    frame(albedo, 0, 0, h, w, 3, 0.3)
    frame(glow, 0, 0, h, w, 3, 0.0)
    return albedo, glow


def slats(shape: tuple[int, int], pitch: int, grey: float) -> Texture:
    """Horizontal slats of a venetian blind, ``pitch`` px apart, with a shaded gap row each."""
    tex = blank(shape, grey)
    tex[pitch - 1 :: pitch, :] = grey * 0.65
    tex[::pitch, :] = min(grey * 1.1, 0.95)
    return tex


def venetian_window(
    rng: Rng, shape: tuple[int, int], frame_px: int, slat_px: int, grey: float, lowered: float
) -> tuple[Texture, Texture, Texture]:
    """A window with a venetian blind of slats ``grey``, ``slat_px`` apart: (albedo with the
    blind down and shut, albedo with it open, glow mask of the open state: the outside view's
    relative luminance where it shows).

    Open: the blind is raised to a packed stack under the head rail; if ``lowered`` (0..1, the
    share of the height it still covers) is above the stack, the lowered part has its slats
    tilted open (the view shows between them). Frame and a mullion are shared by both states.
    """
    h, w = shape
    closed = slats(shape, slat_px, grey) + 0.03 * noise(rng, shape, w / 3, octaves=1)
    fill_rect(closed, h - 2 * frame_px, 0, h - frame_px, w, grey * 0.8)  # bottom rail
    view = outside_view(rng, shape)
    opened, glow = blank(shape, 0.0), view.copy()
    stack = max(frame_px + 2, h // 9)
    down = max(stack, int(h * lowered))
    open_slats = np.zeros(h, bool)
    open_slats[stack:down] = (np.arange(stack, down) % slat_px) == 0
    opened[open_slats, :], glow[open_slats, :] = grey, 0.0
    fill_rect(opened, 0, 0, stack, w, slats((stack, w), 2, grey))
    fill_rect(glow, 0, 0, stack, w, 0.0)
    mullion = (w // 2 - frame_px // 2, w // 2 + frame_px // 2) if w > 2.2 * h / 2 else None
    for tex, value in ((closed, 0.85), (opened, 0.85), (glow, 0.0)):
        frame(tex, 0, 0, h, w, frame_px, value)
        if mullion is not None:
            fill_rect(tex, 0, mullion[0], h, mullion[1], value)
    return closed, opened, glow


#: Glass panels of doors: (top, bottom, left, right) as fractions of the door's shape.
VISION_PANEL = (0.15, 0.6, 0.2, 0.35)
GLAZED_PANEL = (0.1, 0.6, 0.2, 0.8)


def office_door(
    rng: Rng,
    shape: tuple[int, int],
    leaf: float,
    frame_grey: float,
    panel: tuple[float, float, float, float] | None = None,
    behind: tuple[float, float] = (0.08, 0.18),
) -> tuple[Texture, Texture]:
    """A flush door in a steel frame (frame included in ``shape``, no threshold): (albedo, glow).

    ``leaf`` and ``frame_grey`` are the building's (doors of one place share them); a kick plate
    and wear vary per door. A glass ``panel`` (fractions, e.g. :data:`VISION_PANEL`) shows the
    room behind: dark glass in the albedo, in the glow mask that room's luminance relative to
    the sky seen through a window, drawn from ``behind`` (a daylit office: about as bright as a
    lit corridor's walls, a tenth of the sky).
    """
    h, w = shape
    f = max(3, w // 16)
    tex = leaf + 0.02 * noise(rng, shape, w / 2) + 0.01 * noise(rng, shape, 2, octaves=1)
    glow = blank(shape, 0.0)
    if panel is not None:
        r0, r1 = int(h * panel[0]), int(h * panel[1])
        c0, c1 = int(w * panel[2]), int(w * panel[3])
        fill_rect(tex, r0, c0, r1, c1, 0.15)
        room = float(rng.uniform(*behind)) + 0.05 * noise(rng, (r1 - r0, c1 - c0), 8)
        fill_rect(glow, r0, c0, r1, c1, room)
        frame(tex, r0 - 1, c0 - 1, r1 + 1, c1 + 1, 2, frame_grey)
    if rng.random() < 0.5:
        fill_rect(tex, h - h // 10, f, h, w - f, min(leaf + 0.2, 0.9))  # kick plate
    plate = (h * 45 // 100, w - w // 7 - f // 2, h * 6 // 10, w - w // 7 + f // 2)
    fill_rect(tex, *plate, 0.75)  # escutcheon
    handle(tex, h * 52 // 100, w - w // 7 + f // 2, f)
    frame(tex, 0, 0, h + f, w, f, frame_grey)
    return tex, glow


def door_sign(rng: Rng, shape: tuple[int, int], number: str) -> Texture:
    """A room sign: a light plate with the room number large and a few lines of names."""
    h, w = shape
    tex = blank(shape, float(rng.uniform(0.8, 0.95)))
    ink = np.zeros(shape, np.uint8)
    scale = h / 2.0 / 22.0
    cv2.putText(ink, number, (2, h * 4 // 10), cv2.FONT_HERSHEY_SIMPLEX, scale, 255, 1, cv2.LINE_AA)
    tex -= 0.8 * ink.astype(np.float32) / 255.0
    text_lines(tex, rng, (h // 2, 1, h - 1, w + 30), 0.2, max(0.12, h / 240.0))
    frame(tex, 0, 0, h, w, 1, 0.4)
    return tex


def safety_sign(shape: tuple[int, int], kind: str) -> Texture:
    """A square safety sign: ``"exit"`` (green: a running figure towards a door) or
    ``"extinguisher"`` (red: an extinguisher's silhouette), as grey levels."""
    h, w = shape
    if kind == "exit":
        tex = blank(shape, 0.45)
        cv2.rectangle(tex, (w * 6 // 10, h // 6), (w * 9 // 10, h * 5 // 6), 0.95, 1)
        cv2.circle(tex, (w * 35 // 100, h // 4), max(1, h // 10), 0.95, -1, cv2.LINE_AA)
        body = np.array([[w // 3, h * 35 // 100], [w // 4, h * 6 // 10], [w // 6, h * 8 // 10]])
        cv2.polylines(tex, [body.astype(np.int32)], False, 0.95, max(1, h // 12), cv2.LINE_AA)
        legs = np.array(
            [[w // 6, h * 8 // 10], [w // 4, h * 6 // 10], [w * 45 // 100, h * 8 // 10]]
        )
        cv2.polylines(tex, [legs.astype(np.int32)], False, 0.95, max(1, h // 14), cv2.LINE_AA)
    else:
        tex = blank(shape, 0.3)
        fill_rect(tex, h // 4, w * 4 // 10, h * 85 // 100, w * 6 // 10, 0.95)
        fill_rect(tex, h // 6, w * 45 // 100, h // 4, w * 55 // 100, 0.95)
        cv2.line(tex, (w // 2, h // 6), (w * 3 // 4, h // 3), 0.95, max(1, w // 12), cv2.LINE_AA)
    frame(tex, 0, 0, h, w, max(1, h // 16), 0.95)
    return tex


def cabinet_front(
    rng: Rng, shape: tuple[int, int], front_cols: int, doors: int, vents: bool
) -> Texture:
    """A steel cabinet or locker unit unrolled around its sides: painted metal, the first
    ``front_cols`` columns a front of ``doors`` equal leaves with handles; with ``vents``
    (lockers) each leaf has vent slots at the top and bottom and a small number plate."""
    h, w = shape
    tex = metal(rng, shape)
    gap = float(tex[0, 0]) - 0.25
    leaf = front_cols / doors
    for k in range(doors):
        c0, c1 = int(round(k * leaf)), int(round((k + 1) * leaf))
        frame(tex, 0, c0, h, c1, 1, gap)
        mid = (c0 + c1) // 2
        if vents:
            for r0 in (h // 12, h - h // 6):
                for r in range(r0, r0 + h // 16, 3):
                    fill_rect(tex, r, c0 + 4, r + 1, c1 - 4, gap)
            fill_rect(tex, h // 5, mid - 4, h // 5 + 4, mid + 4, 0.9)
            fill_rect(tex, h // 4, c1 - 6, h // 4 + 10, c1 - 4, 0.15)
        else:
            side = c1 - 5 if k % 2 == 0 else c0 + 3
            fill_rect(tex, h * 45 // 100, side, h * 55 // 100, side + 2, 0.1)
    fill_rect(tex, h - 4, 0, h, front_cols, gap)  # plinth
    return tex


def binders(rng: Rng, shape: tuple[int, int], board_px: int) -> Texture:
    """Open steel shelving holding rows of identical binders or archive boxes: one kind, grey
    and width per shelf, labels at one height, a gap at the end of each row."""
    h, w = shape
    steel = float(rng.uniform(0.5, 0.8))
    tex = blank(shape, 0.12) + 0.02 * noise(rng, shape, 10)
    pitch = int(rng.integers(32, 40))
    for bottom in range(h - board_px, pitch // 2, -pitch):
        fill_rect(tex, bottom, 0, bottom + board_px, w, steel)
        grey = float(rng.uniform(0.15, 0.85))
        box = rng.random() < 0.35
        width = int(rng.integers(24, 34)) if box else int(rng.integers(6, 9))
        height = int(pitch * (rng.uniform(0.55, 0.7) if box else rng.uniform(0.75, 0.85)))
        end = board_px + int((w - 2 * board_px) * rng.uniform(0.55, 1.0))
        for c in range(board_px, end - width, width + 1):
            fill_rect(tex, bottom - height, c, bottom, c + width, grey)
            label = bottom - height * 2 // 3
            fill_rect(tex, label, c + 2, label + max(3, height // 5), c + width - 2, 0.9)
            if not box:  # the finger hole near the bottom of the spine
                fill_rect(
                    tex, bottom - height // 4, c + 2, bottom - height // 4 + 3, c + width - 2, 0.05
                )
    frame(tex, 0, 0, h, w, board_px, steel)
    return tex


def monitor(rng: Rng, shape: tuple[int, int], front_cols: int) -> Texture:
    """A flat screen unrolled around its sides: on the first ``front_cols`` columns a switched
    off screen (near black with a faint reflected gradient) in a bezel; dark plastic elsewhere."""
    h, w = shape
    plastic = float(rng.uniform(0.08, 0.25))
    tex = blank(shape, plastic) + 0.01 * noise(rng, shape, 4)
    b = max(1, front_cols // 30)
    gradient = np.linspace(0.09, 0.03, h - 2 * b, dtype=np.float32)[:, None]
    fill_rect(tex, b, b, h - b, front_cols - b, gradient + np.zeros((1, front_cols - 2 * b)))
    return tex


def cable_duct(shape: tuple[int, int], pitch: int, socket: int, offset: int) -> Texture:
    """Wall trunking (rows = its height): a white duct with socket outlets every ``pitch`` px
    from ``offset``, each ``socket`` px square with two pin holes."""
    h, w = shape
    tex = blank(shape, 0.88)
    tex[0, :], tex[-1, :], tex[h // 2, :] = 0.6, 0.5, 0.8
    top = max(0, (h - socket) // 2)
    for c in range(offset, w - socket, pitch):
        for k in (0, 1):
            c0 = c + k * (socket + 2)
            fill_rect(tex, top, c0, top + socket, c0 + socket, 0.95)
            frame(tex, top, c0, top + socket, c0 + socket, 1, 0.65)
            mid = top + socket // 2
            for dc in (socket // 3, 2 * socket // 3):
                fill_rect(tex, mid, c0 + dc, mid + 1, c0 + dc + 1, 0.1)
    return tex


def blackboard(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A wiped blackboard: near-black slate with faint chalk smears, a frame and a chalk tray."""
    h, w = shape
    tex = float(rng.uniform(0.06, 0.12)) + 0.03 * np.abs(noise(rng, shape, w / 8))
    for _ in range(int(rng.integers(2, 6))):
        c = rng.integers(0, [w, h])
        cv2.ellipse(
            tex,
            (int(c[0]), int(c[1])),
            (int(rng.integers(10, max(11, w // 6))), int(rng.integers(4, max(5, h // 8)))),
            float(rng.uniform(-20, 20)),
            0,
            360,
            float(tex.mean() + 0.04),
            -1,
            cv2.LINE_AA,
        )
    frame(tex, 0, 0, h, w, 3, float(rng.uniform(0.3, 0.5)))
    fill_rect(tex, h - 5, 0, h, w, 0.35)
    return tex


def extinguisher(rng: Rng, shape: tuple[int, int]) -> Texture:
    """A fire extinguisher's body unrolled: red paint (a dark grey here), a white instruction
    label at mid-height and the black hose down one side."""
    h, w = shape
    tex = blank(shape, 0.28) + 0.02 * noise(rng, shape, 3)
    fill_rect(tex, h * 3 // 10, w // 8, h * 7 // 10, w // 2, 0.9)
    text_lines(tex, rng, (h * 3 // 10, w // 8, h * 7 // 10, w // 2 + 20), 0.2, 0.15)
    fill_rect(tex, 0, w * 3 // 4, h * 9 // 10, w * 3 // 4 + max(2, w // 16), 0.05)
    return tex
